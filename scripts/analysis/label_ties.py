"""The label-tie study: how ties in SEADS's joint relabelling break, ours against SciPy's.

Reads relabelling problems dumped from real training by
`cargo run --release -p seads-rl --example relabel_dump -- ... --out DUMP.jsonl` (one JSON line
per problem: epoch, batch, k, labels in, labels out, clipped log-posteriors). Each problem is
solved again as the authors solve it (seads-agent, `compute_assignment_relabelling`): SciPy's
`linear_sum_assignment` on the square matrix whose row i is the slot of episode i's label, in
episode order, and whose column j is episode j, cost -C_j[label_i].

For each solver it reports, over the "tied" episodes -- those whose new label's clipped
log-posterior sits at the floor -2 log K, so that any other label at the floor would have cost
the same -- how their labels spread over label indices: the mean index, the share in the lower
half of the labels, and a chi-square statistic of the index histogram against the labels'
share of floor slots. It also checks that both solutions have the same (optimal) total.

    python3 scripts/analysis/label_ties.py DUMP.jsonl[.gz] [DUMP2 ...] [--json OUT]

The committed study (docs/results/label-ties/, K = 25 and K = 30, seed 1, 2.5e5 steps, a
problem of each batch every 250th epoch):

    cargo run --release -p seads-rl --example relabel_dump -- --skills 25 --out k25.jsonl
    cargo run --release -p seads-rl --example relabel_dump -- --skills 30 --out k30.jsonl
    python3 scripts/analysis/label_ties.py docs/results/label-ties/k25.jsonl.gz \
        docs/results/label-ties/k30.jsonl.gz --json docs/results/label-ties/summary.json

Needs NumPy and SciPy (run with SciPy 1.17, NumPy 2.x); standard library otherwise.
"""

import argparse
import gzip
import json
import sys

import numpy as np
import scipy
from scipy.optimize import linear_sum_assignment


def scipy_labels(clipped, labels):
    """The authors' relabelling: rows are slots (labels in episode order), columns episodes."""
    cost = -clipped[:, labels].T  # cost[i, j] = -C_j[labels[i]]
    rows, cols = linear_sum_assignment(cost)
    out = np.empty(len(labels), dtype=int)
    out[cols] = labels[rows]
    return out


def total(clipped, assigned):
    return float(-clipped[np.arange(len(assigned)), assigned].astype(np.float64).sum())


def summarise(name, assigned_list, clipped_list, k):
    """Spread of the tied episodes' labels over label indices."""
    hist = np.zeros(k)
    for clipped, assigned in zip(clipped_list, assigned_list):
        floor = clipped.min()
        value = clipped[np.arange(len(assigned)), assigned]
        tied = value == floor
        np.add.at(hist, assigned[tied], 1)
    n = hist.sum()
    index = np.arange(k)
    return {
        "solver": name,
        "tied_episodes": int(n),
        "mean_label_index": float((hist * index).sum() / max(n, 1)),
        "lower_half_share": float(hist[: k // 2].sum() / max(n, 1)),
        "histogram": hist.astype(int).tolist(),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dumps", nargs="+")
    parser.add_argument("--json", help="write the summary here")
    args = parser.parse_args()
    summary = {"scipy": scipy.__version__, "groups": []}
    for path in args.dumps:
        groups = {}
        opener = gzip.open if path.endswith(".gz") else open
        with opener(path, "rt") as f:
            for line in f:
                p = json.loads(line)
                groups.setdefault((p["k"], p["batch"]), []).append(p)
        for (k, batch), problems in sorted(groups.items()):
            ours, theirs, clipped_list, same_total, worst = [], [], [], 0, 0.0
            changed_ours = changed_theirs = episodes = 0
            same_tied_multiset = agree = tied_total = 0
            kept_ours = kept_theirs = 0
            for p in problems:
                labels = np.array(p["labels"], dtype=int)
                clipped = np.array(p["clipped"], dtype=np.float32).reshape(len(labels), k)
                mine = np.array(p["relabelled"], dtype=int)
                sp = scipy_labels(clipped, labels)
                assert sorted(mine) == sorted(labels), "ours changed the label multiset"
                gap = abs(total(clipped, mine) - total(clipped, sp))
                worst = max(worst, gap)
                same_total += gap <= 1e-3
                ours.append(mine)
                theirs.append(sp)
                clipped_list.append(clipped)
                floor = clipped.min()
                rows = np.arange(len(labels))
                tied_mine = clipped[rows, mine] == floor
                tied_sp = clipped[rows, sp] == floor
                same_tied_multiset += sorted(mine[tied_mine]) == sorted(sp[tied_sp])
                agree += int((mine == sp).sum())
                tied_total += int(tied_mine.sum())
                kept_ours += int((mine[tied_mine] == labels[tied_mine]).sum())
                kept_theirs += int((sp[tied_sp] == labels[tied_sp]).sum())
                changed_ours += int((mine != labels).sum())
                changed_theirs += int((sp != labels).sum())
                episodes += len(labels)
            # The expected spread without bias: every floor slot equally likely, i.e. the
            # label histogram of the slots the tied episodes could take. Approximate it by the
            # multiset of labels in the problems (each label's share of slots).
            slots = np.zeros(k)
            for p in problems:
                np.add.at(slots, np.array(p["labels"], dtype=int), 1)
            share = slots / slots.sum()
            group = {
                "dump": path.rsplit("/", 1)[-1],
                "k": k,
                "batch": batch,
                "problems": len(problems),
                "episodes": episodes,
                "epochs": sorted({p["epoch"] for p in problems}),
                "same_optimal_total": same_total,
                "largest_total_gap": worst,
                "same_tied_label_multiset": same_tied_multiset,
                "episodes_with_the_same_label": agree,
                "tied_episodes_keeping_their_label": {"ours": kept_ours, "scipy": kept_theirs},
                "relabelled_share": {
                    "ours": changed_ours / episodes,
                    "scipy": changed_theirs / episodes,
                },
                "slot_share_lower_half": float(share[: k // 2].sum()),
                "slot_mean_label_index": float((share * np.arange(k)).sum()),
                "solvers": [
                    summarise("ours", ours, clipped_list, k),
                    summarise("scipy", theirs, clipped_list, k),
                ],
            }
            for s in group["solvers"]:
                h = np.array(s["histogram"], dtype=float)
                expected = share * h.sum()
                mask = expected > 0
                s["chi2_vs_slots"] = float(((h[mask] - expected[mask]) ** 2 / expected[mask]).sum())
            summary["groups"].append(group)
            print(
                f"{group['dump']}: K={k} {batch}: {len(problems)} problems, {episodes} episodes, "
                f"same optimum in {same_total} (largest gap {worst:.2e})"
            )
            print(
                f"  tied episodes get the same label multiset in {same_tied_multiset} problems; "
                f"{agree}/{episodes} episodes get the same label; tied episodes keeping their "
                f"label: ours {kept_ours}, scipy {kept_theirs} of {tied_total}"
            )
            print(
                f"  slots: mean label index {group['slot_mean_label_index']:.2f}, "
                f"lower half {group['slot_share_lower_half']:.3f}"
            )
            for s in group["solvers"]:
                print(
                    f"  {s['solver']:>5}: {s['tied_episodes']} tied episodes, mean label index "
                    f"{s['mean_label_index']:.2f}, lower half {s['lower_half_share']:.3f}, "
                    f"chi2 vs slots {s['chi2_vs_slots']:.1f} ({k - 1} dof)"
                )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    sys.exit(main())
