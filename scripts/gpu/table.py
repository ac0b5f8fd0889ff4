"""The device check's table (scripts/gpu/check.sh): reads what the check wrote into its output
folder and prints the planner's and the training's figures, GPU beside CPU. Standard library only,
so it runs with whichever Python the GPU test machine has."""

import csv
import json
import pathlib
import sys


def load_json(path):
    try:
        text = path.read_text().strip()
        return json.loads(text) if text else None
    except (OSError, ValueError):
        return None


def load_lines(path):
    try:
        return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    except (OSError, ValueError):
        return []


def plan_rows(report):
    rows = {}
    for depth in (report or {}).get("depths", []):
        if depth.get("timed_out"):
            rows[depth["depth"]] = ("> limit", "")
        else:
            rows[depth["depth"]] = (f"{depth['mean_s']:.3f}", ",".join(map(str, depth["expanded"])))
    return rows


def committed_coverage(root, steps):
    """Mean ± std of the ten-seed study's SEADS runs (CPU) at `steps`."""
    path = root / "docs/results/table1-ten/coverage-over-training.csv"
    try:
        with path.open() as f:
            for row in csv.DictReader(f):
                if (row["env"], row["variant"], row["measure"], int(row["steps"])) == (
                    "lightsout-cursor", "seads", "coverage_at", steps):
                    return f"{float(row['mean']):.2f} ± {float(row['std']):.2f} ({row['runs']} CPU runs)"
    except (OSError, KeyError, ValueError):
        pass
    return "n/a"


def main():
    out = pathlib.Path(sys.argv[1])
    root = pathlib.Path(__file__).resolve().parents[2]
    gpu = load_json(out / "plan-cuda.json")
    cpu = load_json(out / "plan-cpu.json")
    name = (gpu or {}).get("gpu") or "GPU (no report)"
    print(f"## plan-bench --hidden 256,256, 2 boards per depth, 60 s limit per search")
    print(f"GPU: {name}; CPU: {(cpu or {}).get('threads', '?')} threads of this machine")
    print("| depth | GPU s/plan | GPU expanded | CPU s/plan | CPU expanded | same counts |")
    print("|---|---|---|---|---|---|")
    g, c = plan_rows(gpu), plan_rows(cpu)
    for depth in sorted(set(g) | set(c)):
        gs, ge = g.get(depth, ("-", ""))
        cs, ce = c.get(depth, ("-", ""))
        same = "yes" if ge and ge == ce else ("-" if not (ge and ce) else "NO")
        print(f"| {depth} | {gs} | {ge} | {cs} | {ce} | {same} |")
    one = load_json(out / "plan-cpu-1.json")
    for depth in (one or {}).get("depths", []):
        print(f"CPU, one thread: depth {depth['depth']} {depth['mean_s']:.3f} s/plan "
              f"(expanded {','.join(map(str, depth['expanded']))})")
    print()
    print("## one LightsOutCursor run (preset, one libtorch thread), seed 1")
    print("| device | env steps | wall s | steps/s | skill coverage at the end |")
    print("|---|---|---|---|---|")
    steps = None
    for run, label in (("train-cuda", name), ("train-cpu", "one CPU core")):
        lines = load_lines(out / f"{run}-metrics.jsonl")
        if not lines:
            print(f"| {label} | (no metrics) | | | |")
            continue
        last = lines[-1]
        steps = last["env_steps"]
        print(f"| {label} | {last['env_steps']} | {last['wall_s']:.1f} | "
              f"{last['env_steps'] / max(last['wall_s'], 1e-9):.0f} | {last['skill_coverage']:.2f} |")
    if steps:
        near = round(steps / 50000) * 50000
        print(f"| committed ten-seed study (CPU) at {near} steps | | | | {committed_coverage(root, near)} |")
    print()
    for path in sorted(out.glob("evaluate-*.json")):
        report = load_json(path)
        print(f"{path.stem}: {json.dumps(report)[:200] if report else 'failed (see its .log)'}")
    for path in sorted(out.glob("refused-*.txt")):
        print(f"{path.stem}: {' '.join(path.read_text().split())}")


if __name__ == "__main__":
    main()
