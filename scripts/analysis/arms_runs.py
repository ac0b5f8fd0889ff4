"""The per-run table of an arm study in docs/RESULTS.md (the Reacher cells, the Jaco cells), from
the data `seads report --copy-runs` committed: for each run, its coverage at the end of training,
at a step count (its last evaluation at or before it), the mean over training (the area under its
held coverage curve over the steps it spans, as the report's "Skill coverage over training"), the
task success of its evaluations (mean over depths 1-5, re-planning / plan once; SEADS rows only)
and the processor it trained on (`walltime.csv`).
Usage: python3 scripts/analysis/arms_runs.py docs/results/arms-reacher [--at 2500000]"""

import argparse
import csv
import json
import pathlib


def curve(run):
    """(steps, coverage) of each metrics line that carries a coverage evaluation."""
    points = []
    for line in (run / "metrics.jsonl").read_text().splitlines():
        row = json.loads(line)
        if "skill_coverage" in row:
            points.append((row["env_steps"], row["skill_coverage"]))
    return points


def held_at(points, steps):
    """The coverage of the last evaluation at or before `steps`."""
    return [c for s, c in points if s <= steps][-1]


def mean_over_training(points):
    """Area under the held curve (each value held until the next evaluation) per step spanned."""
    area = sum(c * (s1 - s0) for (s0, c), (s1, _) in zip(points, points[1:]))
    return area / (points[-1][0] - points[0][0])


def success(run, mode):
    """Mean over depths of the share of tasks solved, in percent, or None without the file."""
    path = run / f"evaluation-{mode}.json"
    if not path.exists():
        return None
    results = json.loads(path.read_text())["results"]
    return 100 * sum(r["solved"] / r["tasks"] for r in results) / len(results)


def processor(name):
    for short in ("Intel Xeon", "AMD EPYC"):
        if all(word in name for word in short.split()):
            return short
    return name


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", type=pathlib.Path)
    parser.add_argument("--at", type=int, default=2_500_000)
    args = parser.parse_args()
    with (args.study / "walltime.csv").open() as f:
        walltime = list(csv.DictReader(f))
    (sweep,) = (args.study / "runs").iterdir()
    print(f"| board | variant | seed | coverage at end | at {args.at:.2e} | mean over training "
          "| re-planning / plan once, depth 1-5 mean | processor |")
    print("|---|---|---|---|---|---|---|---|")
    for row in walltime:
        env, variant = row["env"], row["variant"]
        seed = row["run"].rstrip("/").rsplit("/", 1)[-1]
        run = sweep / "runs" / env / variant / seed
        points = curve(run)
        replan, once = success(run, "replan"), success(run, "plan-once")
        tasks = "–" if replan is None or once is None else f"{replan:.0f} / {once:.0f} %"
        print(f"| {env} | {variant} | {seed.removeprefix('seed-')} | {points[-1][1]:.2f} "
              f"| {held_at(points, args.at):.2f} | {mean_over_training(points):.2f} | {tasks} "
              f"| {processor(row['processor'])} |")


if __name__ == "__main__":
    main()
