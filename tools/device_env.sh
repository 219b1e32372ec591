# Sourced by the device-call scripts (tools/perf_*.sh) with ROOT (the checkout) and R (the
# results folder) set: unpacks the carried Vulkan loader (.gl), falls back to the NVIDIA ICD
# file where the loader does not find it, records the GPU (R/gpu.txt), and gives the scripts
# N (the carried binary), LPS (the carried head), `log` (R/commands.txt) and `bench NAME ARGS`
# (a report R/NAME.json, its table R/NAME.txt, its exit in R/exits.txt). The scripts of calls
# already made keep their own copy of this: they are the record of what ran.
for f in "$ROOT"/.gl/*.deb; do dpkg -x "$f" /; done
ldconfig
N=$ROOT/.bin/dermis
export DERMIS_FONT=$ROOT/.bin/DejaVuSans.ttf
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
