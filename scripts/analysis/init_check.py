"""Coverage over training of the forward-model initialisation check (issue 48 item 0).

Compares LightsOutCursor SEADS runs trained with the forward model initialised as the reference's
(PyTorch's default nn.Linear; docs/results/init-check) with the ten committed runs of the
ten-seed study, whose forward model started Xavier-initialised with zero biases
(docs/results/table1-ten). For each epoch of EPOCHS and for the first evaluation at or past
10^5 environment steps: the mean, standard deviation and values of `skill_coverage`, and the
exact two-sided permutation p of the difference of the means (every split of the pooled runs).

Writes docs/results/init-check/curve.json and prints a table. Standard library only:
    python3 scripts/analysis/init_check.py
"""

import itertools
import json
import pathlib
import statistics

ROOT = pathlib.Path(__file__).resolve().parents[2]
NEW = ROOT / "docs/results/init-check/runs/init-check/runs/lightsout-cursor/seads"
OLD = ROOT / "docs/results/table1-ten/runs/table1-lightsout-ten/runs/lightsout-cursor/seads"
EPOCHS = [100, 200, 300, 400]
STEPS = 100_000


def curves(folder: pathlib.Path) -> dict:
    """Seed directory name -> list of metrics lines."""
    out = {}
    for metrics in sorted(folder.glob("seed-*/metrics.jsonl")):
        out[metrics.parent.name] = [json.loads(line) for line in metrics.read_text().splitlines()]
    return out


def at_epoch(lines: list, epoch: int):
    return next((l["skill_coverage"] for l in lines if l["epoch"] == epoch), None)


def at_steps(lines: list, steps: int):
    return next((l["skill_coverage"] for l in lines if l["env_steps"] >= steps), None)


def permutation_p(a: list, b: list) -> float:
    """Exact two-sided p of |mean(a) - mean(b)| over every split of the pooled values."""
    pooled = a + b
    observed = abs(statistics.fmean(a) - statistics.fmean(b))
    total = sum(pooled)
    count = extreme = 0
    for chosen in itertools.combinations(range(len(pooled)), len(a)):
        s = sum(pooled[i] for i in chosen)
        diff = abs(s / len(a) - (total - s) / len(b))
        extreme += diff >= observed - 1e-12
        count += 1
    return extreme / count


def summary(values: list) -> dict:
    return {
        "n": len(values),
        "mean": statistics.fmean(values),
        "std": statistics.stdev(values) if len(values) > 1 else 0.0,
        "values": values,
    }


new, old = curves(NEW), curves(OLD)
rows = []
points = [("epoch", e) for e in EPOCHS] + [("env_steps", STEPS)]
for kind, at in points:
    pick = (lambda l: at_epoch(l, at)) if kind == "epoch" else (lambda l: at_steps(l, at))
    a = [v for v in (pick(l) for l in new.values()) if v is not None]
    b = [v for v in (pick(l) for l in old.values()) if v is not None]
    rows.append(
        {
            kind: at,
            "torch_default_init": summary(a),
            "xavier_init": summary(b),
            "exact_p_two_sided": permutation_p(a, b) if a and b else None,
        }
    )
out = {
    "what": "skill coverage of LightsOutCursor SEADS: forward model initialised as PyTorch's "
    "nn.Linear (init-check) against Xavier with zero biases (table1-ten, SEADS)",
    "runs": {"torch_default_init": sorted(new), "xavier_init": sorted(old)},
    "rows": rows,
}
path = ROOT / "docs/results/init-check/curve.json"
path.write_text(json.dumps(out, indent=1) + "\n")
print(f"{'at':>18}  {'PyTorch default init':>22}  {'Xavier init (committed)':>24}  exact p")
for r in rows:
    at = f"epoch {r['epoch']}" if "epoch" in r else f"{r['env_steps']} steps"
    a, b = r["torch_default_init"], r["xavier_init"]
    p = r["exact_p_two_sided"]
    print(
        f"{at:>18}  {a['mean']:6.2f} ± {a['std']:4.2f} (n={a['n']:2})  "
        f"{b['mean']:6.2f} ± {b['std']:4.2f} (n={b['n']:2})    {p:.3f}"
    )
print(f"wrote {path}")
