"""Compares training runs' metrics line by line (clock fields left out) up to an epoch.

Usage: compare_runs.py --last-epoch N NAME=METRICS.jsonl ... > summary.json

Prints, as JSON, each run's lines at the epochs they all share (environment steps, skill coverage,
losses), the commit and processor of its first training process where a provenance.jsonl lies
beside the metrics, and, for each pair of runs, whether every shared line is equal in every field.
Used by rsqrt_emulation.sh; scripts/gpu/table.py takes its line comparison from here.
"""

import argparse
import json
import os
import sys

CLOCK = {"wall_s", "steps_per_s", "timings"}


def without_clock(rows, last_epoch):
    """The metrics rows up to `last_epoch`, clock fields left out."""
    return [{k: v for k, v in r.items() if k not in CLOCK} for r in rows if r["epoch"] <= last_epoch]


def first_difference(ours, theirs):
    """Where two runs' rows (from `without_clock`) first part: (line from 1, field, ours, theirs),
    with field None where one run has fewer lines; None where they are equal."""
    for i, (a, b) in enumerate(zip(ours, theirs)):
        if a != b:
            field = next(k for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k))
            return i + 1, field, a.get(field), b.get(field)
    if len(ours) != len(theirs):
        return min(len(ours), len(theirs)) + 1, None, len(ours), len(theirs)
    return None


def lines(path, last_epoch):
    with open(path, encoding="utf-8") as f:
        rows = [json.loads(text) for text in f if text.strip()]
    return {row["epoch"]: row for row in without_clock(rows, last_epoch)}


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
