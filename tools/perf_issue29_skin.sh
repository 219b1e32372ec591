#!/usr/bin/env bash
# Issue 29's skinned crowds on the device machine (docs/perf/issue29/README.md,
# "Skinned crowds": predictions written before the call): the default face written
# as a skinned GLB (tools/examples/skinned_face.rs: two joints, a 4 s turn and nod),
# 1, 16, 64 and 256 characters at 1080p, still (the file at rest: one deformed copy
# shared by all) and at --time 1 (the file's clip at each character's phase: one
# copy per character and object), the 256 crowd stepping 1/120 s a frame, the face's
# morph crowd at 256 as the earlier calls' baseline, and `dermis budget` on the
# card's profile for the moving skinned crowds.
#
#   OUT=$OUT bash tools/perf_issue29_skin.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis, stripped
# release build, DejaVuSans.ttf, and skinned-face.glb from the example).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue29-skin
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
S=$ROOT/.bin/skinned-face.glb
F="--warmup 20 --frames 200 --width 1920 --height 1080 --method separable"
for heads in 1 16 64 256; do
  # shellcheck disable=SC2086
  bench "skin-$heads-still" --scene "$S" --heads $heads $F
  # shellcheck disable=SC2086
  bench "skin-$heads-moving" --scene "$S" --heads $heads --time 1 $F
done
# shellcheck disable=SC2086
bench "skin-256-step" --scene "$S" --heads 256 --time 1 --time-step 0.0083333 $F
# shellcheck disable=SC2086
bench "face-256-moving" --heads 256 --time 1 $F
P=nvidia-h100
"$N" devices 2>&1 | grep -qi h200 && P=nvidia-h200
for heads in 1 16 64 256; do
  log dermis budget --profile $P --scene "$S" --heads $heads --time 1 --width 1920 --height 1080 --method separable
  "$N" budget --profile $P --scene "$S" --heads $heads --time 1 --width 1920 --height 1080 --method separable \
    --out "$R/budget-$heads" > "$R/budget-$heads.txt" 2>&1
  echo "budget-$heads exit $?" >> "$R/exits.txt"
done
tar -C /tmp -czf "$OUT/issue29-skin.tgz" issue29-skin
