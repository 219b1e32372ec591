#!/usr/bin/env bash
# Issue 30, second call: `dermis eval --compare-texturing` on the thesis scene set
# (the Lee Perry-Smith head at three distances under four lights, and the
# procedural face) at 720p for every method's eval settings, each texturing against
# its own ground truth (the first call's 240 s cut-off was too short: 26 truths).
#
#   OUT=$OUT bash tools/perf_issue30_eval.sh
#
# Carried: .gl, .bin (dermis, DejaVuSans.ttf), .assets (the head scan).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue30-eval
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
A=(eval --compare-texturing --scene "$LPS" --scenes thesis --width 1280 --height 720
  --warmup 1 --frames 5 --only none --only separable --only ssg --only ss-jittered
  --only poisson --only gather --only tsd)
log dermis "${A[@]}"
start=$(date +%s)
timeout 500 "$N" "${A[@]}" --out "$R/eval" > "$R/eval.txt" 2>&1
echo "eval exit $? in $(( $(date +%s) - start )) s" >> "$R/exits.txt"
tar -C /tmp -czf "$OUT/issue30-eval.tgz" issue30-eval
