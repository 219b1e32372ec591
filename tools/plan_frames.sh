#!/usr/bin/env bash
# The stored frames of the planner's cost model (profiles/frames/plan/): every eval setting of
# every registered real-time method (read from `dermis methods --json`, so a new method or
# setting is picked up), one character (the Lee Perry-Smith head, --view study, 1280x720) at
# six camera distances, rendered on lavapipe with the fetch-counting build by `dermis budget`
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
# One line per eval setting: method<TAB>slug<TAB>label<TAB>flags...
"$BIN" methods --json | python3 -c '
import json, re, sys
for m in json.load(sys.stdin):
    if m["ground_truth"] or m["name"] == "none":
        continue
    # Not in the accuracy model yet, so not the planner's (src/eval/sweep.rs, UNMEASURED).
    if m["name"] == "gather":
        continue
    flags = {o["key"]: (o["flag"], o["kind"]) for o in m["options"]}
    for e in m["eval"]:
        args = []
        for k, v in e["options"]:
            flag, kind = flags[k]
            if kind == "switch":
                if v == "false":
                    args.append("--" + flag)
            else:
                args += ["--" + flag, v]
        slug = re.sub(r"[^a-z0-9]+", "-", e["label"].lower()).strip("-")
        print("\t".join([m["name"], slug, e["label"]] + args))
' > "$D/.settings.tsv" || exit 1
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
rm -f "$D/.settings.tsv"
