#!/usr/bin/env bash
# The frames of docs/aa.md's "Table 9.1 re-scored", rendered on lavapipe with the
# fetch-counting build by `dermis budget --aa mlaa` (counts do not depend on the device's
# speed), then priced again by tools/examples/table91_rescore.rs:
#
#   tools/table91_frames.sh [BIN] [DIR]        BIN: target/release/dermis, DIR: out/table91
#   cargo run --release --features tools --example table91_rescore -- face=DIR/face/budget.json \
#     lines1.5=DIR/lines1.5/budget.json lines2.5=DIR/lines2.5/budget.json \
#     lines5=DIR/lines5/budget.json crowd16=DIR/crowd16/budget.json grid16=DIR/grid16/budget.json
#
# The portrait face, the thin-lines scene at 1.5, 2.5 and 5 head heights (the first is the
# game-like frame: 12% edge pixels), 16 heads in a crowd and in a grid; 1280x720 as run.
set -uo pipefail
BIN=${1:-target/release/dermis}
DIR=${2:-out/table91}
P=xbox360,geforce-9800-gtx-plus,geforce-gtx-470
common=(--device llvmpipe --as-run --aa mlaa --profile "$P" --width 1280 --height 720)
mkdir -p "$DIR"
frame() {
  local name=$1
  shift
  if "$BIN" budget "${common[@]}" "$@" --out "$DIR/$name" > "$DIR/$name.log" 2>&1; then
    echo "ok: $name"
  else
    echo "FAILED: $name: $(tail -1 "$DIR/$name.log")" >&2
  fi
}
frame face
for d in 1.5 2.5 5; do frame "lines$d" --scene builtin:lines --distance "$d"; done
frame crowd16 --heads 16
frame grid16 --heads 16 --layout grid
