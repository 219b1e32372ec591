#!/usr/bin/env python3
"""Merges the rows of a partial accuracy sweep (tools/accuracy_sweep.sh with ONLY=...) into one
of the accuracy model's files (profiles/accuracy/ASSET[-sSIZE].toml): every row of a method the
partial file holds replaces that method's rows, the other methods' rows are kept, and the header
names both runs (command and device), so each row's origin stays readable.

    python3 tools/accuracy_merge.py BASE.toml PARTIAL.toml [OUT.toml]   # OUT defaults to BASE

The frames must agree (same size, field of view and shadow texels): rows measured on another
frame would not be comparable. Written in the form `src/accuracy/data.rs` writes (one inline
table a row, shortest round-trip numbers), which it reads back."""
import sys
import tomllib

KEYS = ["asset", "method", "setting", "px_per_mm", "light_deg", "shadow_mm", "interior", "silhouette"]


def load(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


def value(v):
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(float(v))


def main(argv):
    if len(argv) not in (3, 4):
        sys.exit(__doc__)
    base_path, part_path = argv[1], argv[2]
    out_path = argv[3] if len(argv) == 4 else base_path
    base, part = load(base_path), load(part_path)
    if base["frame"] != part["frame"]:
        sys.exit(f"frames differ: {base['frame']!r} against {part['frame']!r}")
    methods = {r["method"] for r in part["rows"]}
    # A partial sweep's `none` rows are its own baseline, not news: keep the base's.
    methods.discard("none")
    if not methods:
        sys.exit(f"{part_path}: no rows of any method but none")
    texels = {r["shadow_mm"] for r in base["rows"]}
    for r in part["rows"]:
        if not any(abs(r["shadow_mm"] / t - 1) < 1e-9 for t in texels):
            sys.exit(f"{part_path}: a row's shadow texel {r['shadow_mm']} mm is not the base's")
    kept = [r for r in base["rows"] if r["method"] not in methods]
    new = [r for r in part["rows"] if r["method"] in methods]
    rows = kept + new
    names = ", ".join(sorted(methods))
    command = f"{base['command']}; then {names} by: {part['command']}"
    device = f"{base['device']}; {names}: {part['device']}"
    lines = []
    with open(base_path) as f:
        for line in f:
            if not line.startswith("#"):
                break
            lines.append(line.rstrip("\n"))
    lines.append(f"# {names}: merged from {part_path} by tools/accuracy_merge.py")
    lines.append(f"command = {value(command)}")
    lines.append(f"device = {value(device)}")
    lines.append(f"frame = {value(base['frame'])}")
    lines.append("rows = [")
    for r in rows:
        fields = ", ".join(f"{k} = {value(r[k])}" for k in KEYS if k in r)
        lines.append(f"  {{ {fields} }},")
    lines.append("]")
    with open(out_path, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"{out_path}: {len(kept)} rows kept, {len(new)} rows of {names} merged")


if __name__ == "__main__":
    main(sys.argv)
