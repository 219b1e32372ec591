#!/usr/bin/env bash
# Texture-space diffusion on crowds (issue 12), every run a `dermis bench`:
#
#   1. Table 3.1: tsd and tsd-opt (2048 maps) at 1920x1200, the crowd layout,
#      1, 2, 4, 8, 16 heads x camera distances 2.5, 5, 10, 20, 50, 100 head
#      heights (the thesis' units: a head about one unit tall).
#   2. The optimisations apart, at four cells: tsd-opt with one switch on at a
#      time, and the culled map by alpha test against the stencil mask.
#   3. Table 4.4's shape: none, ss-jittered, ssg, separable, tsd and tsd-opt
#      (1024 maps, the table's size) at 1, 5 and 16 characters, 1280x720.
#
#   bash tools/tsd_table31.sh DERMIS OUTDIR [PART...]   PART: t31 apart t44 (default: all)
#
# DERMIS is the dermis binary, OUTDIR where the reports go (t31/, apart/, t44/,
# commands.txt, log.txt, and summary.md when python3 is there). The head is
# $SCENE (default .assets/lee-perry-smith/LeePerrySmith.glb, else
# ../shared/assets/...). A run whose report exists is skipped, and no run starts
# after DEADLINE seconds (default 540): call again on the warm machine to go
# on. Frames per run: WARMUP (10) and FRAMES (40).
#
# On the device machine, carry what tools/perf_h100.sh carries (.gl loader debs,
# .bin/dermis, .assets); the loader is unpacked here when .gl/ exists.
#
# DRY=1: lavapipe at sizes divided by 8 with maps divided by 8 (240x150 with
# 256 maps keeps every eq. 3.1 scale s, since d_ref follows H / T_max; the
# far-head threshold follows H), 3 + 1 frames: the commands checked, and the
# texel counts of every pass (samples passed) at 1/64 of the full size.
set -uo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 DERMIS OUTDIR [t31|apart|t44 ...]" >&2
  exit 2
