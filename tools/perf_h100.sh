#!/usr/bin/env bash
# The device-machine benchmark of docs/perf/, as one command. Run it on the
# device machine from the repository root with .gl (Vulkan loader debs), .bin
# (a stripped release build) and .assets (a copy of ../shared/assets) carried:
#   strip -o .bin/dermis target/release/dermis; cp -r ../shared/assets .assets
# Outputs go to $OUT (the device tool brings them back).
set -euo pipefail
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
B=.bin/dermis
A=.assets/lee-perry-smith/LeePerrySmith.glb
OUT=${OUT:-out/perf}
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader || true
if ! "$B" devices 2>&1 | grep -qi nvidia; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
"$B" devices
set -x
"$B" bench --scene "$A" --width 1920 --height 1080 --shot close --samples 17 --report "$OUT/lps_1080p_close_s17.json"
"$B" bench --scene "$A" --width 1920 --height 1080 --shot mid --samples 17 --report "$OUT/lps_1080p_mid_s17.json"
"$B" bench --scene "$A" --width 1920 --height 1080 --shot close --samples 9 --report "$OUT/lps_1080p_close_s9.json"
"$B" bench --scene "$A" --width 1920 --height 1080 --shot close --samples 33 --report "$OUT/lps_1080p_close_s33.json"
"$B" bench --width 1280 --height 720 --report "$OUT/default_720p_s17.json"
"$B" render --scene "$A" --width 1920 --height 1080 --shot close --frames 20 --out "$OUT/close"
