"""Compares training runs' metrics line by line (clock fields left out) up to an epoch.

Usage: compare_runs.py --last-epoch N NAME=METRICS.jsonl ... > summary.json

Prints, as JSON, each run's lines at the epochs they all share (environment steps, skill coverage,
losses), the commit and processor of its first training process where a provenance.jsonl lies
beside the metrics, and, for each pair of runs, whether every shared line is equal in every field.
Used by rsqrt_emulation.sh.
"""

import argparse
import json
import os
import sys

CLOCK = {"wall_s", "steps_per_s", "timings"}


def lines(path, last_epoch):
    out = {}
    with open(path, encoding="utf-8") as f:
        for text in f:
            row = json.loads(text)
            if row["epoch"] > last_epoch:
                break
            out[row["epoch"]] = {k: v for k, v in row.items() if k not in CLOCK}
    return out


def provenance(path):
    beside = os.path.join(os.path.dirname(path), "provenance.jsonl")
    if not os.path.exists(beside):
        return None
    with open(beside, encoding="utf-8") as f:
        first = json.loads(f.readline())
    return {k: first.get(k) for k in ("commit", "dirty", "cpu_vendor", "cpu_model", "avx512")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--last-epoch", type=int, required=True)
    parser.add_argument("runs", nargs="+", metavar="NAME=METRICS")
    args = parser.parse_args()
    runs, made_by = {}, {}
    for item in args.runs:
        name, _, path = item.partition("=")
        if not path:
            sys.exit(f"compare_runs: {item!r} is not NAME=METRICS")
        runs[name] = lines(path, args.last_epoch)
        made_by[name] = provenance(path)
    shared = sorted(set.intersection(*(set(r) for r in runs.values())))
    if not shared:
        sys.exit("compare_runs: the runs share no epoch")
    names = list(runs)
    summary = {
        "epochs_compared": shared,
        "made_by": made_by,
        "lines": {
            name: {str(e): runs[name][e] for e in shared} for name in names
        },
        "equal": {
            a: {b: all(runs[a][e] == runs[b][e] for e in shared) for b in names if b != a}
            for a in names
        },
    }
    json.dump(summary, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
