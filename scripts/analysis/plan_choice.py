"""The cost of the planner's plan choice, from docs/results/plan-choice/plan-bench.json.

`seads plan-bench` was run with `--plan first-found` and `--plan most-likely`, alternately, twice
each, with one binary. Writes docs/results/plan-choice/summary.md: per depth, the expanded states
(the same search both ways), each choice's mean milliseconds per plan (the two runs in brackets)
and their ratio. Standard library only:
    python3 scripts/analysis/plan_choice.py
"""

import json
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
FOLDER = ROOT / "docs/results/plan-choice"
data = json.loads((FOLDER / "plan-bench.json").read_text())
runs = data["runs"]
lines = [
    f"Written by `scripts/analysis/plan_choice.py` from `plan-bench.json`: `{data['command']}`, "
    f"{data['binary']}; {data['machine']}; runs in the order {data['order']}.",
    "",
    "| depth | expanded states (all boards, both choices) | first found, ms per plan | "
    "most likely, ms per plan | ratio |",
    "|---|---|---|---|---|",
]
for i, row in enumerate(runs[0]["result"]["depths"]):
    ms = {
        choice: [r["result"]["depths"][i]["mean_s"] * 1000 for r in runs if r["plan"] == choice]
        for choice in ("first-found", "most-likely")
    }
    expanded = sorted({sum(r["result"]["depths"][i]["expanded"]) for r in runs})
    mean = {c: sum(v) / len(v) for c, v in ms.items()}
    cells = {c: f"{mean[c]:.2f} ({', '.join(f'{x:.2f}' for x in v)})" for c, v in ms.items()}
    lines.append(
        f"| {row['depth']} | {', '.join(map(str, expanded))} | {cells['first-found']} | "
        f"{cells['most-likely']} | {mean['most-likely'] / mean['first-found']:.2f} |"
    )
(FOLDER / "summary.md").write_text("\n".join(lines) + "\n")
print("\n".join(lines))
