#!/usr/bin/env bash
# Issue 28 on the device machine (docs/perf/issue28/README.md has the
# predictions, written before the call, and the results): separable SSS on
# the fragment path and on the compute path, benched in turn in one call,
# at 1080p and 4K, close-up and mid, 1 and 16 characters (the procedural
# head), and the Lee Perry-Smith head at 1080p close-up; then both paths'
# frames of the 1080p close-up rendered on the GPU and compared there
# (`dermis compare`: relative RMSE of the diffuse light over skin, FLIP;
# `cmp`: whether the diffuse EXRs are the same bytes).
#
#   OUT=$OUT bash tools/perf_issue28.sh
#
# Carried (ignored folders): .gl (the Vulkan loader debs), .bin (dermis,
# stripped release build), .assets (../shared/assets).
set -uo pipefail
ROOT=$PWD
OUT=$(realpath -m "${OUT:-out}")
R=/tmp/issue28
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
for res in "1080|--width 1920 --height 1080" "2160|--width 3840 --height 2160"; do
  r=${res%%|*}; ra=${res#*|}
  for shot in close mid; do
    for heads in 1 16; do
      for path in fragment compute; do
        # shellcheck disable=SC2086
        bench "$r-$shot-$heads-$path" $ra --shot $shot --heads $heads --method separable --path $path $F
      done
    done
  done
done
# ssg, ss-jittered and poisson on both paths, 1080p close-up; ssg also mid
# (its depth-based skipping drops Gaussians by tile there).
bench "1080-mid-1-ssg-fragment" --width 1920 --height 1080 --shot mid --method ssg --path fragment $F
bench "1080-mid-1-ssg-compute" --width 1920 --height 1080 --shot mid --method ssg --path compute $F
for m in ssg ss-jittered poisson; do
  for path in fragment compute; do
    bench "1080-close-1-$m-$path" --width 1920 --height 1080 --shot close --method $m --path $path $F
  done
done
for path in fragment compute; do
  bench "lps-1080-close-$path" --scene "$LPS" --width 1920 --height 1080 --shot close \
    --method separable --path $path $F
done
# The 2D gather of the exact profile (compute only), both profiles, three
# budgets, close-up and mid.
for shot in close mid; do
  for n in 20 40 80; do
    bench "1080-$shot-1-gather-$n" --width 1920 --height 1080 --shot $shot --method gather --sample-budget $n $F
  done
  bench "1080-$shot-1-gather-burley-40" --width 1920 --height 1080 --shot $shot --method gather \
    --sample-budget 40 --diffusion-profile burley $F
done
# The whole frame with bloom and SMAA (the passes without a floor yet: the
# bloom's combine among them), on the compute path.
bench "1080-close-1-bloom-smaa" --width 1920 --height 1080 --shot close --method separable \
  --path compute --bloom --aa smaa $F
# The two paths' images on the GPU (1080p close-up, the procedural head).
for path in fragment compute; do
  log dermis render --width 1920 --height 1080 --shot close --method separable --path $path --out "$R/img-$path"
  "$N" render --width 1920 --height 1080 --shot close --method separable --path $path \
    --out "$R/img-$path" > "$R/img-$path.txt" 2>&1
done
export DERMIS_FONT=$ROOT/.bin/DejaVuSans.ttf
log dermis compare "$R/img-compute" "$R/img-fragment" --out "$R/cmp"
"$N" compare "$R/img-compute" "$R/img-fragment" --out "$R/cmp" > "$R/compare.txt" 2>&1
if cmp -s "$R/img-compute/diffuse.exr" "$R/img-fragment/diffuse.exr"; then r=same; else r=DIFFERENT; fi
echo "diffuse.exr $r" >> "$R/compare.txt"
cd "$R" && tar czf "$OUT/issue28.tgz" --exclude='*.png' --exclude='*.exr' . && cd "$ROOT"
ls -la "$OUT"
