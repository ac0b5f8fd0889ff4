"""The package README's examples run, and the training loop learns."""

import pathlib
import runpy

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def test_the_training_loop_solves_more_boards_than_at_its_start():
    train = runpy.run_path(str(EXAMPLES / "cem.py"))["train"]
    history = train(iterations=60, n=256)
    # A random linear policy solves about 2 % of depth-1 boards; the elites' mean does better.
    assert sum(history[-10:]) / 10 > 3 * sum(history[:5]) / 5


def test_the_random_rollout_renders_every_step():
    rollout = runpy.run_path(str(EXAMPLES / "random_rollout.py"))["rollout"]
    frames = rollout(steps=30)
    assert frames.shape == (31, 256, 256, 3)
