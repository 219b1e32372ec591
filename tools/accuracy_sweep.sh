#!/usr/bin/env bash
# The accuracy model's sweep (docs/accuracy.md, "The accuracy model"): every
# registered method's eval settings and none, on the Lee Perry-Smith head and the
# procedural face, at 8 scales from 0.1 to 10 px/mm x 4 key-light angles, against
# the ground truth. Writes DIR/scan/ and DIR/procedural/ (eval.csv, eval.json,
# ASSET.toml, accuracy-ASSET.png/svg, loso.json, the log); copy DIR/*/ASSET.toml
# into profiles/accuracy/ to update the model.
#
#   bash tools/accuracy_sweep.sh [DERMIS] [DIR]
#     DERMIS   the binary (default target/release/dermis)
#     DIR      where to write (default out/accuracy)
#   W, H       the frame (default 640x360: the centre of the 1280x720 eval view)
#   HEAD       the head scan (default ../shared/assets/lee-perry-smith/LeePerrySmith.glb)
#   DEADLINE   seconds after which no asset's sweep is started or left running
#              (default: none)
#
# Measured: NVIDIA H200 at 640x360, see docs/perf/h200-accuracy/commands.txt;
# lavapipe on 2 cores, docs/accuracy.md.
set -uo pipefail
B=${1:-target/release/dermis}
DIR=${2:-out/accuracy}
W=${W:-640}
H=${H:-360}
HEAD=${HEAD:-../shared/assets/lee-perry-smith/LeePerrySmith.glb}
START=$SECONDS
mkdir -p "$DIR"
for asset in scan procedural; do
  left=${DEADLINE:+$((DEADLINE - (SECONDS - START)))}
  if [ -n "$left" ] && (( left < 20 )); then
    echo "SKIPPED (deadline): $asset" | tee -a "$DIR/commands.txt"
    continue
  fi
  cmd=("$B" eval --scene "$HEAD" --scenes "accuracy:$asset" --width "$W" --height "$H" \
    --warmup 1 --frames 3 --out "$DIR/$asset")
  echo "+ ${cmd[*]}" >> "$DIR/commands.txt"
  t0=$SECONDS
  if ${left:+timeout "$left"} "${cmd[@]}" > "$DIR/$asset.log" 2>&1; then
    echo "    ok in $((SECONDS - t0)) s" >> "$DIR/commands.txt"
  else
    echo "    FAILED (rc $?) after $((SECONDS - t0)) s" >> "$DIR/commands.txt"
  fi
done
echo "done in $((SECONDS - START)) s" >> "$DIR/commands.txt"
cat "$DIR/commands.txt"