fi
B=$1
OUT=$2
shift 2
PARTS=("$@")
[ ${#PARTS[@]} -eq 0 ] && PARTS=(t31 apart t44)
START=$SECONDS
DEADLINE=${DEADLINE:-540}
DRY=${DRY:-0}
SCENE=${SCENE:-.assets/lee-perry-smith/LeePerrySmith.glb}
[ -f "$SCENE" ] || SCENE=../shared/assets/lee-perry-smith/LeePerrySmith.glb
mkdir -p "$OUT"/t31 "$OUT"/apart "$OUT"/t44

if [ "$DRY" = 1 ]; then
  DEV=(--device llvmpipe)
  # Three warm-up frames: the report's counts come from the last frame, and
  # far characters keep their maps only once they have one.
  FR=(--warmup 3 --frames 1)
  W31=240 H31=150 T31=256
  W44=160 H44=90 T44=128
else
  DEV=()
  FR=(--warmup "${WARMUP:-10}" --frames "${FRAMES:-40}")
  W31=1920 H31=1200 T31=2048
  W44=1280 H44=720 T44=1024
  if ls .gl/*.deb > /dev/null 2>&1; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
  fi
  if ! "$B" devices 2>&1 | grep -qi nvidia && [ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  fi
fi
# The far-head threshold of the z pre-passes (64 px at 1200 lines) follows the frame height.
far() { echo $((64 * $1 / 1200)); }

# run OUTPUT dermis-args...: skipped when OUTPUT exists or the deadline has passed.
run() {
  local output=$1
  shift
  if [ -e "$output" ]; then return; fi
  if (( SECONDS - START > DEADLINE )); then
    echo "SKIPPED (deadline): dermis $*" >> "$OUT/commands.txt"
    return
  fi
  echo "+ dermis $*" >> "$OUT/commands.txt"
  local t0=$SECONDS
  local left=$((DEADLINE + 50 - (SECONDS - START)))
  # The recorded runs were made at the view now called study (the default became
  # the portrait in issue 15): the commands that take a view keep it.
  local sub=$1
  shift
  local view=()
  case $sub in render | bench | eval | budget | reference) view=(--view study) ;; esac
  if timeout $((left < 300 ? left : 300)) "$B" "$sub" "${view[@]}" "$@" >> "$OUT/log.txt" 2>&1; then
    echo "    ok in $((SECONDS - t0)) s" >> "$OUT/commands.txt"
  else
    echo "    FAILED (rc $?) after $((SECONDS - t0)) s" >> "$OUT/commands.txt"
  fi
}

HEADS31=(1 2 4 8 16)
DIST31=(2.5 5 10 20 50 100)

t31() {
  local f
  f=$(far "$H31")
  for h in "${HEADS31[@]}"; do
    for d in "${DIST31[@]}"; do
      local common=(bench "${DEV[@]}" "${FR[@]}" --scene "$SCENE" --width "$W31" --height "$H31"
        --heads "$h" --layout crowd --distance "$d" --irradiance-size "$T31")
      run "$OUT/t31/tsd_${h}h_d${d}.json" "${common[@]}" --method tsd \
        --report "$OUT/t31/tsd_${h}h_d${d}.json"
      run "$OUT/t31/opt_${h}h_d${d}.json" "${common[@]}" --method tsd-opt --far-px "$f" \
        --report "$OUT/t31/opt_${h}h_d${d}.json"
    done
  done
}

# Each optimisation alone (the others off), and the culled map by alpha test.
apart() {
  local f
  f=$(far "$H31")
  local none=(--cull off --no-depth-sized --no-clip --no-z-prepass)
  for cell in "1 2.5" "4 5" "16 10" "16 50"; do
    read -r h d <<< "$cell"
    local common=(bench "${DEV[@]}" "${FR[@]}" --scene "$SCENE" --width "$W31" --height "$H31"
      --heads "$h" --layout crowd --distance "$d" --irradiance-size "$T31" --method tsd-opt)
    local tag="${h}h_d${d}"
    run "$OUT/apart/stencil_$tag.json" "${common[@]}" --cull stencil --no-depth-sized --no-clip --no-z-prepass \
      --report "$OUT/apart/stencil_$tag.json"
    run "$OUT/apart/alpha_$tag.json" "${common[@]}" --cull alpha --no-depth-sized --no-clip --no-z-prepass \
      --report "$OUT/apart/alpha_$tag.json"
    run "$OUT/apart/depth_$tag.json" "${common[@]}" --cull off --no-clip --no-z-prepass \
      --report "$OUT/apart/depth_$tag.json"
    run "$OUT/apart/clip_$tag.json" "${common[@]}" --cull off --no-depth-sized --no-z-prepass \
      --report "$OUT/apart/clip_$tag.json"
    run "$OUT/apart/zpre_$tag.json" "${common[@]}" --cull off --no-depth-sized --no-clip --far-px "$f" \
      --report "$OUT/apart/zpre_$tag.json"
    run "$OUT/apart/all_alpha_$tag.json" "${common[@]}" --cull alpha --far-px "$f" \
      --report "$OUT/apart/all_alpha_$tag.json"
    run "$OUT/apart/none_$tag.json" "${common[@]}" "${none[@]}" \
      --report "$OUT/apart/none_$tag.json"
  done
}

t44() {
  local f
  f=$(far "$H44")
  for h in 1 5 16; do
    for m in none ss-jittered ssg separable tsd tsd-opt; do
      local extra=()
      case $m in
        tsd) extra=(--irradiance-size "$T44") ;;
        tsd-opt) extra=(--irradiance-size "$T44" --far-px "$f") ;;
      esac
      run "$OUT/t44/${m}_${h}h.json" bench "${DEV[@]}" "${FR[@]}" --scene "$SCENE" \
        --width "$W44" --height "$H44" --heads "$h" --layout crowd --distance 4 \
        --method "$m" "${extra[@]}" --report "$OUT/t44/${m}_${h}h.json"
    done
  done
}

for p in "${PARTS[@]}"; do
  case $p in
    t31) t31 ;;
    apart) apart ;;
    t44) t44 ;;
    *) echo "unknown part '$p' (t31, apart, t44)" >&2; exit 2 ;;
  esac
done

# The summary: frame and texture-space milliseconds, and the texels every
# pass shaded (samples passed), per report; the speed-up table of Table 3.1.
if command -v python3 > /dev/null; then
  python3 - "$OUT" << 'EOF' > "$OUT/summary.md"
import glob, json, os, sys
out = sys.argv[1]
def load(p):
    try:
        return json.load(open(p))
    except Exception:
        return None
def frame_ms(r):
    return r["frame"]["gpu_ms"]["median"] if r and r.get("frame") else None
def texels(r, prefix):
    return sum(p.get("samples_passed", 0) for p in r["passes"] if p["name"].startswith(prefix))
print("# tsd on crowds: summary of", out, "\n")
print("## Table 3.1: speed-up of tsd-opt over tsd (frame ms)\n")
heads, dists = [1, 2, 4, 8, 16], ["2.5", "5", "10", "20", "50", "100"]
print("| heads | " + " | ".join(dists) + " |")
print("|---|" + "---|" * len(dists))
for h in heads:
    row = []
    for d in dists:
        a = load(f"{out}/t31/tsd_{h}h_d{d}.json")
        b = load(f"{out}/t31/opt_{h}h_d{d}.json")
        fa, fb = frame_ms(a), frame_ms(b)
        row.append(f"{fa / fb:.2f} ({fa:.2f}/{fb:.2f} ms)" if fa and fb else "-")
    print(f"| {h} | " + " | ".join(row) + " |")
print("\n## Texels shaded per frame (samples passed), tsd -> tsd-opt\n")
print("| heads | " + " | ".join(dists) + " |")
print("|---|" + "---|" * len(dists))
for h in heads:
    row = []
    for d in dists:
        a = load(f"{out}/t31/tsd_{h}h_d{d}.json")
        b = load(f"{out}/t31/opt_{h}h_d{d}.json")
        if a and b:
            row.append(f"{texels(a, 'tsd g') / 1e6:.1f}M -> {texels(b, 'tsd g') / 1e6:.2f}M")
        else:
            row.append("-")
    print(f"| {h} | " + " | ".join(row) + " |")
print("\n## Every report\n")
print("| report | frame ms | tsd passes ms | blur texels | irradiance texels |")
print("|---|---|---|---|---|")
for p in sorted(glob.glob(f"{out}/*/*.json")):
    r = load(p)
    if not r:
        continue
    tsd_ms = sum(q["gpu_ms"]["median"] for q in r["passes"] if q["name"].startswith("tsd"))
    print(f"| {os.path.relpath(p, out)} | {frame_ms(r):.3f} | {tsd_ms:.3f} | "
          f"{texels(r, 'tsd g')} | {texels(r, 'tsd irradiance')} |")
EOF
fi
echo "done in $((SECONDS - START)) s; reports in $OUT"
