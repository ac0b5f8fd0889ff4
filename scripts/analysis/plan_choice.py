"""The planner's plan choice: its cost (docs/results/plan-choice/plan-bench.json) and what it
changes for trained agents (docs/results/plan-choice/agents/<choice>/seed-N/).

`docs/results/plan-choice/bench.sh` ran `seads plan-bench` with `--plan first-found` and
`--plan most-likely` by one binary, and `--plan most-likely` by the binary before the change, in
turn, twice each. Writes docs/results/plan-choice/summary.md: per depth, the expanded states (the
same search every way), each run's mean milliseconds per plan (the two runs in brackets), the
most likely plan's cost against the first found's (one binary) and against the previous binary's
most likely plan; then, for each agent evaluated with both choices (the same tasks), the boards
solved per depth and the tasks that one choice solved and the other did not. Standard library
only:
    python3 scripts/analysis/plan_choice.py
"""

import json
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
FOLDER = ROOT / "docs/results/plan-choice"
data = json.loads((FOLDER / "plan-bench.json").read_text())
runs = data["runs"]
COLUMNS = [
    ("new", "first-found", "first found, ms per plan"),
    ("new", "most-likely", "most likely, ms per plan"),
    ("old", "most-likely", "most likely before, ms per plan"),
]
lines = [
    f"Written by `scripts/analysis/plan_choice.py` from `plan-bench.json`: `{data['command']}`; "
    f"{data['binary']}, and before it {data['previous']}; release builds; {data['machine']}; "
    f"runs in the order {data['order']}.",
    "",
    "| depth | expanded states (all boards, every run) | "
    + " | ".join(title for _, _, title in COLUMNS)
    + " | most likely / first found | most likely / before |",
    "|---|---|---|---|---|---|---|",
]
for i, row in enumerate(runs[0]["result"]["depths"]):
    mean, cells = {}, []
    for which, plan, _ in COLUMNS:
        ms = [
            r["result"]["depths"][i]["mean_s"] * 1000
            for r in runs
            if r["which"] == which and r["plan"] == plan
        ]
        mean[which, plan] = sum(ms) / len(ms)
        cells.append(f"{mean[which, plan]:.2f} ({', '.join(f'{x:.2f}' for x in ms)})")
    expanded = sorted({sum(r["result"]["depths"][i]["expanded"]) for r in runs})
    likely = mean["new", "most-likely"]
    lines.append(
        f"| {row['depth']} | {', '.join(map(str, expanded))} | {' | '.join(cells)} | "
        f"{likely / mean['new', 'first-found']:.2f} | {likely / mean['old', 'most-likely']:.2f} |"
    )

GROUPS = [
    ("agents", "the init-check agents: K = 25, 10^5 steps"),
    ("agents-k30", "the more-skills agents: K = 30 for 25 moves, 5*10^5 steps"),
]
for folder_name, what in GROUPS:
    agents = FOLDER / folder_name
    if not (agents / "most-likely").is_dir():
        continue
    seeds = sorted(
        p.name
        for p in (agents / "most-likely").glob("seed-*")
        if (agents / "first-found" / p.name / "evaluation-replan.json").is_file()
    )
    lines += [
        "",
        f"`{folder_name}/`, {what}: `seads evaluate --replan --plan CHOICE --max-expanded 1048576` "
        "on the 20 standard test boards per depth 1-5 of each agent.",
        "",
        "| agent | most likely: solved per depth | first found: solved per depth | tasks only most likely solved | tasks only first found solved |",
        "|---|---|---|---|---|",
    ]
    totals = {"most-likely": 0, "first-found": 0}
    tasks_total = 0
    for seed in seeds:
        solved, tasks = {}, {}
        for choice in ("most-likely", "first-found"):
            folder = agents / choice / seed
            record = json.loads((folder / "evaluation-replan.json").read_text())
            solved[choice] = [r["solved"] for r in record["results"]]
            totals[choice] += sum(solved[choice])
            rows = (folder / "evaluation-replan-tasks.jsonl").read_text().splitlines()
            tasks[choice] = {
                (t["depth"], t["seed"], t["board"]): t["solved"] for t in map(json.loads, rows)
            }
        tasks_total += len(tasks["most-likely"])

        def only(a, b):
            return sum(1 for k, v in tasks[a].items() if v and not tasks[b].get(k, False))

        lines.append(
            f"| {seed} | {' / '.join(map(str, solved['most-likely']))} | "
            f"{' / '.join(map(str, solved['first-found']))} | {only('most-likely', 'first-found')} | "
            f"{only('first-found', 'most-likely')} |"
        )
    lines += [
        "",
        f"In all: most likely {totals['most-likely']} of {tasks_total} tasks, first found "
        f"{totals['first-found']} of {tasks_total}.",
    ]
(FOLDER / "summary.md").write_text("\n".join(lines) + "\n")
print("\n".join(lines))
