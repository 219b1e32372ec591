# Sourced by the scripts in tools/: the method names of the registry, read from
# `dermis methods --json`, so no script keeps its own list of methods.
#
#   . tools/methods.sh
#   dermis_methods BIN [PYTHON_CONDITION]
#
# prints the names in registry order, separated by spaces; the condition, a
# Python expression over the listing's row `m` (fields as `dermis methods
# --json` prints them), keeps only the rows it holds for, e.g.
# 'not m["ground_truth"]'.
dermis_methods() {
  local bin=$1 cond=${2:-True}
  "$bin" methods --json | python3 -c '
import json, sys
cond = sys.argv[1]
print(" ".join(m["name"] for m in json.load(sys.stdin) if eval(cond, {}, {"m": m})))
' "$cond"
}
