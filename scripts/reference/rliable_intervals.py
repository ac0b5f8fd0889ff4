"""Reference values for the report's interval estimates: rliable 1.2 (Agarwal et al., 2021) on
committed studies' runs. For every cell (environment x variant) of the studies below, the final
skill coverage of each run (the `skill_coverage` of the last line of its metrics.jsonl, as
`seads report` takes it) is one run's score on one task; rliable then gives

- the IQM (`metrics.aggregate_iqm`) and the mean (`metrics.aggregate_mean`), each with its
  stratified bootstrap 95 % confidence interval (`library.get_interval_estimates`, percentile
  method, 50,000 resamples, `random_state=np.random.RandomState(0)`);
- the probability of improvement of the variant over the study's reference variant
  (`metrics.probability_of_improvement`) with its interval (`get_interval_estimates` on the
  pair, which bootstraps the two groups independently);
- the run score distribution at a few thresholds (`library.create_performance_profile`'s point
  estimates: the share of runs above tau).

Writes data/reference/rliable/intervals.json, checked by
crates/seads-study/tests/intervals.rs: the IQM, the mean, the probability of improvement and
the profile exactly, the intervals within bootstrap error.

rliable 1.2 pulls arch 7.2, which fails to import with pandas 3; pandas < 3 works. Run it in a
scratch environment from the repository's root (it was run with rliable 1.2.0, arch 7.2.0,
pandas 2.3.3, NumPy 2.x):
    python3 -m venv /tmp/rl && /tmp/rl/bin/pip install "rliable==1.2.0" "arch==7.2.0" "pandas<3"
    /tmp/rl/bin/python scripts/reference/rliable_intervals.py
"""

import json
import pathlib

import numpy as np
from rliable import library, metrics

# (study folder under docs/results, its sweep, the reference variant)
STUDIES = [
    ("table1-ten", "table1-lightsout-ten", "seads"),
    ("table1", "table1", "seads"),
    ("vic-a634bb8", "vic", "seads"),
]
TAUS = [0.0, 5.0, 10.0, 12.0, 20.0, 23.0, 24.0, 24.5, 24.9]
REPS = 50_000


def final_coverage(run: pathlib.Path) -> float:
    last = (run / "metrics.jsonl").read_text().strip().splitlines()[-1]
    return float(json.loads(last)["skill_coverage"])


def seed_of(run: pathlib.Path) -> int:
    return int(run.name.removeprefix("seed-"))


def interval(scores, func):
    point, ci = library.get_interval_estimates(
        {"x": scores}, func, reps=REPS, random_state=np.random.RandomState(0)
    )
    return float(np.asarray(point["x"]).ravel()[0]), [float(v) for v in np.asarray(ci["x"]).ravel()]


def main():
    root = pathlib.Path(__file__).resolve().parents[2]
    cells = []
    for study, sweep, reference in STUDIES:
        runs = root / "docs" / "results" / study / "runs" / sweep / "runs"
        for env in sorted(p for p in runs.iterdir() if p.is_dir()):
            scores = {}
            for variant in sorted(p for p in env.iterdir() if p.is_dir()):
                seeds = sorted((p for p in variant.iterdir() if (p / "metrics.jsonl").exists()), key=seed_of)
                scores[variant.name] = [final_coverage(s) for s in seeds]
            for variant, values in scores.items():
                x = np.array(values).reshape(-1, 1)
                iqm, iqm_ci = interval(x, lambda s: np.array([metrics.aggregate_iqm(s)]))
                mean, mean_ci = interval(x, lambda s: np.array([metrics.aggregate_mean(s)]))
                cell = {
                    "study": study,
                    "env": env.name,
                    "variant": variant,
                    "values": values,
                    "iqm": iqm,
                    "iqm_ci": iqm_ci,
                    "mean": mean,
                    "mean_ci": mean_ci,
                }
                if variant != reference and reference in scores:
                    y = np.array(scores[reference]).reshape(-1, 1)
                    point, ci = library.get_interval_estimates(
                        {"x": [x, y]},
                        lambda a, b: np.array([metrics.probability_of_improvement(a, b)]),
                        reps=REPS,
                        random_state=np.random.RandomState(0),
                    )
                    cell["reference"] = reference
                    cell["reference_values"] = scores[reference]
                    cell["improvement"] = float(np.asarray(point["x"]).ravel()[0])
                    cell["improvement_ci"] = [float(v) for v in np.asarray(ci["x"]).ravel()]
                profile, _ = library.create_performance_profile({"x": x}, np.array(TAUS), reps=2)
                cell["profile"] = {str(t): float(v) for t, v in zip(TAUS, profile["x"])}
                cells.append(cell)
    out = root / "data" / "reference" / "rliable" / "intervals.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"reps": REPS, "taus": TAUS, "cells": cells}, indent=1) + "\n")
    print(f"wrote {len(cells)} cells to {out}")


if __name__ == "__main__":
    main()
