#!/usr/bin/env bash
# Issue 27 on the device machine (docs/perf/issue27/README.md has the
# predictions, written before the call, and the results):
#   1. a binary that runs anywhere: the carried binary, run from /tmp (no
#      source tree), plans and prices with its built-in profiles; the binary
#      before issue 27 cannot (it read profiles/ from the tree it was built in);
#   2. a report renders its frame again bit for bit on the GPU
#      (`render --settings report.json`), a single-method frame and a mixed one;
#   3. the frame's per-pass times are what they were: the binaries before and
#      after issue 27 benched in turn, three rounds, on the same GPU.
#
#   OUT=$OUT bash tools/perf_issue27.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis after,
# dermis-before: the release build of 4543ad7, both stripped).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue27
rm -rf "$R"
mkdir -p "$R" "$OUT"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
N=$ROOT/.bin/dermis
O=$ROOT/.bin/dermis-before
if ! "$N" devices 2>&1 | grep -qi nvidia; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
# The charts need a TrueType font; the device machine has none.
export DERMIS_FONT=$ROOT/.bin/DejaVuSans.ttf
cd /tmp
log() { echo "+ $*" >> "$R/commands.txt"; }
{
  "$N" --version
  "$N" devices
} > "$R/gpu.txt" 2>&1

# 1. Runs anywhere: the source tree's data hidden while both binaries run (the
# device's copy of the checkout sits where this one was built).
mv "$ROOT/profiles" "$ROOT/profiles.hidden"
log dermis plan --profile nvidia-h100 --budget-ms 0.5 --heads 16 --out "$R/plan"
"$N" plan --profile nvidia-h100 --budget-ms 0.5 --heads 16 --out "$R/plan" > "$R/plan.txt" 2>&1
echo "after: plan exit $?" >> "$R/anywhere.txt"
log dermis budget --profile nvidia-h100,xbox360 --width 1920 --height 1080 --shot close --out "$R/budget"
"$N" budget --profile nvidia-h100,xbox360 --width 1920 --height 1080 --shot close \
  --out "$R/budget" > "$R/budget.txt" 2>&1
echo "after: budget exit $?" >> "$R/anywhere.txt"
"$O" budget --profile nvidia-h100 --width 1920 --height 1080 --shot close \
  --out "$R/budget-before" > "$R/budget-before.txt" 2>&1
echo "before: budget exit $?" >> "$R/anywhere.txt"
mv "$ROOT/profiles.hidden" "$ROOT/profiles"

# 2. A report renders its frame again, bit for bit, on the GPU.
for c in "single|--width 1920 --height 1080 --shot close" \
         "mixed|--width 1920 --height 1080 --heads 9 --assign d0-4=separable,*=ss-jittered --aa smaa"; do
  n=${c%%|*}; a=${c#*|}
  log dermis render $a --out "$R/$n-a"
  # shellcheck disable=SC2086
  "$N" render $a --warmup 2 --frames 5 --out "$R/$n-a" > "$R/$n-a.txt" 2>&1
  log dermis render --settings "$R/$n-a/report.json" --out "$R/$n-b"
  "$N" render --settings "$R/$n-a/report.json" --warmup 2 --frames 5 --out "$R/$n-b" > "$R/$n-b.txt" 2>&1
  for f in frame.png diffuse.exr depth.exr; do
    if cmp -s "$R/$n-a/$f" "$R/$n-b/$f"; then r=same; else r=DIFFERENT; fi
    echo "$n $f $r" >> "$R/again.txt"
  done
done

# 3. Before and after, in turn.
B="--width 1920 --height 1080 --shot close --warmup 20 --frames 200"
for round in 1 2 3; do
  for who in before after; do
    if [ $who = before ]; then bin=$O; else bin=$N; fi
    log "$who: dermis bench $B --report $R/bench-$who-$round.json"
    # The before binary needs no profile for a bench.
    # shellcheck disable=SC2086
    "$bin" bench $B --report "$R/bench-$who-$round.json" > "$R/bench-$who-$round.txt" 2>&1
  done
done
cd "$R" && tar czf "$OUT/issue27.tgz" --exclude='*.exr' --exclude='*.png' . && cd "$ROOT"
ls -la "$OUT"
