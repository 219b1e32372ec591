#!/usr/bin/env bash
# Every device-machine measurement of docs/perf/ and docs/accuracy.md.
#
#   bash tools/perf_h100.sh [PART...]      PART: smoke issue2 issue3-720 issue3-1080 frame-ab nofollow images dolly eval
#                                          (default: all, in that order)
#
# Run it on the device machine from the repository root with these carried (see
# /work/.library/device/README.md and docs/perf/README.md):
#   .gl      Vulkan loader debs (apt-get download libvulkan1 ...), unpacked into /
#   .vvl     vulkan-validationlayers deb, unpacked under /tmp (smoke part only)
#   .bin     a stripped release build:  strip -o .bin/dermis target/release/dermis
#            and a font for the chart:  cp /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf .bin/
#   .assets  a copy of ../shared/assets: cp -r ../shared/assets .assets
#
# A call may run at most 10 minutes, so the script stops starting runs after
# DEADLINE seconds (default 540) and writes what it has. Results accumulate in
# $STORE (default /tmp/dermis-perf) and a run whose report exists is skipped, so
# a second call on the still-warm machine resumes where the first stopped.
# Everything lands in $OUT/perf.tgz (the device tool returns at most 8 files).
#
# DRY=1 checks the script here on lavapipe: tiny sizes, 1+2 frames, no .gl.
set -uo pipefail
START=$SECONDS
DEADLINE=${DEADLINE:-540}
OUT=${OUT:-out}
STORE=${STORE:-/tmp/dermis-perf}
P=$STORE/perf
B=${B:-.bin/dermis}
A=.assets/lee-perry-smith/LeePerrySmith.glb
mkdir -p "$P" "$OUT"
. "$(dirname "$0")/methods.sh"
DRY=${DRY:-0}
if [ "$DRY" = 1 ]; then
  EXTRA=(--device llvmpipe --warmup 1 --frames 2)
  EVAL_FRAMES=(--density 8)
  A=../shared/assets/lee-perry-smith/LeePerrySmith.glb
else
  EXTRA=()
  EVAL_FRAMES=(--warmup 5 --frames 30)
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
  # The chart needs a TrueType font; the device machine may have none.
  [ -f .bin/DejaVuSans.ttf ] && export DERMIS_FONT=$PWD/.bin/DejaVuSans.ttf
  if ! "$B" devices 2>&1 | grep -qi nvidia; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  fi
fi
# In dry mode every size is divided by 8.
w() { if [ "$DRY" = 1 ]; then echo $(($1 / 8)); else echo "$1"; fi; }

# run NAME OUTPUT dermis-args...: skipped when OUTPUT exists or the deadline has passed.
run() {
  local name=$1 output=$2
  shift 2
  if [ -e "$output" ]; then return; fi
  if (( SECONDS - START > DEADLINE )); then
    echo "SKIPPED (deadline): dermis $*" >> "$P/commands.txt"
    return
  fi
  echo "+ dermis $*" >> "$P/commands.txt"
  local t0=$SECONDS
  echo "=== $name: dermis $*" >> "$P/log.txt"
  # Nothing may outlive the call: the last run is cut at START + DEADLINE + 50 s.
  local left=$((DEADLINE + 50 - (SECONDS - START)))
  # The recorded runs were made at the view now called study (the default became
  # the portrait in issue 15): the commands that take a view keep it.
  local sub=$1
  shift
  local view=()
  case $sub in render | bench | eval | budget | reference) view=(--view study) ;; esac
  if timeout $((left < 300 ? left : 300)) "$B" "$sub" "${view[@]}" "$@" >> "$P/log.txt" 2>&1; then
    echo "    ok in $((SECONDS - t0)) s" >> "$P/commands.txt"
  else
    echo "    FAILED (rc $?) after $((SECONDS - t0)) s" >> "$P/commands.txt"
  fi
}

