#!/usr/bin/env bash
# The accuracy model's sweep (docs/accuracy.md, "The accuracy model"): every
# registered method's eval settings and none, on the Lee Perry-Smith head and the
# procedural face, at 8 scales from 0.1 to 10 px/mm x 4 key-light angles, against
# the ground truth, at each shadow-map size of SHADOWS (the shadow texel at the
# character is the model's third axis). Writes DIR/ASSET-sSIZE/ (eval.csv,
# eval.json, ASSET.toml, accuracy-ASSET.png/svg, loso.json, the log); then
#   dermis accuracy-merge DIR/*/ASSET.toml --out profiles/accuracy/ASSET.toml
# per asset updates the model.
#
#   bash tools/accuracy_sweep.sh [DERMIS] [DIR]
#     DERMIS   the binary (default target/release/dermis)
#     DIR      where to write (default out/accuracy)
#   W, H       the frame (default 640x360: the centre of the 1280x720 eval view)
#   HEAD       the head scan (default ../shared/assets/lee-perry-smith/LeePerrySmith.glb)
#   ASSETS     which heads (default "scan procedural")
#   SHADOWS    shadow-map sizes (default "2048 512 128 32")
#   SWEEPS     the sweeps in the order to run, as ASSET:SIZE words (default:
#              every size of SHADOWS for every asset of ASSETS, size by size)
#   JOBS       sweeps run at once (default 1; the sweep is mostly CPU work per
#              view, so a many-core host with one GPU runs several side by side)
#   DEADLINE   seconds after which no sweep is started, or left running
#              (default: none)
#   MIN_LEFT   seconds a sweep needs to be started (default 20)
#   ONLY       settings to sweep, as `eval --only` takes them, space-separated (METHOD or
#              METHOD/LABEL; default: the whole registry). Rows of a partial sweep are
#              merged into the model's files by tools/accuracy_merge.py.
#
# Measured: NVIDIA H200 at 640x360, see docs/perf/h200-accuracy/commands.txt;
# lavapipe on 2 cores, docs/accuracy.md.
set -uo pipefail
B=${1:-target/release/dermis}
DIR=${2:-out/accuracy}
W=${W:-640}
H=${H:-360}
HEAD=${HEAD:-../shared/assets/lee-perry-smith/LeePerrySmith.glb}
ASSETS=${ASSETS:-scan procedural}
SHADOWS=${SHADOWS:-2048 512 128 32}
JOBS=${JOBS:-1}
MIN_LEFT=${MIN_LEFT:-20}
ONLY_ARGS=()
for o in ${ONLY:-}; do ONLY_ARGS+=(--only "$o"); done
START=$SECONDS
mkdir -p "$DIR"
sweep() { # asset size
  local asset=$1 size=$2 left=$3
  local out="$DIR/$asset-s$size"
  local cmd=("$B" eval --scene "$HEAD" --scenes "accuracy:$asset" --width "$W" --height "$H" \
    --shadow-size "$size" --warmup 1 --frames 3 "${ONLY_ARGS[@]}" --out "$out")
  local t0=$SECONDS rc=0
  ${left:+timeout "$left"} "${cmd[@]}" > "$DIR/$asset-s$size.log" 2>&1 || rc=$?
  if (( rc == 0 )); then
    echo "+ ${cmd[*]}"$'\n'"    ok in $((SECONDS - t0)) s" >> "$DIR/commands.txt"
  else
    echo "+ ${cmd[*]}"$'\n'"    FAILED (rc $rc) after $((SECONDS - t0)) s" >> "$DIR/commands.txt"
  fi
}
if [ -z "${SWEEPS:-}" ]; then
  SWEEPS=$(for size in $SHADOWS; do for asset in $ASSETS; do printf '%s:%s ' "$asset" "$size"; done; done)
fi
for job in $SWEEPS; do
  asset=${job%%:*}
  size=${job##*:}
  while (( $(jobs -rp | wc -l) >= JOBS )); do wait -n; done
  left=${DEADLINE:+$((DEADLINE - (SECONDS - START)))}
  if [ -n "$left" ] && (( left < MIN_LEFT )); then
    echo "SKIPPED (deadline): $asset at shadow $size" >> "$DIR/commands.txt"
    continue
  fi
  sweep "$asset" "$size" "$left" &
done
wait
echo "done in $((SECONDS - START)) s" >> "$DIR/commands.txt"
cat "$DIR/commands.txt"
