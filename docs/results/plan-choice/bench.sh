#!/usr/bin/env bash
# The plan choice's cost (issue 44 item 2): `seads plan-bench` with `--plan first-found` and
# `--plan most-likely` by one binary (NEW), and `--plan most-likely` by the binary before the
# change (OLD), in turn, twice each; 20 boards per depth 1-5 and 3 at depth 9. Writes
# plan-bench.json beside this script; `python3 scripts/analysis/plan_choice.py` makes the table.
#   OLD=/root/seads-frozen/a58a2c4/bin/seads NEW=/root/seads-frozen/96fb2ef/bin/seads \
#     MACHINE="Intel Xeon, 2 cores; ..." bash docs/results/plan-choice/bench.sh
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
: "${OLD:?the binary before the change}" "${NEW:?the binary to measure}" "${MACHINE:?where it ran}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
order=()
for round in 1 2; do
  for run in "old most-likely" "new first-found" "new most-likely"; do
    read -r which plan <<< "$run"
    binary=$OLD; [[ $which == new ]] && binary=$NEW
    name=$round-$which-$plan
    "$binary" plan-bench --depths 1,2,3,4,5 --boards 20 --plan "$plan" --json > "$tmp/$name-shallow.json"
    "$binary" plan-bench --depths 9 --boards 3 --plan "$plan" --json > "$tmp/$name-deep.json"
    "$binary" --version > "$tmp/$name.version"
    order+=("$name")
  done
done
python3 - "$tmp" "$here/plan-bench.json" "$MACHINE" "${order[@]}" <<'EOF'
import json, os, pathlib, sys
tmp, out, machine, names = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), sys.argv[3], sys.argv[4:]
runs = []
for name in names:
    _, which, plan = name.split("-", 2)
    shallow = json.loads((tmp / f"{name}-shallow.json").read_text())
    deep = json.loads((tmp / f"{name}-deep.json").read_text())
    shallow["depths"] += deep["depths"]
    binary = (tmp / f"{name}.version").read_text().strip()
    runs.append({"binary": binary, "which": which, "plan": plan, "result": shallow})
data = {
    "command": "seads plan-bench --depths 1,2,3,4,5 --boards 20 --plan CHOICE --json, and --depths 9 --boards 3",
    "binary": next(r["binary"] for r in runs if r["which"] == "new"),
    "previous": next(r["binary"] for r in runs if r["which"] == "old"),
    "machine": machine,
    "order": ", ".join(f"{r['which']} {r['plan']}" for r in runs),
    "runs": runs,
}
part = out.with_suffix(".json.part")
with open(part, "w") as f:
    json.dump(data, f, indent=2)
    f.write("\n")
    f.flush()
    os.fsync(f.fileno())
os.replace(part, out)
EOF
