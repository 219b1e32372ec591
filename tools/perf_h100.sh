#!/usr/bin/env bash
# Every device-machine measurement of docs/perf/ and docs/accuracy.md, as one
# command (one device call). Run it on the device machine from the repository
# root with these carried (see /work/.library/device/README.md):
#   .gl      Vulkan loader debs (apt-get download libvulkan1 ... as the README says)
#   .bin     a stripped release build:  strip -o .bin/dermis target/release/dermis
#   .assets  a copy of ../shared/assets: cp -r ../shared/assets .assets
# Everything lands in $OUT/perf.tgz (the device tool returns at most 8 files).
set -euo pipefail
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
B=.bin/dermis
A=.assets/lee-perry-smith/LeePerrySmith.glb
OUT=${OUT:-out}
P=$OUT/perf
mkdir -p "$P"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$P/gpu.txt" || true
if ! "$B" devices 2>&1 | grep -qi nvidia; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
"$B" devices | tee -a "$P/gpu.txt"
run() { echo "+ dermis $*" >> "$P/commands.txt"; "$B" "$@" >> "$P/log.txt" 2>&1 || echo "FAILED: $*" >> "$P/commands.txt"; }

# Issue 2: separable SSS, 1080p, close-up and mid shot, 17 samples (and 9, 33).
run bench --scene "$A" --width 1920 --height 1080 --shot close --samples 17 --report "$P/sep_1080p_close_s17.json"
run bench --scene "$A" --width 1920 --height 1080 --shot mid --samples 17 --report "$P/sep_1080p_mid_s17.json"
run bench --scene "$A" --width 1920 --height 1080 --shot close --samples 9 --report "$P/sep_1080p_close_s9.json"
run bench --scene "$A" --width 1920 --height 1080 --shot close --samples 33 --report "$P/sep_1080p_close_s33.json"
run render --scene "$A" --width 1920 --height 1080 --shot close --frames 20 --out "$P/close_render"

# Issue 3: the thesis' three distances (zoom 28, near 50, far 132 units for a
# 27-unit head = 1.037, 1.852, 4.889 head heights) x 1/3/5 heads x methods, 720p and 1080p.
for res in "1280 720" "1920 1080"; do
  set -- $res
  for d in zoom:1.037 near:1.852 far:4.889; do
    for h in 1 3 5; do
      tag="${1}x${2}_${d%%:*}_${h}h"
      run bench --scene "$A" --width "$1" --height "$2" --distance "${d##*:}" --heads "$h" --method ssg --report "$P/ssg_lod_$tag.json"
      run bench --scene "$A" --width "$1" --height "$2" --distance "${d##*:}" --heads "$h" --method ssg --no-lod --report "$P/ssg_nolod_$tag.json"
      run bench --scene "$A" --width "$1" --height "$2" --distance "${d##*:}" --heads "$h" --method ss-jittered --report "$P/jittered_$tag.json"
      run bench --scene "$A" --width "$1" --height "$2" --distance "${d##*:}" --heads "$h" --method poisson --report "$P/poisson_$tag.json"
      run bench --scene "$A" --width "$1" --height "$2" --distance "${d##*:}" --heads "$h" --method separable --report "$P/separable_$tag.json"
    done
  done
done
run bench --scene "$A" --width 1920 --height 1080 --distance 1.037 --method ssg --mask branch --report "$P/ssg_branch_1080p_zoom.json"

# Issue 4: the cost/error chart on the thesis' scene set at 720p.
run eval --scene "$A" --scenes thesis --width 1280 --height 720 --warmup 5 --frames 30 --out "$P/eval"

tar czf "$OUT/perf.tgz" -C "$OUT" perf
