#!/usr/bin/env bash
# Issue 29 on the device machine (docs/perf/issue29/README.md has the
# predictions, written before the call, and the results): the deform pass
# (morph targets, one copy of the face per character at its own phase)
# and the per-copy draws of a moving crowd, against the same crowd still,
# for 1, 16, 64 and 256 characters at 1080p; the Lee Perry-Smith head's
# crowd turning (a model matrix each: no deform) against still; the budget
# model's price of the same frames on the profile of the card.
#
#   OUT=$OUT bash tools/perf_issue29.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis,
# stripped release build, and DejaVuSans.ttf), .assets (../shared/assets).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue29
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
F="--warmup 20 --frames 200 --width 1920 --height 1080 --method separable"
for heads in 1 16 64 256; do
  # shellcheck disable=SC2086
  bench "face-$heads-still" --heads $heads $F
  # shellcheck disable=SC2086
  bench "face-$heads-moving" --heads $heads --time 1 $F
done
for heads in 1 256; do
  # shellcheck disable=SC2086
  bench "lps-$heads-still" --scene "$LPS" --heads $heads $F
  # shellcheck disable=SC2086
  bench "lps-$heads-turning" --scene "$LPS" --heads $heads --time 1 $F
done
# The card's profile prices the same frames (from this run's counts).
P=nvidia-h100
"$N" devices 2>&1 | grep -qi h200 && P=nvidia-h200
for heads in 1 16 64 256; do
  log dermis budget --profile $P --heads $heads --time 1 --width 1920 --height 1080 --method separable
  "$N" budget --profile $P --heads $heads --time 1 --width 1920 --height 1080 --method separable \
    --out "$R/budget-$heads" > "$R/budget-$heads.txt" 2>&1
  echo "budget-$heads exit $?" >> "$R/exits.txt"
done
tar -C /tmp -czf "$OUT/issue29.tgz" issue29
