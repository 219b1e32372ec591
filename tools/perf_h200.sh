#!/usr/bin/env bash
# The H200 measurements of docs/perf/h200/ (issues 9, 10 and 12), by part:
#
#   bash tools/perf_h200.sh PART...
#     smoke    GPU facts; every method of the registry under the validation layer
#     card     the card and uniform-light tests (tests/suite/accuracy.rs) on the GPU
#     eval     the cost/error chart: thesis scene set, 1280x720 (tools/perf_h100.sh eval)
#     dolly    the error along a camera dolly, 1280x720 (tools/perf_h100.sh dolly)
#     matrix   the bench matrix the budget calibration pairs (tools/bench_matrix.sh)
#     t31 apart t44   texture-space diffusion (tools/tsd_table31.sh)
#
# Run on the device machine from the repository root with carried:
#   .gl      Vulkan loader debs, unpacked into /  (see docs/perf/README.md)
#   .vvl     the vulkan-validationlayers deb (smoke, card)
#   .bin     dermis (strip -o .bin/dermis target/release/dermis), suite (the release
#            test binary of tests/suite/, `cargo test --release --test suite --no-run`
#            names it) and DejaVuSans.ttf for the charts
#   .assets  a copy of ../shared/assets
# Each part skips runs whose output exists and starts none after DEADLINE seconds
# (default 540) from the script's start, so a call stays inside the device's
# 10 minutes. Everything lands in $OUT/h200.tgz (no EXR).
set -uo pipefail
START=$SECONDS
DEADLINE=${DEADLINE:-540}
OUT=${OUT:-out}
STORE=${STORE:-/tmp/dermis-h200}
B=.bin/dermis
mkdir -p "$STORE" "$OUT"
. "$(dirname "$0")/methods.sh"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
[ -f .bin/DejaVuSans.ttf ] && export DERMIS_FONT=$PWD/.bin/DejaVuSans.ttf
if ! "$B" devices 2>&1 | grep -qi nvidia; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
left() { echo $((DEADLINE - (SECONDS - START))); }
validation_layer() {
  mkdir -p /tmp/vvl && for f in .vvl/*.deb; do dpkg -x "$f" /tmp/vvl; done
  export VK_LAYER_PATH=/tmp/vvl/usr/share/vulkan/explicit_layer.d
  export LD_LIBRARY_PATH=/tmp/vvl/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
}

for part in "$@"; do
  (( $(left) > 20 )) || { echo "SKIPPED (deadline): $part" >> "$STORE/parts.txt"; continue; }
  t0=$SECONDS
  case $part in
    smoke)
      { nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader || true; "$B" devices; } > "$STORE/gpu.txt" 2>&1
      validation_layer
      mkdir -p "$STORE/validate"
      for m in $(dermis_methods "$B"); do
        [ -e "$STORE/validate/$m/report.json" ] && continue
        echo "+ dermis render --validate --scene .assets/lee-perry-smith/LeePerrySmith.glb --method $m --width 1280 --height 720" >> "$STORE/validate/commands.txt"
        if "$B" render --view study --validate --scene .assets/lee-perry-smith/LeePerrySmith.glb --method "$m" \
          --width 1280 --height 720 --out "$STORE/validate/$m" >> "$STORE/validate/log.txt" 2>&1; then
          echo "    ok" >> "$STORE/validate/commands.txt"
        else
          echo "    FAILED" >> "$STORE/validate/commands.txt"
        fi
      done
      find "$STORE/validate" -name '*.exr' -delete
      unset VK_LAYER_PATH ;;
    card)
      validation_layer
      DERMIS_TEST_DEVICE=nvidia DERMIS_ASSETS=$PWD/.assets timeout "$(left)" .bin/suite \
        accuracy:: --nocapture --test-threads 1 > "$STORE/card.txt" 2>&1
      echo "rc $?" >> "$STORE/card.txt"
      unset VK_LAYER_PATH ;;
    eval | dolly)
      STORE=$STORE/core OUT=$STORE/core DEADLINE=$(left) B=$B bash tools/perf_h100.sh "$part" > /dev/null 2>&1
      rm -f "$STORE/core/perf.tgz" ;;
    matrix)
      DEADLINE=$(left) bash tools/bench_matrix.sh "$B" "$STORE/matrix" > "$STORE/matrix.log" 2>&1 ;;
    t31 | apart | t44)
      DEADLINE=$(left) bash tools/tsd_table31.sh "$B" "$STORE/tsd" "$part" > "$STORE/tsd-$part.log" 2>&1 ;;
    *) echo "unknown part '$part' (valid: smoke card eval dolly matrix t31 apart t44)" >&2; exit 2 ;;
  esac
  echo "$part: $((SECONDS - t0)) s" >> "$STORE/parts.txt"
done
echo "done in $((SECONDS - START)) s" >> "$STORE/parts.txt"
tar czf "$OUT/h200.tgz" --exclude='*.exr' -C "$STORE" .
cat "$STORE/parts.txt"
