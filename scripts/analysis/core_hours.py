"""Training core-hours per study: the sum of the runs' wall time (`wall_s`) in each study's
`walltime.csv` (written by `seads report`), over 3,600. Every run of these studies trained on one
core of its own or one shared core, so wall time is core time; evaluations by a separate binary are
not counted. A run that two studies report (the ten-seed study holds Table 1's seeds 1-5) counts in
each, except where a report reads another study's committed runs in place (its `run` path lies under
docs/results/<that study>/, as the TileSwapCursor baselines read the VIC study's SEADS runs): those
count in the study that holds them only. Usage: python3 scripts/analysis/core_hours.py [docs/results]"""

import csv
import pathlib
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "docs/results")


def held_elsewhere(study, run):
    """Whether `run` is a path into another study's committed folder."""
    parts = pathlib.PurePosixPath(run).parts
    return parts[:2] == ("docs", "results") and len(parts) > 2 and parts[2] != study


rows = []
for path in sorted(root.glob("*/walltime.csv")):
    study = path.parent.name
    with path.open() as f:
        runs = [
            r
            for r in csv.DictReader(f)
            if r.get("wall_s") and not held_elsewhere(study, r["run"])
        ]
    hours = sum(float(r["wall_s"]) for r in runs) / 3600
    steps = sum(int(r["env_steps"]) for r in runs if r.get("env_steps"))
    rows.append((study, len(runs), hours, steps))
print("| study | runs | training core-hours | environment steps |")
print("|---|---|---|---|")
for study, n, hours, steps in rows:
    print(f"| {study} | {n} | {hours:.1f} | {steps:,} |")
print(f"| all | {sum(r[1] for r in rows)} | {sum(r[2] for r in rows):.1f} | {sum(r[3] for r in rows):,} |")
