#!/usr/bin/env bash
# Issue 30's per-texel parameters and post-scatter texturing on the device machine
# (docs/perf/issue30/README.md: predictions written before the call). At 1080p on
# the default face and the Lee Perry-Smith head: separable (both paths), ssg and tsd
# with pre- and post-scatter texturing (the albedo target the geometry pass writes,
# the composite's third fetch, tsd's strength blend); then `dermis eval
# --compare-texturing` on the thesis scene set at 720p for the methods' settings
# (each texturing against its own truth), cut off at 240 s.
#
#   OUT=$OUT bash tools/perf_issue30_texturing.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis, stripped
# release build, DejaVuSans.ttf), .assets (the head scan).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue30-texturing
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
F="--warmup 20 --frames 200 --width 1920 --height 1080"
for t in pre post; do
  # shellcheck disable=SC2086
  bench "face-separable-$t" --method separable --texturing $t $F
  # shellcheck disable=SC2086
  bench "face-separable-compute-$t" --method separable --path compute --texturing $t $F
  # shellcheck disable=SC2086
  bench "face-ssg-$t" --method ssg --texturing $t $F
  # shellcheck disable=SC2086
  bench "face-tsd-$t" --method tsd --texturing $t $F
  # shellcheck disable=SC2086
  bench "lps-separable-$t" --scene "$LPS" --shot close --method separable --texturing $t $F
done
log dermis eval --compare-texturing --scene "$LPS" --scenes thesis --width 1280 --height 720 \
  --warmup 2 --frames 10 --only none --only separable --only ssg --only ss-jittered \
  --only poisson --only gather --only tsd
timeout 240 "$N" eval --compare-texturing --scene "$LPS" --scenes thesis --width 1280 --height 720 \
  --warmup 2 --frames 10 --only none --only separable --only ssg --only ss-jittered \
  --only poisson --only gather --only tsd --out "$R/eval" > "$R/eval.txt" 2>&1
echo "eval exit $?" >> "$R/exits.txt"
tar -C /tmp -czf "$OUT/issue30-texturing.tgz" issue30-texturing