smoke() {
  { nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader || true; "$B" devices; } > "$P/gpu.txt" 2>&1
  # The same renderer under the Khronos validation layer (synchronization
  # validation on; any message is an error) on a real GPU: the default scene
  # with every method of the registry, and the head with ssg.
  if [ "$DRY" != 1 ] && ls .vvl/*.deb > /dev/null 2>&1; then
    mkdir -p /tmp/vvl && for f in .vvl/*.deb; do dpkg -x "$f" /tmp/vvl; done
    export VK_LAYER_PATH=/tmp/vvl/usr/share/vulkan/explicit_layer.d
    export LD_LIBRARY_PATH=/tmp/vvl/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  fi
  for m in $(dermis_methods "$B"); do
    run "validate $m" "$P/validate/$m/report.json" render --validate "${EXTRA[@]}" --method "$m" \
      --width "$(w 1280)" --height "$(w 720)" --out "$P/validate/$m"
  done
  run "validate head ssg" "$P/validate/head_ssg/report.json" render --validate "${EXTRA[@]}" --scene "$A" \
    --method ssg --width "$(w 1280)" --height "$(w 720)" --out "$P/validate/head_ssg"
  # Several SSS-region rectangles (three heads far away).
  run "validate 3 heads separable" "$P/validate/heads3_separable/report.json" render --validate "${EXTRA[@]}" --scene "$A" \
    --heads 3 --distance 4.889 --width "$(w 1280)" --height "$(w 720)" --out "$P/validate/heads3_separable"
  unset VK_LAYER_PATH
}

issue2() {
  # Separable SSS, 1080p, close-up and mid shot, 17 samples (and 9, 33 at close-up).
  for s in 17 9 33; do
    run "sep close s$s" "$P/sep_1080p_close_s$s.json" bench "${EXTRA[@]}" --scene "$A" \
      --width "$(w 1920)" --height "$(w 1080)" --shot close --samples "$s" --report "$P/sep_1080p_close_s$s.json"
  done
  run "sep mid s17" "$P/sep_1080p_mid_s17.json" bench "${EXTRA[@]}" --scene "$A" \
    --width "$(w 1920)" --height "$(w 1080)" --shot mid --samples 17 --report "$P/sep_1080p_mid_s17.json"
  run "render close" "$P/close_render/frame.png" render "${EXTRA[@]}" --scene "$A" \
    --width "$(w 1920)" --height "$(w 1080)" --shot close --out "$P/close_render"
}

# The thesis' three distances (zoom 28, near 50, far 132 units for a 27-unit head
# = 1.037, 1.852, 4.889 head heights) x 1/3/5 heads x methods.
issue3() {
  local W=$1 H=$2
  for d in zoom:1.037 near:1.852 far:4.889; do
    for h in 1 3 5; do
      local tag="${W}x${H}_${d%%:*}_${h}h"
      local args=(bench "${EXTRA[@]}" --scene "$A" --width "$(w "$W")" --height "$(w "$H")" --distance "${d##*:}" --heads "$h")
      run "ssg lod $tag" "$P/ssg_lod_$tag.json" "${args[@]}" --method ssg --report "$P/ssg_lod_$tag.json"
      run "ssg nolod $tag" "$P/ssg_nolod_$tag.json" "${args[@]}" --method ssg --no-lod --report "$P/ssg_nolod_$tag.json"
      run "separable $tag" "$P/separable_$tag.json" "${args[@]}" --method separable --report "$P/separable_$tag.json"
      run "jittered $tag" "$P/jittered_$tag.json" "${args[@]}" --method ss-jittered --report "$P/jittered_$tag.json"
      run "poisson $tag" "$P/poisson_$tag.json" "${args[@]}" --method poisson --report "$P/poisson_$tag.json"
    done
  done
  run "ssg branch ${W}x${H}" "$P/ssg_branch_${W}x${H}_zoom_1h.json" bench "${EXTRA[@]}" --scene "$A" \
    --width "$(w "$W")" --height "$(w "$H")" --distance 1.037 --method ssg --mask branch \
    --report "$P/ssg_branch_${W}x${H}_zoom_1h.json"
}

# The same benches with the SSS passes on the whole frame (--sss-region frame, once
# spelled screen): what limiting the seed copies and the draws to the skin's region
# saves. (The part was called screen-ab, still accepted; its reports stay in screen/,
# where docs/perf/ recorded them.)
frame_ab() {
  for res in "1280 720" "1920 1080"; do
    set -- $res
    for d in zoom:1.037 near:1.852 far:4.889; do
      for h in 1 3; do
        local tag="${1}x${2}_${d%%:*}_${h}h"
        local args=(bench "${EXTRA[@]}" --scene "$A" --width "$(w "$1")" --height "$(w "$2")" --distance "${d##*:}" --heads "$h" --sss-region frame)
        run "screen ssg lod $tag" "$P/screen/ssg_lod_$tag.json" "${args[@]}" --method ssg --report "$P/screen/ssg_lod_$tag.json"
        run "screen ssg nolod $tag" "$P/screen/ssg_nolod_$tag.json" "${args[@]}" --method ssg --no-lod --report "$P/screen/ssg_nolod_$tag.json"
        run "screen separable $tag" "$P/screen/separable_$tag.json" "${args[@]}" --method separable --report "$P/screen/separable_$tag.json"
      done
    done
  done
  run "screen sep close s17" "$P/screen/sep_1080p_close_s17.json" bench "${EXTRA[@]}" --scene "$A" --sss-region frame \
    --width "$(w 1920)" --height "$(w 1080)" --shot close --samples 17 --report "$P/screen/sep_1080p_close_s17.json"
}

# Separable without follow-surface (the SSSS demo's default: no depth taps),
# the configuration of the thesis' 1.05 ms, against ssg at the same shots.
nofollow() {
  for shot in close mid; do
    run "sep nofollow $shot" "$P/nofollow/sep_1080p_${shot}_s17.json" bench "${EXTRA[@]}" --scene "$A" --no-follow-surface \
      --width "$(w 1920)" --height "$(w 1080)" --shot "$shot" --samples 17 --report "$P/nofollow/sep_1080p_${shot}_s17.json"
    run "ssg $shot" "$P/nofollow/ssg_1080p_${shot}.json" bench "${EXTRA[@]}" --scene "$A" --method ssg \
      --width "$(w 1920)" --height "$(w 1080)" --shot "$shot" --report "$P/nofollow/ssg_1080p_${shot}.json"
  done
  for res in "1280 720" "1920 1080"; do
    set -- $res
    for d in zoom:1.037 near:1.852; do
      local tag="${1}x${2}_${d%%:*}_1h"
      run "sep nofollow $tag" "$P/nofollow/separable_$tag.json" bench "${EXTRA[@]}" --scene "$A" --no-follow-surface \
        --width "$(w "$1")" --height "$(w "$2")" --distance "${d##*:}" --method separable --report "$P/nofollow/separable_$tag.json"
    done
  done
}

# Pictures of the failure cases for docs/accuracy.md: each method and the
# reference, rendered, then compared (false-colour error images); the .exr
# dumps are deleted so the tarball stays small.
images() {
  local I=$P/images W=640 H=360
  local head=(--scene "$A" --distance 1.852 --light-azimuth 150 --light-elevation 45)
  local thin=(--light-azimuth 165 --light-elevation 5)
  local band=(--light-azimuth 80 --light-elevation 10)
  for case in head thin band; do
    local -n args=$case
    run "img $case reference" "$I/$case/reference/frame.png" render "${EXTRA[@]}" "${args[@]}" --width $W --height $H --method reference --out "$I/$case/reference"
  done
  # Every method but the ground truth (rendered above) beside it.
  for m in $(dermis_methods "$B" 'not m["ground_truth"]'); do
    run "img head $m" "$I/head/$m/frame.png" render "${EXTRA[@]}" "${head[@]}" --width $W --height $H --method "$m" --out "$I/head/$m"
  done
  run "img head separable nofollow" "$I/head/separable-nofollow/frame.png" render "${EXTRA[@]}" "${head[@]}" --width $W --height $H --no-follow-surface --out "$I/head/separable-nofollow"
  for m in separable ssg; do
    run "img thin $m" "$I/thin/$m/frame.png" render "${EXTRA[@]}" "${thin[@]}" --width $W --height $H --method "$m" --out "$I/thin/$m"
    run "img thin $m notrans" "$I/thin/$m-notrans/frame.png" render "${EXTRA[@]}" "${thin[@]}" --width $W --height $H --method "$m" --no-transmittance --out "$I/thin/$m-notrans"
  done
  for n in 9 33; do
    run "img band s$n" "$I/band/separable-s$n/frame.png" render "${EXTRA[@]}" "${band[@]}" --width $W --height $H --samples $n --out "$I/band/separable-s$n"
  done
  for d in "$I"/*/*/; do
    case $d in */reference/) continue ;; esac
    run "compare $d" "$d/compare.json" compare "$d" "$(dirname "$d")/reference"
  done
  find "$I" -name '*.exr' -delete
}

