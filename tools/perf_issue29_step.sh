#!/usr/bin/env bash
# Issue 29's planned face crowd stepping through its clip on the device machine
# (docs/perf/issue29/README.md, "Stepping through the clip"): the 256-character
# moving crowd at 1080p with its plan (the third call's: `dermis plan` at
# --budget-ms 1 --lod-pixels 1), benched at a fixed time (--time 1) and stepping
# 1/120 s a frame from it (--time-step 0.0083333), in one call.
#
#   OUT=$OUT bash tools/perf_issue29_step.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis, stripped
# release build, and DejaVuSans.ttf).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue29-step
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
HD="--width 1920 --height 1080"
log dermis plan --profile nvidia-h100 --budget-ms 1 --lod-pixels 1 $HD --heads 256 --time 1 --out "$R/plan"
# shellcheck disable=SC2086
"$N" plan --profile nvidia-h100 --budget-ms 1 --lod-pixels 1 $HD --heads 256 --time 1 --out "$R/plan" > "$R/plan.txt" 2>&1
F="--warmup 20 --frames 200 $HD --heads 256 --time 1 --plan $R/plan/plan.json"
for rep in 1 2; do
  # shellcheck disable=SC2086
  bench "fixed-$rep" $F
  # shellcheck disable=SC2086
  bench "step-$rep" $F --time-step 0.0083333
done
tar -C /tmp -czf "$OUT/issue29-step.tgz" issue29-step
