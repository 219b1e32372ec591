#!/usr/bin/env bash
# Hashes of every image, pass dump and count that dermis produces for every
# method on two scenes, so a restructuring can be shown to change nothing:
#
#   tools/golden_hashes.sh OUTFILE [PROCEDURAL_SCENE_ARGS...]
#
# Renders each configuration once on lavapipe with validation at 256x144 with
# --dump, and writes one line per file (sha256 of frame.png, diffuse.exr and
# every pass dump) and one line per pass of report.json (fragment invocations,
# samples passed). Times are left out: they are the only thing allowed to move.
# PROCEDURAL_SCENE_ARGS name the procedural scene (default: none, the embedded
# default; after the default head changed: --scene builtin:egg). GRID="--layout grid"
# keeps the 3-head case on the grid layout once the crowd became the default.
set -euo pipefail
out=$1; shift
proc=("$@")
B=${B:-target/release/dermis}
HEAD=${HEAD:-../shared/assets/lee-perry-smith/LeePerrySmith.glb}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# A plan with three cross-fades: between two methods, from none and to none.
cat > "$tmp/fades.json" <<'JSON'
{"version":1,"characters":3,"assignments":[
 {"character":0,"method":"separable","fade":{"method":"ssg","weight":0.5}},
 {"character":1,"method":"ss-jittered","fade":{"method":"none","weight":0.25}},
 {"character":2,"method":"none","fade":{"method":"separable","options":{"samples":"9"},"weight":0.75}}]}