# Error along a camera dolly (1 to 24 head heights), 720p: where LOD steps.
dolly() {
  run "eval dolly 720p" "$P/dolly/eval.csv" eval "${EXTRA[@]}" --scene "$A" --scenes dolly \
    --width "$(w 1280)" --height "$(w 720)" "${EVAL_FRAMES[@]}" --out "$P/dolly"
}

# A few benches again after a change that should not move them.
recheck() {
  run "recheck sep close" "$P/recheck/sep_1080p_close_s17.json" bench "${EXTRA[@]}" --scene "$A" \
    --width "$(w 1920)" --height "$(w 1080)" --shot close --samples 17 --report "$P/recheck/sep_1080p_close_s17.json"
  run "recheck ssg far 3h" "$P/recheck/ssg_lod_1280x720_far_3h.json" bench "${EXTRA[@]}" --scene "$A" \
    --width "$(w 1280)" --height "$(w 720)" --distance 4.889 --heads 3 --method ssg --report "$P/recheck/ssg_lod_1280x720_far_3h.json"
  run "recheck ssg far 1h 1080p" "$P/recheck/ssg_lod_1920x1080_far_1h.json" bench "${EXTRA[@]}" --scene "$A" \
    --width "$(w 1920)" --height "$(w 1080)" --distance 4.889 --method ssg --report "$P/recheck/ssg_lod_1920x1080_far_1h.json"
}

