#!/usr/bin/env bash
# Issue 28 part 4 on the device machine ("a floor for every pass";
# docs/perf/issue28/floors.md has the predictions, written before the
# call): the whole frame benched with every kind of pass (shadow map,
# geometry, SSS on both paths, composite, bloom, each AA, a mix's merges),
# each pass with its floor or the reason it has none; the bloom's image
# before and after its fix compared byte for byte when the binary before it
# is carried as .bin/dermis-before.
#
#   OUT=$OUT bash tools/perf_floors.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis,
# stripped release build; optionally dermis-before, built before the bloom fix: 41b60b8 or 4e5c1d2),
# .assets (../shared/assets).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/floors
rm -rf "$R"
mkdir -p "$R" "$OUT"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
N=$ROOT/.bin/dermis
if ! "$N" devices 2>&1 | grep -qi nvidia; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
log() { echo "+ $*" >> "$R/commands.txt"; }
{
  "$N" --version
  "$N" devices
} > "$R/gpu.txt" 2>&1
LPS=$ROOT/.assets/lee-perry-smith/LeePerrySmith.glb
bench() { # name, args...
  local n=$1; shift
  log dermis bench "$@" --report "$R/$n.json"
  "$N" bench "$@" --report "$R/$n.json" > "$R/$n.txt" 2>&1
  echo "$n exit $?" >> "$R/exits.txt"
}
F="--warmup 20 --frames 200"
HD="--width 1920 --height 1080"
# shellcheck disable=SC2086
{
  # The frame of the example, with the bloom and each AA.
  bench close-compute-bloom-smaa $HD --shot close --method separable --path compute --bloom --aa smaa $F
  bench close-fragment-bloom-mlaa $HD --shot close --method separable --path fragment --bloom --aa mlaa $F
  bench close-fragment-fxaa $HD --shot close --method separable --path fragment --aa fxaa $F
  # The LPS portrait of docs/perf/h200-msaa (the bloom's 0.90 ms before the fix).
  bench lps-portrait-bloom --scene "$LPS" $HD --bloom $F
  # A mix (merges on both paths) and the other methods' compute passes.
  bench mix-3 $HD --shot mid --heads 3 --assign "0=ssg:path=compute,1=separable:path=compute,*=poisson" $F
  # The 2D gather's pass and its floor.
  bench close-gather-40 $HD --shot close --method gather --sample-budget 40 $F
  # What bounds the shadow map: its 2048^2 clear (the time follows the
  # map's area) or its triangles (the time stays).
  bench close-shadow-1024 $HD --shot close --method separable --path compute --shadow-size 1024 $F
  bench close-shadow-4096 $HD --shot close --method separable --path compute --shadow-size 4096 $F
}
# The bloom's image before and after its fix (the sizes pushed, not queried).
if [ -x "$ROOT/.bin/dermis-before" ]; then
  for b in dermis dermis-before; do
    "$ROOT/.bin/$b" render --scene "$LPS" $HD --bloom --out "$R/img-$b" > "$R/img-$b.txt" 2>&1
  done
  for f in frame.png diffuse.exr; do
    if cmp -s "$R/img-dermis/$f" "$R/img-dermis-before/$f"; then r=same; else r=DIFFERENT; fi
    echo "$f $r" >> "$R/bloom-image.txt"
  done
fi
cd "$R" && tar czf "$OUT/floors.tgz" --exclude='*.png' --exclude='*.exr' . && cd "$ROOT"
