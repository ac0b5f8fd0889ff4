#!/usr/bin/env python3
"""The wary plan choice against the most likely one, task by task (docs/results/plan-wary).

Usage: python3 scripts/analysis/plan_wary.py docs/results/plan-wary

Reads each agent's wary evaluations (`seed-N/evaluation-replan-depths-D-D*`) and the same agent's
most-likely evaluations in
`docs/results/deep-search/agents-a58a2c4/sweep/runs/lightsout-cursor/seads/seed-N/`, and writes
`summary.md` beside them: boards solved per agent and depth by each choice, the tasks only one of
them solved, and the mean search time per task; and, where `shallow/` holds both choices
evaluations of depths 1-5 (`run.sh`), the same for those. A task whose most-likely run saw no skill deviate
twice must be the same under both choices (the wary choice differs only after a second failure of
one skill); the script checks that and fails otherwise.
"""
import json
import pathlib
import statistics
import sys
from collections import Counter

root = pathlib.Path(sys.argv[1])
base = root.parent / "deep-search" / "agents-a58a2c4" / "sweep" / "runs" / "lightsout-cursor" / "seads"


def tasks(path):
    return {(t["depth"], t["seed"]): t for t in map(json.loads, path.read_text().splitlines())}


def record(path):
    return json.loads(path.read_text())["results"][0]


rows = []
totals = Counter()
for wary_dir in sorted(root.glob("seed-*")):
    for f in sorted(wary_dir.glob("evaluation-replan-depths-*-tasks.jsonl")):
        name = f.name
        likely_file = base / wary_dir.name / name
        if not likely_file.exists():
            continue
        wary, likely = tasks(f), tasks(likely_file)
        assert wary.keys() == likely.keys(), f
        for key, t in likely.items():
            twice = Counter(d["skill"] for d in t["deviations"])
            if not any(n >= 2 for n in twice.values()):
                same = {k: v for k, v in t.items() if k != "planning_s"}
                other = {k: v for k, v in wary[key].items() if k != "planning_s"}
                assert same == other, f"{f}: task {key} differs without a repeated failure"
        depth = next(iter(wary))[0]
        only_wary = sum(wary[k]["solved"] and not likely[k]["solved"] for k in wary)
        only_likely = sum(likely[k]["solved"] and not wary[k]["solved"] for k in wary)
        rw = record(f.with_name(name.replace("-tasks.jsonl", ".json")))
        rl = record(likely_file.with_name(name.replace("-tasks.jsonl", ".json")))
        rows.append((wary_dir.name, depth, rl["solved"], rw["solved"], len(wary), only_wary,
                     only_likely, statistics.mean(rl["planning_s"]), statistics.mean(rw["planning_s"])))
        totals["likely"] += rl["solved"]
        totals["wary"] += rw["solved"]
        totals["tasks"] += len(wary)

out = ["Written by `scripts/analysis/plan_wary.py` from `seed-N/` (the wary choice, `run.sh`) and "
       "`../deep-search/agents-a58a2c4/sweep/runs/lightsout-cursor/seads/seed-N/` (the most likely plan), the same agents, boards "
       "and protocol (re-planning, from both ends, 16 GiB, 2^22 expanded states).",
       "",
       "| agent | depth | most likely: solved | wary: solved | only wary solved | only most likely solved "
       "| mean search per task, most likely / wary |",
       "|---|---|---|---|---|---|---|"]
for a, d, sl, sw, n, ow, ol, tl, tw in sorted(rows, key=lambda r: (r[0], r[1])):
    out.append(f"| {a} | {d} | {sl} / {n} | {sw} / {n} | {ow} | {ol} | {tl:.1f} s / {tw:.1f} s |")
out += ["", f"In all: most likely {totals['likely']} of {totals['tasks']} tasks, "
            f"wary {totals['wary']} of {totals['tasks']}."]
# Depths 1-5: both choices evaluated here (`shallow/<choice>/seed-N/`), the standard test boards.
shallow = root / "shallow"
if shallow.exists():
    out += ["", "Depths 1-5 (`shallow/`, the standard 20 test boards per depth, both choices by the same "
            "binary and protocol):", "",
            "| agent | most likely: solved per depth | wary: solved per depth | only wary solved "
            "| only most likely solved | search per task, most likely / wary |",
            "|---|---|---|---|---|---|"]
    t = Counter()
    for likely_dir in sorted((shallow / "most-likely").glob("seed-*")):
        wary_dir = shallow / "most-likely-wary" / likely_dir.name
        fl, fw = likely_dir / "evaluation-replan-tasks.jsonl", wary_dir / "evaluation-replan-tasks.jsonl"
        if not (fl.exists() and fw.exists()):
            continue
        likely, wary = tasks(fl), tasks(fw)
        for key, task in likely.items():
            if not any(n >= 2 for n in Counter(d["skill"] for d in task["deviations"]).values()):
                assert task == wary[key], f"{fw}: task {key} differs without a repeated failure"
        rl = json.loads((likely_dir / "evaluation-replan.json").read_text())["results"]
        rw = json.loads((wary_dir / "evaluation-replan.json").read_text())["results"]
        ow = sum(wary[k]["solved"] and not likely[k]["solved"] for k in wary)
        ol = sum(likely[k]["solved"] and not wary[k]["solved"] for k in wary)
        mean = lambda rs: statistics.mean(x for r in rs for x in r["planning_s"])
        out.append(f"| {likely_dir.name} | {' / '.join(str(r['solved']) for r in rl)} "
                   f"| {' / '.join(str(r['solved']) for r in rw)} | {ow} | {ol} "
                   f"| {mean(rl):.2f} s / {mean(rw):.2f} s |")
        t["likely"] += sum(r["solved"] for r in rl)
        t["wary"] += sum(r["solved"] for r in rw)
        t["tasks"] += len(wary)
    out += ["", f"In all: most likely {t['likely']} of {t['tasks']} tasks, wary {t['wary']} of {t['tasks']}."]
(root / "summary.md").write_text("\n".join(out) + "\n")
print("\n".join(out))
