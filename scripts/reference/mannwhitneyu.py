"""Reference values for the report's Mann–Whitney U test: SciPy's
`scipy.stats.mannwhitneyu(x, y, alternative="less")` with its default `method="auto"` (exact
when both samples hold at most 8 values and there are no ties; otherwise the normal
approximation with tie correction and continuity correction).

Each case also holds the exact permutation p-value of the same one-sided test with ties kept
(`permutation_test` over every split of the pooled values, `p_exact`), which the report gives
beside SciPy's p for small samples, and two effect sizes the report gives beside them: Cliff's
delta by counting every (x, y) pair (`delta`: the share of pairs with y > x minus the share with
y < x) and Cohen's d from NumPy's sample standard deviations (`d`: mean(y) - mean(x) over the
pooled standard deviation; null where no group has any spread).

The cases are the shapes a Table 1 comparison takes: five or ten final skill coverages per
variant, often tied at the maximum (25.0 or 12.0), plus samples beyond 8 values and small
samples without ties. Writes data/reference/mannwhitneyu.json, checked by the unit tests of
crates/seads-study/src/report/stats.rs.

Run in any Python with SciPy (it was run with SciPy 1.17.1, NumPy 2.x):
    python3 -m venv /tmp/scipyenv && /tmp/scipyenv/bin/pip install scipy
    /tmp/scipyenv/bin/python scripts/reference/mannwhitneyu.py
"""

import json
import pathlib

import numpy as np
import scipy
from scipy.stats import mannwhitneyu, permutation_test

rng = np.random.default_rng(20261124)
cases = [
    # No ties, exact.
    ([1.0, 2.0, 3.0, 4.0, 5.0], [6.0, 7.0, 8.0, 9.0, 10.0]),
    ([23.1, 24.6, 22.9, 24.0, 23.5], [24.2, 24.95, 24.8, 23.9, 24.7]),
    ([24.85, 24.9, 24.95, 24.8, 24.7], [24.75, 24.65, 24.99, 24.6, 24.55]),
    ([3.0, 1.0, 2.0], [4.0, 5.0, 0.5, 6.0]),
    # Ties at the maximum, as coverage has them: normal approximation with tie correction.
    ([25.0, 25.0, 24.95, 24.9, 25.0], [25.0, 25.0, 25.0, 25.0, 24.95]),
    ([24.3, 24.75, 25.0, 24.9, 24.6], [25.0, 25.0, 25.0, 24.95, 25.0]),
    ([12.0, 12.0, 12.0, 12.0, 12.0], [12.0, 12.0, 12.0, 12.0, 11.95]),
    ([11.0, 12.0, 10.5, 12.0, 11.5], [12.0, 12.0, 12.0, 12.0, 12.0]),
    # Every value equal (a variant as perfect as the reference): no evidence, p = 1.
    ([25.0] * 5, [25.0] * 5),
    # More than 8 values each: normal approximation even without ties.
    (list(rng.normal(23.0, 1.0, 10)), list(rng.normal(24.0, 0.5, 10))),
    (list(rng.normal(24.0, 1.0, 9)), list(rng.normal(24.0, 1.0, 12))),
    # One sample of 8 or fewer and no ties: exact.
    (list(rng.normal(22.0, 1.0, 6)), list(rng.normal(24.0, 1.0, 12))),
    # A baseline's success (3 runs) against SEADS's 100 % (5 runs, all tied): the normal
    # approximation gives 0.0084, below the exact minimum 1/56.
    ([6.0, 2.0, 16.0], [100.0] * 5),
]


def u_less(x, y, axis=-1):
    return mannwhitneyu(x, y, alternative="less", axis=axis).statistic


def exact_p(x, y):
    """The exact permutation p of U (every split of the pooled values, ties kept)."""
    r = permutation_test((x, y), u_less, permutation_type="independent", alternative="less",
                         n_resamples=np.inf, vectorized=True)
    return float(r.pvalue)

def cliffs_delta(x, y):
    diff = np.subtract.outer(np.asarray(y), np.asarray(x))
    return float((np.sum(diff > 0) - np.sum(diff < 0)) / diff.size)


def cohens_d(x, y):
    x, y = np.asarray(x), np.asarray(y)
    dof = len(x) + len(y) - 2
    pooled = ((len(x) - 1) * np.var(x, ddof=1) + (len(y) - 1) * np.var(y, ddof=1)) / dof
    return None if pooled == 0 else float((y.mean() - x.mean()) / np.sqrt(pooled))


out = []
for x, y in cases:
    r = mannwhitneyu(x, y, alternative="less")
    out.append({"x": [float(v) for v in x], "y": [float(v) for v in y],
                "u": float(r.statistic), "p": float(r.pvalue), "p_exact": exact_p(x, y),
                "delta": cliffs_delta(x, y), "d": cohens_d(x, y)})
path = pathlib.Path(__file__).resolve().parents[2] / "data/reference/mannwhitneyu.json"
path.write_text(json.dumps({"scipy": scipy.__version__, "alternative": "less", "cases": out},
                           indent=1) + "\n")
print(f"wrote {len(out)} cases to {path}")
