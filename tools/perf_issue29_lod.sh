#!/usr/bin/env bash
# Issue 29's levels of detail on the device machine (docs/perf/issue29/README.md,
# "Levels of detail": predictions first, then the results): 256-character
# crowds at 1080p (the face moving, the Lee Perry-Smith head turning: --time 1)
# benched with --lod-pixels 0 (the full meshes), 0.5, 1 and 2; each level
# setting's frame rendered on the GPU and compared with the full meshes'
# (`dermis compare`: relative RMSE of the diffuse light over skin and FLIP,
# over all skin and per band).
#
#   OUT=$OUT bash tools/perf_issue29_lod.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis,
# stripped release build, and DejaVuSans.ttf), .assets (../shared/assets).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue29-lod
rm -rf "$R"
mkdir -p "$R" "$OUT"
# shellcheck source=tools/device_env.sh
. "$ROOT/tools/device_env.sh"
F="--warmup 20 --frames 200 --width 1920 --height 1080 --method separable --heads 256 --time 1"
for scene in "face|" "lps|--scene $LPS"; do
  s=${scene%%|*}; sa=${scene#*|}
  for px in 0 0.5 1 2; do
    # shellcheck disable=SC2086
    bench "$s-256-lod$px" $sa --lod-pixels $px $F
    log dermis render $sa --lod-pixels $px --heads 256 --time 1 --width 1920 --height 1080 --frames 1 --warmup 0 --out "$R/img-$s-lod$px"
    # shellcheck disable=SC2086
    "$N" render $sa --lod-pixels $px --heads 256 --time 1 --width 1920 --height 1080 \
      --frames 1 --warmup 0 --out "$R/img-$s-lod$px" > "$R/img-$s-lod$px.txt" 2>&1
    echo "img-$s-lod$px exit $?" >> "$R/exits.txt"
  done
  for px in 0.5 1 2; do
    log dermis compare "$R/img-$s-lod$px" "$R/img-$s-lod0" --out "$R/cmp-$s-lod$px"
    "$N" compare "$R/img-$s-lod$px" "$R/img-$s-lod0" --out "$R/cmp-$s-lod$px" \
      > "$R/cmp-$s-lod$px.txt" 2>&1
    echo "cmp-$s-lod$px exit $?" >> "$R/exits.txt"
  done
done
# Keep the numbers and two frames, not every image.
cp "$R/img-face-lod0/frame.png" "$R/face-lod0.png"
cp "$R/img-face-lod1/frame.png" "$R/face-lod1.png"
find "$R" -name '*.exr' -delete
find "$R" -mindepth 2 -name '*.png' -delete
tar -C /tmp -czf "$OUT/issue29-lod.tgz" issue29-lod
