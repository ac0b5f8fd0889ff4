"""How a trained agent's forward model handles the sliding puzzle's moves, which exist only in
some states (issue 45 item 4). On the 8-puzzle a push moves a tile only if it lies next to the
gap; a skill that pushes a field away from the gap changes nothing (the episode ends at T_max
with z_T = z_0).

For every board up to `--depth` moves from the goal (both splits), the script asks the model
for each skill's predicted successor (`Agent.successors`, the mode of q(z_T | z_0, k)) and
names it: the board after game move m ("move m"), the board itself ("nothing"), or another
board ("other"). Each skill's move is the move it is predicted to make most often where that
move exists. The first table then says, per skill, how often the model predicts that move where
it exists, and what it predicts where it does not: "nothing" is the right answer there.

A skill sees the board, so it may instead have learned a move relative to the gap ("the tile
above the gap slides down"), which exists wherever the gap is not on that edge. The second table
names each prediction by the way the gap moves (up, down, left, right), and says per skill how
often the model predicts its most frequent direction where that direction exists.

Usage: python scripts/analysis/sliding_model.py RUN_DIR [--depth 6] [--out FILE.json]
(needs the Python package: pip install ./crates/seads-py)"""

import argparse
import collections
import json

import numpy as np

import seads


# How the gap moves when the tile at (row, column) offset from it slides into it.
DIRECTIONS = {(-1, 0): "up", (1, 0): "down", (0, -1): "left", (0, 1): "right"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run")
    parser.add_argument("--depth", type=int, default=6)
    parser.add_argument("--out")
    args = parser.parse_args()
    agent = seads.Agent.load(args.run)
    game = seads.Game("sliding", 3)
    boards = np.concatenate(
        [game.boards(d, split) for d in range(1, args.depth + 1) for split in ("train", "test")]
    )
    k = agent.num_skills
    # predicted[skill] counts (kind, available) pairs; kind is "move m", "nothing" or "other".
    predicted = [collections.Counter() for _ in range(k)]
    per_move = [collections.Counter() for _ in range(k)]
    directions = [collections.Counter() for _ in range(k)]
    # Whether the predicted successor is a board at all (each tile once) and how many fields
    # it changes.
    valid, changed_fields = 0, collections.Counter()
    per_direction = [collections.Counter() for _ in range(k)]
    for board in boards:
        after = {m: game.apply(board, m) for m in range(game.num_moves)}
        available = {m for m, b in after.items() if not np.array_equal(b, board)}
        successors = agent.successors(board)
        for skill in range(k):
            z = successors[skill]
            valid += sorted(z.tolist()) == list(range(9))
            changed_fields[int((z != board).sum())] += 1
            if np.array_equal(z, board):
                kind = "nothing"
            else:
                kind = next((f"move {m}" for m in available if np.array_equal(after[m], z)), "other")
            predicted[skill][kind] += 1
            for m in range(game.num_moves):
                per_move[skill][(m, m in available, kind)] += 1
            gap = int(np.flatnonzero(board == 0)[0])
            way = {DIRECTIONS[(m // 3 - gap // 3, m % 3 - gap % 3)]: m for m in available}
            made = "nothing" if kind == "nothing" else "other"
            if kind.startswith("move"):
                m = int(kind.split()[1])
                made = DIRECTIONS[(m // 3 - gap // 3, m % 3 - gap % 3)]
            directions[skill][made] += 1
            for d in DIRECTIONS.values():
                per_direction[skill][(d, d in way, made)] += 1
    rows = []
    for skill in range(k):
        moves = [kind for kind in predicted[skill] if kind.startswith("move")]
        if not moves:
            rows.append({"skill": skill, "move": None, "predicted": dict(predicted[skill])})
            continue
        move = int(max(moves, key=lambda kind: predicted[skill][kind]).split()[1])
        where = {True: collections.Counter(), False: collections.Counter()}
        for (m, exists, kind), n in per_move[skill].items():
            if m == move:
                where[exists][kind] += n
        exists, absent = sum(where[True].values()), sum(where[False].values())
        rows.append({
            "skill": skill,
            "move": move,
            "boards_where_the_move_exists": exists,
            "predicts_the_move_there": where[True][f"move {move}"] / exists if exists else None,
            "boards_where_it_does_not": absent,
            "predicts_nothing_there": where[False]["nothing"] / absent if absent else None,
            "predicts_another_move_there": sum(n for kind, n in where[False].items()
                                               if kind.startswith("move")) / absent if absent else None,
        })
    relative = []
    for skill in range(k):
        made = [d for d in directions[skill] if d in DIRECTIONS.values()]
        if not made:
            relative.append({"skill": skill, "direction": None})
            continue
        d = max(made, key=lambda x: directions[skill][x])
        exists = sum(n for (dd, e, _), n in per_direction[skill].items() if dd == d and e)
        hits = sum(n for (dd, e, m), n in per_direction[skill].items() if dd == d and e and m == d)
        relative.append({"skill": skill, "direction": d, "boards_where_it_exists": exists,
                         "predicts_it_there": hits / exists if exists else None,
                         "predictions": dict(directions[skill])})
    report = {"run": args.run, "epoch": agent.epoch, "boards": len(boards),
              "max_depth": args.depth,
              "predictions_that_are_boards": valid / (len(boards) * k),
              "predictions_by_fields_changed": {str(n): c for n, c in sorted(changed_fields.items())},
              "skills": rows, "relative_to_the_gap": relative}
    text = json.dumps(report, indent=1)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")
    print(f"{len(boards)} boards of depth 1-{args.depth}; agent at epoch {agent.epoch}")
    print(f"predicted successors that are boards (each tile once): "
          f"{100 * report['predictions_that_are_boards']:.1f} %; fields changed: "
          f"{report['predictions_by_fields_changed']} (a slide changes 2)")
    print("skill  move  where it exists: predicted   where it does not: nothing / another move")
    for r in rows:
        if r["move"] is None:
            print(f"{r['skill']:>5}     -  predicts no move anywhere: {r['predicted']}")
            continue
        fmt = lambda x: "   -" if x is None else f"{100 * x:5.1f} %"
        print(f"{r['skill']:>5} {r['move']:>5}  {fmt(r['predicts_the_move_there']):>20}   "
              f"{fmt(r['predicts_nothing_there'])} / {fmt(r['predicts_another_move_there'])}")
    print("skill  gap moves  where it can: predicted   all predictions")
    for r in relative:
        if r["direction"] is None:
            print(f"{r['skill']:>5}          -")
            continue
        print(f"{r['skill']:>5} {r['direction']:>10}  {100 * r['predicts_it_there']:>18.1f} %   "
              f"{r['predictions']}")


if __name__ == "__main__":
    main()
