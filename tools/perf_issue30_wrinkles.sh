#!/usr/bin/env bash
# Issue 30's expression wrinkles (thesis ch. 8) on the device machine
# (docs/perf/issue30/README.md: predictions written before the call). At 1080p,
# each frame with the built-in face's wrinkles and again with --no-wrinkles
# (the same morphs, the same deform pass: only the wrinkle maps' three fetches
# and Listing 8.1's sum differ):
# - five heads (the thesis' ch. 7 claim: five heads at "essentially no
#   additional cost"), every zone weighed (joy, surprise and disgust at once),
#   separable on both paths and tsd (its irradiance passes shade with them);
# - one head close, the same weights; and at neutral weights (the maps bound,
#   no zone weighed: the shader skips them);
# - a crowd of 64 characters, each at its own phase of the expressions clip,
#   stepping 1/30 s a frame (their zones rewritten every frame).
#
#   OUT=$OUT bash tools/perf_issue30_wrinkles.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis, stripped
# release build, DejaVuSans.ttf).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue30-wrinkles
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
F="--warmup 20 --frames 200 --width 1920 --height 1080"
W="--morph-weights joy=0.5,surprise=1,disgust=0.6"
for w in on off; do
  X=""
  [ "$w" = off ] && X="--no-wrinkles"
  # shellcheck disable=SC2086
  bench "h5-separable-$w" --heads 5 --method separable $W $X $F
  # shellcheck disable=SC2086
  bench "h5-separable-compute-$w" --heads 5 --method separable --path compute $W $X $F
  # shellcheck disable=SC2086
  bench "h5-tsd-$w" --heads 5 --method tsd $W $X $F
  # shellcheck disable=SC2086
  bench "h1-separable-$w" --shot close --method separable $W $X $F
  # shellcheck disable=SC2086
  bench "neutral-separable-$w" --shot close --method separable $X $F
  # shellcheck disable=SC2086
  bench "crowd64-separable-$w" --heads 64 --time 3 --time-step 0.0333 --method separable $X $F
done
tar -C /tmp -czf "$OUT/issue30-wrinkles.tgz" issue30-wrinkles