eval_chart() {
  # The cost/error chart on the thesis' scene set at 720p.
  run "eval thesis 720p" "$P/eval/eval.csv" eval "${EXTRA[@]}" --scene "$A" --scenes thesis \
    --width "$(w 1280)" --height "$(w 720)" "${EVAL_FRAMES[@]}" --out "$P/eval"
}

parts=("$@")
[ ${#parts[@]} -eq 0 ] && parts=(smoke issue2 issue3-720 issue3-1080 frame-ab nofollow images dolly eval)
for part in "${parts[@]}"; do
  case $part in
    smoke) smoke ;;
    issue2) issue2 ;;
    issue3-720) issue3 1280 720 ;;
    issue3-1080) issue3 1920 1080 ;;
    frame-ab | screen-ab) frame_ab ;;
    nofollow) nofollow ;;
    images) images ;;
    dolly) dolly ;;
    recheck) recheck ;;
    eval) eval_chart ;;
    *) echo "unknown part '$part' (valid: smoke issue2 issue3-720 issue3-1080 frame-ab nofollow images dolly recheck eval)" >&2; exit 2 ;;
  esac
done
echo "done in $((SECONDS - START)) s" >> "$P/commands.txt"
tar czf "$OUT/perf.tgz" -C "$STORE" perf
cat "$P/commands.txt"
