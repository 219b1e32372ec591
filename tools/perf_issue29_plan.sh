#!/usr/bin/env bash
# Issue 29's planned crowds on the device machine (docs/perf/issue29/README.md,
# "Planned crowds": predictions first, then the results): 256-character crowds at
# 1080p, moving (--time 1), benched with the binary before this stop's changes
# (.bin/dermis-old: levels to 1/16, every vertex deformed, the backdrop drawn first)
# and this one (levels to 1/64, each copy deforming its level's vertices, the
# backdrop last), each with `dermis plan`'s per-character methods, levels and
# shadow casters (--budget-ms 1 on the H100 profile, --lod-pixels 1); a crowd of
# 64 walking past the camera with its shadow casters culled against the same plan
# with every character casting; and the error the levels add (the planned frame
# against the same plan at level 0: `dermis compare`).
#
#   OUT=$OUT bash tools/perf_issue29_plan.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis and
# dermis-old, stripped release builds, and DejaVuSans.ttf), .assets (../shared/assets).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue29-plan
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
O=$ROOT/.bin/dermis-old
bench_old() { # name, args...
  local n=$1; shift
  log dermis-old bench "$@" --report "$R/$n.json"
  "$O" bench "$@" --report "$R/$n.json" > "$R/$n.txt" 2>&1
  echo "$n exit $?" >> "$R/exits.txt"
}
run() { # name, dermis args...
  local n=$1; shift
  log dermis "$@"
  "$N" "$@" > "$R/$n.txt" 2>&1
  echo "$n exit $?" >> "$R/exits.txt"
}
HD="--width 1920 --height 1080"
F="--warmup 20 --frames 200 $HD --heads 256 --time 1"
for scene in "face|" "lps|--scene $LPS"; do
  s=${scene%%|*}; sa=${scene#*|}
  # shellcheck disable=SC2086
  run "plan-$s" plan --profile nvidia-h100 --budget-ms 1 --lod-pixels 1 $sa $HD --heads 256 --time 1 --out "$R/plan-$s"
  # shellcheck disable=SC2086
  bench_old "$s-lod1-old" $sa --method separable --lod-pixels 1 $F
  # shellcheck disable=SC2086
  bench "$s-lod0" $sa --method separable --lod-pixels 0 $F
  # shellcheck disable=SC2086
  bench "$s-lod1" $sa --method separable --lod-pixels 1 $F
  # shellcheck disable=SC2086
  bench "$s-plan" $sa --plan "$R/plan-$s/plan.json" $F
  # The same plan with every character at its full meshes: the error the
  # levels add, and their time.
  sed -E 's/"level": [0-9]+/"level": 0/' "$R/plan-$s/plan.json" > "$R/plan-$s-full.json"
  # shellcheck disable=SC2086
  bench "$s-plan-full" $sa --plan "$R/plan-$s-full.json" $F
  for p in "plan|$R/plan-$s/plan.json" "plan-full|$R/plan-$s-full.json"; do
    pn=${p%%|*}; pf=${p#*|}
    # shellcheck disable=SC2086
    run "img-$s-$pn" render $sa --plan "$pf" $HD --heads 256 --time 1 --frames 1 --warmup 0 --out "$R/img-$s-$pn"
  done
  run "cmp-$s-plan" compare "$R/img-$s-plan" "$R/img-$s-plan-full" --out "$R/cmp-$s-plan"
  # shellcheck disable=SC2086
  run "budget-$s-plan" budget --profile nvidia-h100 $sa --plan "$R/plan-$s/plan.json" $HD --heads 256 --time 1 --out "$R/budget-$s-plan"
done
# Shadow-caster culling: 64 characters walked 12 head heights toward the
# camera (the front rows past it), the key light from the right.
W="--heads 64 --crowd-walked 12 --light-azimuth 90 $HD"
# shellcheck disable=SC2086
run plan-walk plan --profile nvidia-h100 --budget-ms 1 $W --out "$R/plan-walk"
sed 's/"casts_shadow": false/"casts_shadow": true/' "$R/plan-walk/plan.json" > "$R/plan-walk-all.json"
# shellcheck disable=SC2086
bench walk-culled --plan "$R/plan-walk/plan.json" --warmup 20 --frames 200 $W
# shellcheck disable=SC2086
bench walk-all --plan "$R/plan-walk-all.json" --warmup 20 --frames 200 $W
for p in "culled|$R/plan-walk/plan.json" "all|$R/plan-walk-all.json"; do
  pn=${p%%|*}; pf=${p#*|}
  # shellcheck disable=SC2086
  run "img-walk-$pn" render --plan "$pf" $W --frames 1 --warmup 0 --out "$R/img-walk-$pn"
done
cmp "$R/img-walk-culled/frame.png" "$R/img-walk-all/frame.png" > "$R/walk-cmp.txt" 2>&1
echo "walk frames identical: exit $?" >> "$R/walk-cmp.txt"
# Keep the numbers and the planned face crowd's frame, not every image.
cp "$R/img-face-plan/frame.png" "$R/face-plan.png" 2>/dev/null
find "$R" -name '*.exr' -delete
find "$R" -mindepth 2 -name '*.png' -delete
tar -C /tmp -czf "$OUT/issue29-plan.tgz" issue29-plan