JSON
# The study view (RenderSettings::study() at the mid shot): the default view
# before issue 15 made the default a portrait, so the hashes keep meaning one view.
common=(--device llvmpipe --validate --width 256 --height 144 --view study)
configs=(
  "none|--method none"
  "separable 9|--method separable --samples 9"
  "separable 17|--method separable"
  "separable 17 demo nofollow|--method separable --preset demo --no-follow-surface"
  "ssg 6 lod|--method ssg"
  "ssg 4 lod|--method ssg --fit 4"
  "ssg 6 nolod|--method ssg --no-lod"
  "ssg 6 branch|--method ssg --mask branch"
  "ss-jittered|--method ss-jittered"
  "poisson|--method poisson"
  "separable screen region|--method separable --sss-region screen"
  "separable 3 heads|--method separable --heads 3 ${GRID:-}"
  "reference|--method reference --density 8"
  "tsd 512|--method tsd --irradiance-size 512"
  "tsd-opt 512|--method tsd-opt --irradiance-size 512"
  "tsd-opt 512 alpha noprepass|--method tsd-opt --irradiance-size 512 --cull alpha --no-z-prepass"
  "tsd-opt 3 heads|--method tsd-opt --irradiance-size 512 --heads 3 ${GRID:-}"
  # Issue 27: the post chain, MSAA, the character ids and mixed frames (rules,
  # a plan file with cross-fades, a crowd by distance) hashed as well.
  "fxaa|--method separable --aa fxaa"
  "mlaa|--method separable --aa mlaa"
  "mlaa depth edges|--method separable --aa mlaa --aa-edges depth"
  "smaa high|--method separable --aa smaa"
  "smaa ultra color|--method separable --aa smaa --smaa-preset ultra --aa-edges color"
  "smaa low|--method ss-jittered --aa smaa --smaa-preset low"
  "bloom|--method separable --bloom"
  "msaa 4|--method separable --msaa 4"
  "msaa 4 ssg smaa|--method ssg --msaa 4 --aa smaa"
  "character ids|--method separable --character-ids --heads 3 --layout grid"
  "mix rules|--heads 3 --layout grid --assign 0=ssg:fit=4,1=separable:preset=physical,*=none"
  "mix poisson tsd|--heads 3 --layout grid --assign 0=poisson,1=tsd-opt:irradiance-size=512,*=ss-jittered"
  "mix crowd by distance|--heads 9 --assign d0-5=separable:samples=9,*=ss-jittered --aa mlaa"
  "mix plan fades|--heads 3 --layout grid --plan PLANFILE"
)
: > "$out"
for scene in procedural head; do
  if [ $scene = head ]; then sargs=(--scene "$HEAD" --shot close); else sargs=("${proc[@]}"); fi
  for c in "${configs[@]}"; do
    name=${c%%|*}; args=${c#*|}; args=${args//PLANFILE/$tmp/fades.json}
    d=$tmp/run
    rm -rf "$d"
    # shellcheck disable=SC2086
    "$B" render "${common[@]}" "${sargs[@]}" $args --warmup 0 --frames 1 --dump --out "$d" >/dev/null
    ( cd "$d"; for f in frame.png diffuse.exr characters.png groups.png passes/*.exr; do
        [ -e "$f" ] || continue
        echo "$scene | $name | $(basename "$f" | sed 's/^[0-9]*_//') | $(sha256sum "$f" | cut -c1-16)"
      done ) >> "$out"
    python3 - "$d/report.json" "$scene" "$name" >> "$out" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
for p in r["passes"]:
    print(f'{sys.argv[2]} | {sys.argv[3]} | counts {p["name"]} | inv {p.get("fragment_invocations")} samples {p.get("samples_passed")}')
groups = r.get("groups", [])
if len(groups) > 1:
    for g in groups:
        f = g.get("fade") or {}
        print(f'{sys.argv[2]} | {sys.argv[3]} | group {g["index"]} {g["choice"]} | stencil {g["stencil"]} '
              f'characters {g["characters"]} region {g["region_pixels"]} px {len(g["region_rects"])} rects '
              f'skin {g.get("skin_pixels")} fade {f.get("from")} {f.get("weight")} {f.get("region_pixels")}')
PY
    echo "done: $scene $name" >&2
  done
  # Budget figures: every method priced on two targets. Measured times (the only thing
  # allowed to move) are dropped; every modelled figure, count and resolve is kept;
  # the two shaders renamed in issue 15 are hashed under their old names.
  d=$tmp/budget
  rm -rf "$d"
  "$B" budget "${common[@]}" "${sargs[@]}" \
    --profile xbox360,nvidia-h200 --compare-methods --warmup 0 --frames 1 --out "$d" >/dev/null
  python3 - "$d" "$scene" >> "$out" <<'PY'
import json, sys, pathlib, hashlib
TIME = ("measured", "command", "device", "driver", "provenance")
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in sorted(v.items()) if not any(t in k for t in TIME)}
    if isinstance(v, list):
        return [strip(x) for x in v]
    if isinstance(v, str):
        # Shaders renamed after their method in issue 15: their old names, so the
        # figures are compared and not the spelling of a file name.
        return v.replace("separable_blur.frag", "sss_blur.frag").replace(
            "poisson_mip_down.frag", "mip_down.frag")
    return v
d = pathlib.Path(sys.argv[1])
for f in [d / "budget.json"] + sorted((d / "frames").glob("*.json")):
    j = strip(json.load(open(f)))
    h = hashlib.sha256(json.dumps(j, sort_keys=True).encode()).hexdigest()[:16]
    print(f"{sys.argv[2]} | budget | {f.name} | {h}")
PY
  echo "done: $scene budget" >&2
  # Issue 27: a mixed frame with SMAA and an MSAA frame with MLAA priced too,
  # and a plan (device-free) for a crowd of nine.
  for b in "mix|--heads 3 --layout grid --assign 0=ssg:fit=4,1=poisson,*=separable --aa smaa --profile xbox360,switch-handheld" \
           "msaa|--method separable --msaa 4 --aa mlaa --profile geforce-gtx-470,steam-deck"; do
    bname=${b%%|*}; bargs=${b#*|}
    d=$tmp/budget-$bname
    rm -rf "$d"
    # shellcheck disable=SC2086
    "$B" budget "${common[@]}" "${sargs[@]}" $bargs --warmup 0 --frames 1 --out "$d" >/dev/null
    python3 - "$d" "$scene" "$bname" >> "$out" <<'PY'
import json, sys, pathlib, hashlib
TIME = ("measured", "command", "device", "driver", "provenance")
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in sorted(v.items()) if not any(t in k for t in TIME)}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
d = pathlib.Path(sys.argv[1])
for f in [d / "budget.json"] + sorted((d / "frames").glob("*.json")):
    j = strip(json.load(open(f)))
    h = hashlib.sha256(json.dumps(j, sort_keys=True).encode()).hexdigest()[:16]
    print(f"{sys.argv[2]} | budget {sys.argv[3]} | {f.name} | {h}")
PY
    echo "done: $scene budget $bname" >&2
  done
  d=$tmp/plan
  rm -rf "$d"
  "$B" plan "${sargs[@]}" --width 256 --height 144 --view study --heads 9 \
    --profile xbox360 --budget-ms 2 --out "$d" >/dev/null
  python3 - "$d/plan.json" "$scene" >> "$out" <<'PY'
import json, sys, hashlib
j = json.load(open(sys.argv[1]))
for k in ("command", "dermis_version", "run"):
    j.pop(k, None)
# The planner's own time is the one thing allowed to move.
j["notes"] = [n for n in j.get("notes", []) if not n.startswith("time:")]
h = hashlib.sha256(json.dumps(j, sort_keys=True).encode()).hexdigest()[:16]
print(f"{sys.argv[2]} | plan | plan.json | {h}")
for a in j["assignments"]:
    print(f"{sys.argv[2]} | plan | character {a['character']} | {a['method']} {sorted(a.get('options', {}).items())} {a.get('predicted_ms')}")
PY
  echo "done: $scene plan" >&2
done
