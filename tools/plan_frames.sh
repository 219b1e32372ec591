#!/usr/bin/env bash
# The stored frames of the planner's cost model (profiles/frames/plan/): every setting the
# planner chooses among (`dermis methods --planned`: each eval setting of the six Gaussians, on
# each path of a method that has two), one character (the Lee Perry-Smith head, --view study,
# 1280x720) at six camera distances, rendered on lavapipe with the fetch-counting build by
# `dermis budget`
# (counts do not depend on the device's speed). `src/plan/cost.rs` reads each pass's counts per
# skin pixel, per region pixel and per rectangle from them, interpolated in pixels per mm.
#
#   tools/plan_frames.sh [BIN]        BIN defaults to target/release/dermis
#
# Writes profiles/frames/plan/<method>__<setting>__d<D>.json and index.json (what each file
# is: method, setting, options, distance, size, field of view). Existing frames are kept
# (delete to redo); index.json is rewritten from the files present.
set -uo pipefail
BIN=${1:-target/release/dermis}
ASSET=${ASSET:-../shared/assets/lee-perry-smith/LeePerrySmith.glb}
D=profiles/frames/plan
DISTANCES=(1.5 3 6 12 24 48)
W=1280
H=720
mkdir -p "$D"
# One line per planned setting (`dermis methods --planned --json`: the planner's own list, so a
# new method, setting or path is picked up, and a method the planner leaves out is left out):
# method<TAB>slug<TAB>label<TAB>flags...
"$BIN" methods --json > "$D/.methods.json" || exit 1
"$BIN" methods --planned --json | python3 -c '
import json, re, sys
methods = {m["name"]: m for m in json.load(open(sys.argv[1]))}
for p in json.load(sys.stdin):
    flags = {o["key"]: (o["flag"], o["kind"]) for o in methods[p["method"]]["options"]}
    args = []
    for k, v in p["options"]:
        flag, kind = flags[k]
        if kind == "switch":
            if v == "false":
                args.append("--" + flag)
        else:
            args += ["--" + flag, v]
    slug = re.sub(r"[^a-z0-9]+", "-", p["setting"].lower()).strip("-")
    print("\t".join([p["method"], slug, p["setting"]] + args))
' "$D/.methods.json" > "$D/.settings.tsv" || exit 1
while IFS=$'\t' read -r method slug label flags; do
  read -r -a extra <<< "$flags"
  for d in "${DISTANCES[@]}"; do
    target="$D/${method}__${slug}__d$d.json"
    [ -e "$target" ] && continue
    tmp=$(mktemp -d)
    if "$BIN" budget --view study --device llvmpipe --profile nvidia-h100 --warmup 0 --frames 1 \
        --scene "$ASSET" --width $W --height $H --distance "$d" --method "$method" "${extra[@]}" \
        --out "$tmp" > "$tmp/log.txt" 2>&1; then
      cp "$tmp"/frames/*.json "$target"
      echo "ok: $target"
    else
      echo "FAILED: $target: $(tail -1 "$tmp/log.txt")" >&2
    fi
    rm -rf "$tmp"
  done
done < "$D/.settings.tsv"
# The index: what every frame is (cost.rs reads it).
python3 - "$D" "$W" "$H" <<'PY'
import json, os, sys
d, w, h = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rows = []
for line in open(os.path.join(d, ".settings.tsv")):
    method, slug, label = line.rstrip("\n").split("\t")[:3]
    for f in sorted(os.listdir(d)):
        pre = f"{method}__{slug}__d"
        if f.startswith(pre) and f.endswith(".json"):
            rows.append({"method": method, "setting": label, "file": f,
                         "distance_heads": float(f[len(pre):-5]), "width": w, "height": h,
                         "fovy_deg": 20.0})
json.dump({"command": "tools/plan_frames.sh", "frames": rows}, open(os.path.join(d, "index.json"), "w"), indent=1)
print(f"index.json: {len(rows)} frames")
PY
rm -f "$D/.settings.tsv" "$D/.methods.json"
