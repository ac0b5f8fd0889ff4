"""Games and planning against independent sources: binomial coefficients, Python's zlib CRC-32,
the project's committed depth counts, and breadth-first search against the GF(2) solver."""

import csv
import math
import pathlib
import zlib

import numpy as np
import pytest

import seads

ROOT = pathlib.Path(__file__).resolve().parents[3]


def test_3x3_lightsout_depths_are_binomial_coefficients():
    # Each set of k presses is its own board at depth k: C(9, k) boards.
    assert seads.Game("lightsout", 3).depth_counts() == [math.comb(9, k) for k in range(10)]


def test_depth_counts_match_the_committed_table():
    rows = list(csv.DictReader(open(ROOT / "data" / "depth_counts.csv")))
    for name, size in [("tileswap", 3), ("lightsout", 4)]:
        expected = [int(r["count"]) for r in rows if r["game"] == name and int(r["size"]) == size]
        assert seads.Game(name, size).depth_counts() == expected


def test_the_split_is_crc32_of_the_board_string_mod_3():
    game = seads.Game("lightsout")
    rng = np.random.default_rng(1)
    for _ in range(200):
        board = rng.integers(0, 2, 25).astype(np.uint8)
        crc = zlib.crc32(",".join(map(str, board)).encode())
        assert game.split(board) == ("train" if crc % 3 == 0 else "test")


@pytest.mark.parametrize("depth", [1, 3, 5])
def test_boards_of_a_depth_lie_at_that_depth_in_their_split(depth):
    game = seads.Game("lightsout")
    boards = game.boards(depth, "test")
    assert len(boards) > 0
    for board in boards[:: max(1, len(boards) // 25)]:
        assert game.depth(board) == depth and game.split(board) == "test"


def test_planning_with_the_true_model_finds_optimal_plans():
    for name in ["lightsout", "tileswap"]:
        game = seads.Game(name)
        rng = np.random.default_rng(2)
        for _ in range(20):
            board = game.goal()
            for move in rng.integers(0, game.num_moves, 4):
                board = game.apply(board, int(move))
            plan = seads.plan(game, board)
            assert len(plan) == game.depth(board) == len(game.solve(board))
            for move in plan:
                board = game.apply(board, move)
            assert game.is_goal(board)
    assert seads.plan(game, game.goal()) == []


def test_plan_on_an_unsolvable_board_says_so_at_once():
    # One lit corner cannot be solved on 5×5 LightsOut (its moves span 23 of 25 dimensions):
    # the solver's answer, not a search through every reachable board (no state budget here).
    game = seads.Game("lightsout")
    corner = np.zeros(25, dtype=np.uint8)
    corner[0] = 1
    with pytest.raises(ValueError) as solver_error:
        game.solve(corner)
    with pytest.raises(ValueError) as plan_error:
        seads.plan(game, corner, max_expanded=None)
    assert str(plan_error.value) == str(solver_error.value)
    # A goal of its own: a plan to it exists iff the boards differ by a solvable board.
    goal = np.zeros(25, dtype=np.uint8)
    goal[1] = goal[5] = 1
    start = goal.copy()
    start[0] = 1  # differs from the goal by a corner: unsolvable
    with pytest.raises(ValueError):
        seads.plan(game, start, goal=goal, max_expanded=None)
    move_0 = game.apply(np.zeros(25, dtype=np.uint8), 0)  # the corner and its two neighbours
    start = np.bitwise_xor(goal, move_0)  # differs from the goal by move 0
    assert seads.plan(game, start, goal=goal) == [0]
