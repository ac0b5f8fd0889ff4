"""The device check's table (scripts/gpu/check.sh): reads what the check wrote into its output
folder and prints the planner's and the training's figures, GPU beside CPU. Standard library only,
so it runs with whichever Python the GPU test machine has."""

import csv
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "determinism"))
from compare_runs import first_difference, without_clock  # noqa: E402


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


def population(out, root):
    """The population of 16 on the GPU against the one-core run: summed steps/s and the ratio."""
    wall = load_json(out / "population-wall.json")
    members = [load_lines(out / f"population-seed-{seed}-metrics.jsonl") for seed in range(1, 17)]
    members = [m for m in members if m]
    cpu = load_lines(out / "train-cpu-metrics.jsonl")
    print("## a population of 16 LightsOutCursor runs (seeds 1-16, preset) on the GPU")
    if not wall or not members:
        print("(no population figures: see population.log)")
        return
    steps = sum(m[-1]["env_steps"] for m in members)
    per_s = steps / max(wall["wall_s"], 1e-9)
    line = f"{len(members)} members, {steps} steps in {wall['wall_s']:.1f} s: {per_s:.0f} steps/s summed"
    if cpu:
        one = cpu[-1]["env_steps"] / max(cpu[-1]["wall_s"], 1e-9)
        line += f"; one run on one CPU core: {one:.0f} steps/s; ratio {per_s / one:.1f} (target 25)"
    print(line)
    coverage = sorted(m[-1]["skill_coverage"] for m in members)
    near = round(members[0][-1]["env_steps"] / 50000) * 50000
    print(f"members' coverage at the end: {', '.join(f'{c:.2f}' for c in coverage)}; "
          f"committed CPU runs at {near} steps: {committed_coverage(root, near) if near else 'n/a'}")


def golden(out, root):
    """This processor's golden run against the EPYC's (data/golden/: libtorch 2.13, which the same
    binary as here, libtorch 2.11, repeats there: data/golden/libtorch-2.11/)."""
    ours = load_lines(out / "golden-metrics.jsonl")
    theirs = load_lines(root / "data/golden/metrics.jsonl")
    print("## the golden configuration (portable numerics) on this CPU, gpu/seads-cpu (libtorch 2.11)")
    if not ours or not theirs:
        print("(no golden figures: see golden.log)")
        return
    cpu = (load_lines(out / "golden-provenance.jsonl") or [{}])[0].get("cpu_model", "?")
    ours_fp = load_json(out / "golden-fingerprint.json")
    theirs_fp = load_json(root / "data/golden/fingerprint.json")
    if ours_fp and theirs_fp:
        parted = sorted(k for k in set(ours_fp) | set(theirs_fp) if ours_fp.get(k) != theirs_fp.get(k))
        print(f"primitives whose fingerprint differs from the golden's: {', '.join(parted) or 'none'}")
        if "tch.sqrt" in parted:
            print("(tch.sqrt is libtorch's root, from the processor's rsqrtps estimate; portable runs "
                  "take seads_nn.sqrt instead: docs/RESULTS.md, 'Determinism across processors')")
    ref = (load_lines(root / "data/golden/provenance.jsonl") or [{}])[0].get("cpu_model", "?")
    ours, theirs = without_clock(ours, 300), without_clock(theirs, 300)
    parted = first_difference(ours, theirs)
    if parted is None:
        print(f"{cpu} repeats {ref}: {len(ours)} metrics lines to epoch 300 equal, field for field")
    elif parted[1] is None:
        print(f"{cpu}: {parted[2]} lines to epoch 300, {ref}: {parted[3]}")
    else:
        line, field, a, b = parted
        print(f"{cpu} parts from {ref} at line {line} (epoch {ours[line - 1]['epoch']}): "
              f"{field} {a} against {b}")


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
    population(out, root)
    print()
    golden(out, root)
    print()
    for path in sorted(out.glob("evaluate-*.json")):
        report = load_json(path)
        print(f"{path.stem}: {json.dumps(report)[:200] if report else 'failed (see its .log)'}")
    for path in sorted(out.glob("refused-*.txt")):
        print(f"{path.stem}: {' '.join(path.read_text().split())}")


if __name__ == "__main__":
    main()
