#!/usr/bin/env bash
# The frames the budget calibration prices (profiles/frames/), rendered on lavapipe with
# the fetch-counting build by `dermis budget` (counts do not depend on the device's speed):
#
#   published/  the scenes of the published timings, as docs/budget-calibration.md reads them
#   h100/       the configuration of every report of docs/perf/h100/ (its declared work and
#               counted fetches; the H100's own counts and times come from the report)
#   matrix/     tools/bench_matrix.sh's configurations, paired with docs/perf/h200/ (or any
#               directory of new-format bench reports of that matrix)
#   porting/    docs/budget.md's frames: the head at 1280x720, 1/3/5 characters, close/mid/far,
#               every real-time method (h{N}_{shot}_{method}.json)
#   issue28/    the H100 runs of docs/perf/issue28/h100/ that calibrate the compute path (1080p
#               close-up: separable, ssg, ss-jittered, Poisson on the compute path, the gather
#               at 20/40/80 samples and Burley's at 40) and those held out of the fit (1080p
#               mid, 4K): the default (portrait) view, as `dermis bench` ran them
#   msaa/       the configurations of docs/perf/h200-msaa (the scan's portrait at 720p and
#               1080p, 16 heads at 4 head heights at 720p; at 1x, with MLAA at 720p, SMAA 1x at 1080p): their
#               counted fetches for tools/examples/msaa_score.rs (the H200's reports hold the
#               counts of every sample count, lavapipe renders 1x and 4x only)
#
#   tools/budget_frames.sh [BIN] [PART...]     PART: published h100 matrix porting msaa issue28 (default: all)
#
# BIN defaults to target/release/dermis. Existing frames are kept (delete to redo).
set -uo pipefail
BIN=${1:-target/release/dermis}
shift || true
ASSET=${ASSET:-../shared/assets/lee-perry-smith/LeePerrySmith.glb}
D=profiles/frames
parts=("$@")
[ ${#parts[@]} -eq 0 ] && parts=(published h100 matrix porting msaa issue28)
# The view of frame(): the study view of the recorded runs before issue 15 (issue28 sets its own).
VIEW=(--view study)

# frame DIR NAME dermis-budget-args...: one frame on lavapipe.
frame() {
  local dir=$1 name=$2
  shift 2
  local target="$D/$dir/$name.json"
  [ -e "$target" ] && return
  mkdir -p "$D/$dir"
  local tmp
  tmp=$(mktemp -d)
  if "$BIN" budget "${VIEW[@]}" --device llvmpipe --profile nvidia-h100 --warmup 0 --frames 1 "$@" \
      --out "$tmp" > "$tmp/log.txt" 2>&1; then
    cp "$tmp"/frames/*.json "$target"
    echo "ok: $dir/$name"
  else
    echo "FAILED: $dir/$name: $(tail -1 "$tmp/log.txt")" >&2
  fi
  rm -rf "$tmp"
}

published() {
  local head=(--scene "$ASSET")
  # Thesis 000 Table 6.2 (1080p, 17 samples, the SSSS shader: no follow-surface, passes on
  # the whole screen with a stencil). Close: the head almost fills the screen (1.852 head
  # heights, 55% skin); mid: a mid shot (its counts are then read as "no skin shaded").
  local t62=(--width 1920 --height 1080 --sss-region screen)
  frame published t62_separable_close "${head[@]}" "${t62[@]}" --distance 1.852 --no-follow-surface
  frame published t62_separable_mid "${head[@]}" "${t62[@]}" --shot mid --no-follow-surface
  frame published t62_ssg_close "${head[@]}" "${t62[@]}" --distance 1.852 --method ssg
  frame published t62_ssg_mid "${head[@]}" "${t62[@]}" --shot mid --method ssg
  # Fig. 6.4 (GTX 470, 1080p): the head at screen height, 9/17/33 samples.
  for s in 9 17 33; do
    frame published "f64_s$s" "${head[@]}" "${t62[@]}" --shot close --samples "$s" --no-follow-surface
  done
  # Table 4.4 (8600M GS, 720p): 1/3/5 characters near the camera (crowd: the camera stays).
  for h in 1 3 5; do
    local t44=(--width 1280 --height 720 --sss-region screen --distance 1.852 --heads "$h")
    frame published "t44_ssg_${h}h" "${head[@]}" "${t44[@]}" --method ssg
    frame published "t44_jittered_${h}h" "${head[@]}" "${t44[@]}" --method ss-jittered
  done
  # Seed 001 Table 5.2 (GTX 970M, 1681x942, 20 samples, depth taps): close, mid, far with
  # 21 samples (dermis's kernels are odd; the calibration scales the taps to 19).
  for shot in close mid far; do
    frame published "t52_$shot" "${head[@]}" --width 1681 --height 942 --sss-region screen \
      --shot "$shot" --samples 21
  done
}

# The H100 reports' own command lines, on lavapipe: their scene path replaced by ASSET,
# and the grid layout the multi-head runs had before the crowd layout existed.
h100() {
  for r in docs/perf/h100/*.json; do
    local name cmd
    name=$(basename "$r" .json)
    cmd=$(grep -m1 '"command"' "$r" | sed -e 's/^ *"command": "//' -e 's/",\?$//')
    read -r -a words <<< "$cmd"
    local args=() skip=0 heads=1
    for ((i = 2; i < ${#words[@]}; i++)); do
      local w=${words[$i]}
      if [ $skip = 1 ]; then skip=0; continue; fi
      case $w in
        --report) skip=1 ;;
        --scene) args+=(--scene "$ASSET"); skip=1 ;;
        --heads) heads=${words[$((i + 1))]}; args+=("$w") ;;
        *) args+=("$w") ;;
      esac
    done
    [ "$heads" != 1 ] && args+=(--layout grid)
    frame h100 "$name" "${args[@]}"
  done
}

matrix() {
  mkdir -p "$D/matrix"
  DEADLINE=100000 tools/bench_matrix.sh "$BIN" "$D/matrix" --frames
}

porting() {
  mkdir -p "$D/porting"
  for h in 1 3 5; do
    for shot in close mid far; do
      local name="h${h}_${shot}"
      ls "$D/porting/${name}_"*.json > /dev/null 2>&1 && continue
      local tmp
      tmp=$(mktemp -d)
      if "$BIN" budget --view study --device llvmpipe --profile xbox360 --compare-methods --warmup 0 --frames 1 \
          --scene "$ASSET" --width 1280 --height 720 --heads "$h" --shot "$shot" \
          --out "$tmp" > "$tmp/log.txt" 2>&1; then
        for f in "$tmp"/frames/*.json; do cp "$f" "$D/porting/${name}_$(basename "$f")"; done
        echo "ok: porting/$name"
      else
        echo "FAILED: porting/$name: $(tail -1 "$tmp/log.txt")" >&2
      fi
      rm -rf "$tmp"
    done
  done
  # What a port of the separable method would ship: 9 samples, no depth taps (the SSSS
  # demo's default).
  for h in 1 3 5; do
    for shot in close mid far; do
      local target="$D/porting/h${h}_${shot}_separable-s9nf.json"
      [ -e "$target" ] && continue
      local tmp
      tmp=$(mktemp -d)
      if "$BIN" budget --view study --device llvmpipe --profile xbox360 --warmup 0 --frames 1 --scene "$ASSET" \
          --width 1280 --height 720 --heads "$h" --shot "$shot" --samples 9 --no-follow-surface \
          --out "$tmp" > "$tmp/log.txt" 2>&1; then
        cp "$tmp/frames/separable.json" "$target"
        echo "ok: $target"
      else
        echo "FAILED: $target: $(tail -1 "$tmp/log.txt")" >&2
      fi
      rm -rf "$tmp"
    done
  done
}

# docs/perf/h200-msaa/aa.sh's views (the default portrait view, not --view study).
msaa() {
  mkdir -p "$D/msaa"
  local name args
  for spec in "portrait-1280x720|--width 1280 --height 720" \
      "portrait-1920x1080|--width 1920 --height 1080" \
      "crowd16-1280x720|--width 1280 --height 720 --heads 16 --distance 4" \
      "portrait-1280x720-mlaa|--width 1280 --height 720 --aa mlaa" \
      "portrait-1920x1080-smaa|--width 1920 --height 1080 --aa smaa" \
      "crowd16-1280x720-mlaa|--width 1280 --height 720 --heads 16 --distance 4 --aa mlaa"; do
    name=${spec%%|*}
    read -r -a args <<< "${spec#*|}"
    local target="$D/msaa/$name.json"
    [ -e "$target" ] && continue
    local tmp
    tmp=$(mktemp -d)
    if "$BIN" budget --device llvmpipe --as-run --profile nvidia-h200 --warmup 0 --frames 1 \
        --scene "$ASSET" "${args[@]}" --out "$tmp" > "$tmp/log.txt" 2>&1; then
      cp "$tmp/frames/separable.json" "$target"
      echo "ok: msaa/$name"
    else
      echo "FAILED: msaa/$name: $(tail -1 "$tmp/log.txt")" >&2
    fi
    rm -rf "$tmp"
  done
}

# docs/perf/issue28/h100/'s runs (tools/perf_issue28.sh), by report name: the default view, as
# bench ran them. Their reports' `settings` cannot be replayed (the gather's budget was
# `--samples` then, `--sample-budget` now; its profile `--profile`, now `--diffusion-profile`).
issue28() {
  VIEW=(--view portrait)
  local hd=(--width 1920 --height 1080) uhd=(--width 3840 --height 2160) spec name args
  for spec in \
      "1080-close-1-compute|${hd[*]} --shot close --method separable --path compute" \
      "1080-close-1-ssg-compute|${hd[*]} --shot close --method ssg --path compute" \
      "1080-close-1-ss-jittered-compute|${hd[*]} --shot close --method ss-jittered --path compute" \
      "1080-close-1-poisson-compute|${hd[*]} --shot close --method poisson --path compute" \
      "1080-close-1-gather-20|${hd[*]} --shot close --method gather --sample-budget 20" \
      "1080-close-1-gather-40|${hd[*]} --shot close --method gather --sample-budget 40" \
      "1080-close-1-gather-80|${hd[*]} --shot close --method gather --sample-budget 80" \
      "1080-close-1-gather-burley-40|${hd[*]} --shot close --method gather --sample-budget 40 --diffusion-profile burley" \
      "1080-mid-1-compute|${hd[*]} --shot mid --method separable --path compute" \
      "1080-mid-1-ssg-compute|${hd[*]} --shot mid --method ssg --path compute" \
      "1080-mid-1-gather-20|${hd[*]} --shot mid --method gather --sample-budget 20" \
      "1080-mid-1-gather-40|${hd[*]} --shot mid --method gather --sample-budget 40" \
      "1080-mid-1-gather-80|${hd[*]} --shot mid --method gather --sample-budget 80" \
      "1080-mid-1-gather-burley-40|${hd[*]} --shot mid --method gather --sample-budget 40 --diffusion-profile burley" \
      "2160-close-1-compute|${uhd[*]} --shot close --method separable --path compute" \
      "2160-mid-1-compute|${uhd[*]} --shot mid --method separable --path compute"; do
    name=${spec%%|*}
    read -r -a args <<< "${spec#*|}"
    frame issue28 "$name" "${args[@]}"
  done
  VIEW=(--view study)
}

for p in "${parts[@]}"; do
  case $p in
    published) published ;;
    h100) h100 ;;
    matrix) matrix ;;
    porting) porting ;;
    msaa) msaa ;;
    issue28) issue28 ;;
    *) echo "unknown part '$p' (valid: published h100 matrix porting msaa issue28)" >&2; exit 2 ;;
  esac
done
