#!/usr/bin/env bash
# Issue 28's last device call (docs/perf/issue28/final.md has the predictions, written before
# it): the one-group dispatch probe and the compute floors that start from it; the gather with
# its normal test; the budget model's calibrated compute prices checked out of sample at
# 2560x1440, a size no fit saw; plans that choose the path per group, predicted by `dermis plan`
# and measured by `dermis bench --plan` on the same card; the gather's rows of the accuracy
# model (tools/accuracy_sweep.sh with ONLY=gather).
#
#   OUT=$OUT bash tools/perf_issue28_final.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis, stripped release
# build; dermis-before.gz, the build of the previous calls, before the blur's arithmetic cut),
# .assets (../shared/assets).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/final
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
plan() { # name, args... (no device: the plan's prediction)
  local n=$1; shift
  log dermis plan "$@" --out "$R/$n"
  "$N" plan "$@" --out "$R/$n" > "$R/$n.txt" 2>&1
  echo "$n exit $?" >> "$R/exits.txt"
}
F="--warmup 20 --frames 200"
HD="--width 1920 --height 1080"
QHD="--width 2560 --height 1440"
# shellcheck disable=SC2086
{
  # The baseline of this call and the compute floors (the dispatch probe is in every report).
  bench close-fragment $HD --shot close --method separable --path fragment $F
  bench close-compute $HD --shot close --method separable --path compute $F
  bench mid-compute $HD --shot mid --method separable --path compute $F
  # The blur's arithmetic cut: the build before it, same views, same card (carried gzipped:
  # the carried tree has a size limit).
  if [ -f "$ROOT/.bin/dermis-before.gz" ]; then
    gunzip -c "$ROOT/.bin/dermis-before.gz" > /tmp/dermis-before && chmod +x /tmp/dermis-before
  fi
  if [ -x /tmp/dermis-before ]; then
    for shot in close mid; do
      log dermis-before bench $HD --shot $shot --method separable --path compute $F
      /tmp/dermis-before bench $HD --shot $shot --method separable --path compute $F \
        --report "$R/before-$shot-compute.json" > "$R/before-$shot-compute.txt" 2>&1
      echo "before-$shot-compute exit $?" >> "$R/exits.txt"
    done
  fi
  # The gather with its normal test, both profiles.
  for b in 20 40 80; do
    bench close-gather-$b $HD --shot close --method gather --sample-budget $b $F
  done
  bench close-gather-burley-40 $HD --shot close --method gather --sample-budget 40 --diffusion-profile burley $F
  bench mid-gather-40 $HD --shot mid --method gather --sample-budget 40 $F
  # Plans choosing the path per group on the H100 profile, then the planned frame measured.
  for b in 0.1 0.3; do
    plan plan-study16-$b --profile nvidia-h100 --budget-ms $b --view study --heads 16 --scene "$LPS"
    bench plan-study16-$b --view study --heads 16 --scene "$LPS" --plan "$R/plan-study16-$b/plan.json" $F
  done
  plan plan-crowd64-0.5 --profile nvidia-h100 --budget-ms 0.5 $HD --view study --heads 64 --scene "$LPS"
  bench plan-crowd64-0.5 $HD --view study --heads 64 --scene "$LPS" --plan "$R/plan-crowd64-0.5/plan.json" $F
  # Out of sample for the budget model: 2560x1440, close-up and mid, every compute method.
  for shot in close mid; do
    bench qhd-$shot-separable $QHD --shot $shot --method separable --path compute $F
    bench qhd-$shot-ssg $QHD --shot $shot --method ssg --path compute $F
    bench qhd-$shot-jittered $QHD --shot $shot --method ss-jittered --path compute $F
    bench qhd-$shot-poisson $QHD --shot $shot --method poisson --path compute $F
    bench qhd-$shot-gather-40 $QHD --shot $shot --method gather --sample-budget 40 $F
  done
}
# The gather's rows of the accuracy model (the planner's error for it): both heads, every
# shadow-map size, at once (each sweep is mostly CPU work per view); merged afterwards into
# profiles/accuracy/ by tools/accuracy_merge.py.
# ACC_DEADLINE=0 leaves it out (a call short of device time).
if [ "${ACC_DEADLINE:-300}" -gt 0 ]; then
  JOBS=8 DEADLINE=${ACC_DEADLINE:-300} ONLY=gather HEAD=$LPS \
    bash "$ROOT/tools/accuracy_sweep.sh" "$N" "$R/accuracy" > "$R/accuracy.log" 2>&1
  echo "accuracy exit $?" >> "$R/exits.txt"
fi
cd "$R" && tar czf "$OUT/final.tgz" --exclude='*.png' --exclude='*.exr' --exclude='*.svg' . && cd "$ROOT"
