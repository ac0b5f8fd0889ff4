#!/usr/bin/env python3
"""Which test boards of a 5×5 LightsOut evaluation need one field pressed.

Usage: lightsout_needs_field.py TASKS_JSONL FIELD

TASKS_JSONL is a per-task file of `seads evaluate` (e.g. evaluation-replan-tasks.jsonl); FIELD is
a field id (row-major, 0 at the top left). LightsOut is linear over GF(2): a board has 4
solutions (sets of presses). For each task whose fewest-press solution presses FIELD, this prints
its depth, that solution's length, the fewest presses of a solution that avoids FIELD, and what
the agent did (skills executed, plans, solved). Standard library only; used for docs/RESULTS.md
("LightsOutJaco at 10⁷ steps on main").
"""
import itertools
import json
import sys

N = 5
CELLS = N * N


def toggles(field):
    r, c = divmod(field, N)
    mask = 0
    for dr, dc in ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)):
        rr, cc = r + dr, c + dc
        if 0 <= rr < N and 0 <= cc < N:
            mask |= 1 << (rr * N + cc)
    return mask


def solutions(board):
    """Every press set x (bit i = press field i) that turns `board` off."""
    presses = [toggles(i) for i in range(CELLS)]
    # One equation per cell: the presses that toggle it, and the cell's value.
    rows = []
    for cell in range(CELLS):
        coeff = sum(1 << i for i in range(CELLS) if presses[i] >> cell & 1)
        rows.append([coeff, board >> cell & 1])
    pivot_row = [-1] * CELLS
    r = 0
    for col in range(CELLS):
        sel = next((k for k in range(r, CELLS) if rows[k][0] >> col & 1), None)
        if sel is None:
            continue
        rows[r], rows[sel] = rows[sel], rows[r]
        for k in range(CELLS):
            if k != r and rows[k][0] >> col & 1:
                rows[k][0] ^= rows[r][0]
                rows[k][1] ^= rows[r][1]
        pivot_row[col] = r
        r += 1
    if any(row[0] == 0 and row[1] for row in rows):
        return []
    free = [c for c in range(CELLS) if pivot_row[c] == -1]
    result = []
    for bits in itertools.product((0, 1), repeat=len(free)):
        x = sum(1 << f for f, b in zip(free, bits) if b)
        for col in range(CELLS):
            if pivot_row[col] != -1:
                coeff, value = rows[pivot_row[col]]
                for f, b in zip(free, bits):
                    if b and coeff >> f & 1:
                        value ^= 1
                if value:
                    x |= 1 << col
        result.append(x)
    return result


def main():
    if len(sys.argv) != 3 or not sys.argv[2].isdigit() or int(sys.argv[2]) >= CELLS:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        sys.exit(2)
    path, field = sys.argv[1], int(sys.argv[2])
    needing = 0
    with open(path) as f:
        for line in f:
            task = json.loads(line)
            values = [int(v) for v in task["board"].split(",")]
            board = sum(v << i for i, v in enumerate(values))
            sols = solutions(board)
            best = min(sols, key=lambda s: bin(s).count("1"))
            if not best >> field & 1:
                continue
            needing += 1
            avoiding = [bin(s).count("1") for s in sols if not s >> field & 1]
            print(
                f"depth {task['depth']}: shortest {bin(best).count('1')} presses, "
                f"without field {field} {min(avoiding) if avoiding else '-'}; "
                f"executed {len(task['executed'])} skills in {task['plans']} plans, "
                f"solved {task['solved']}"
            )
    print(f"{needing} task(s) whose shortest solution presses field {field}")


if __name__ == "__main__":
    main()
