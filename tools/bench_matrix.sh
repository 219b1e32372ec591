#!/usr/bin/env bash
# The bench matrix of docs/perf/ (issue 2: separable at 1080p close/mid, 9/17/33 samples;
# issue 3: every method at 720p and 1080p, three distances, 1/3/5 heads), one report per
# configuration, named as in docs/perf/h100/ so the budget calibration pairs them.
#
#   tools/bench_matrix.sh BIN OUTDIR            # bench: OUTDIR/NAME.json, a `dermis bench` report each
#   tools/bench_matrix.sh BIN OUTDIR --frames   # the frames the calibration pairs with them: OUTDIR/NAME.json,
#                                               # `dermis budget`'s frame of the same configuration on lavapipe
#                                               # (fetches counted), as committed in profiles/frames/matrix/
#
# On the device machine (one H200), from the repository root, with a release build carried:
#   tools/bench_matrix.sh .bin/dermis out/h200 && tar czf "$OUT/h200.tgz" -C out h200
# then commit the reports as docs/perf/h200/NAME.json; `cargo run --release --features tools --example
# budget_calibration` scores the model on them. Set up the device
# as tools/perf_h100.sh does: .gl (Vulkan loader debs) is unpacked here when present, and the
# NVIDIA ICD is named when the loader does not find it.
#
# ASSET: the Lee Perry-Smith head (default ../shared/assets/lee-perry-smith/LeePerrySmith.glb,
# else .assets/lee-perry-smith/LeePerrySmith.glb). EXTRA: more arguments for every run.
# A run whose output exists is skipped (a second call resumes); after DEADLINE seconds
# (default 540, inside the device's 10-minute calls) no new run starts.
set -uo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 BIN OUTDIR [--frames]" >&2
  exit 2
fi
BIN=$1
OUT=$2
MODE=${3:-bench}
START=$SECONDS
DEADLINE=${DEADLINE:-540}
read -r -a EXTRA <<< "${EXTRA:-}"
ASSET=${ASSET:-../shared/assets/lee-perry-smith/LeePerrySmith.glb}
[ -f "$ASSET" ] || ASSET=.assets/lee-perry-smith/LeePerrySmith.glb
[ -f "$ASSET" ] || { echo "no head asset at $ASSET (set ASSET)" >&2; exit 2; }
mkdir -p "$OUT"
if [ "$MODE" != --frames ]; then
  if [ -d .gl ]; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
  fi
  if ! "$BIN" devices 2>&1 | grep -qi nvidia && [ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  fi
  "$BIN" devices > "$OUT/devices.txt" 2>&1
fi

# run NAME dermis-args...: one configuration.
run() {
  local name=$1
  shift
  local target="$OUT/$name.json"
  [ -e "$target" ] && return
  if (( SECONDS - START > DEADLINE )); then
    echo "SKIPPED (deadline): $name" >&2
    return
  fi
  if [ "$MODE" = --frames ]; then
    local tmp
    tmp=$(mktemp -d)
    if "$BIN" budget --view study --device llvmpipe --profile nvidia-h200 --warmup 0 --frames 1 \
        --scene "$ASSET" "${EXTRA[@]}" "$@" --out "$tmp" > "$tmp/log.txt" 2>&1; then
      cp "$tmp"/frames/*.json "$target"
      echo "ok: $name"
    else
      echo "FAILED: $name: $(tail -1 "$tmp/log.txt")" >&2
    fi
    rm -rf "$tmp"
  else
    echo "+ $BIN bench --view study --scene $ASSET ${EXTRA[*]} $* --report $target"
    "$BIN" bench --view study --scene "$ASSET" "${EXTRA[@]}" "$@" --report "$target" > /dev/null \
      || echo "FAILED: $name" >&2
  fi
}

# Issue 2: separable SSS, 1080p, close-up (9, 17, 33 samples) and mid shot.
for s in 17 9 33; do
  run "sep_1080p_close_s$s" --width 1920 --height 1080 --shot close --samples "$s"
done
run sep_1080p_mid_s17 --width 1920 --height 1080 --shot mid --samples 17

# Issue 3: the thesis' three distances (zoom 1.037, near 1.852, far 4.889 head heights)
# x 1/3/5 characters (crowd layout: the camera stays) x every method setting.
for res in "1280 720" "1920 1080"; do
  read -r W H <<< "$res"
  for d in zoom:1.037 near:1.852 far:4.889; do
    for h in 1 3 5; do
      tag="${W}x${H}_${d%%:*}_${h}h"
      args=(--width "$W" --height "$H" --distance "${d##*:}" --heads "$h")
      run "ssg_lod_$tag" "${args[@]}" --method ssg
      run "ssg_nolod_$tag" "${args[@]}" --method ssg --no-lod
      run "separable_$tag" "${args[@]}" --method separable
      run "jittered_$tag" "${args[@]}" --method ss-jittered
      run "poisson_$tag" "${args[@]}" --method poisson
    done
  done
  run "ssg_branch_${W}x${H}_zoom_1h" --width "$W" --height "$H" --distance 1.037 --method ssg --mask branch
done
echo "done in $((SECONDS - START)) s: $(ls "$OUT"/*.json 2>/dev/null | wc -l) reports in $OUT"
