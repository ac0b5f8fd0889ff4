"""Bad input raises a Python exception with a clear message; the interpreter never crashes."""

import gymnasium
import numpy as np
import pytest

import seads


def test_a_wrong_action_shape_is_a_value_error():
    env = gymnasium.make("seads/LightsOutCursor-v0")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros(4, dtype=np.float32))
    core = seads.Env("lightsout-cursor")
    core.reset()
    with pytest.raises(ValueError, match="3 values, got 2"):
        core.step(np.zeros(2, dtype=np.float32))


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_non_finite_action_is_a_value_error(bad):
    env = seads.SeadsEnv("lightsout-reacher")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="not a finite number"):
        env.step(np.array([0.0, bad, 0.0], dtype=np.float32))
    vec = seads.SeadsVectorEnv("lightsout-cursor", 4)
    vec.reset(seed=0)
    actions = np.zeros((4, 3), dtype=np.float32)
    actions[2, 1] = bad
    with pytest.raises(ValueError, match="environment 2"):
        vec.step(actions)
    with pytest.raises(ValueError, match="shape"):
        vec.step(np.zeros((3, 3), dtype=np.float32))


def test_unknown_environments_and_options_are_named():
    with pytest.raises(gymnasium.error.Error):
        gymnasium.make("seads/NoSuchGame-v0")
    with pytest.raises(ValueError, match="unknown environment"):
        seads.SeadsEnv("no-such-game")
    with pytest.raises(ValueError, match="max_depth"):
        seads.SeadsEnv("lightsout-cursor", max_depth=3)
    with pytest.raises(ValueError, match="max_solution_depth"):
        seads.SeadsEnv("lightsout-cursor", max_solution_depth=0)
    with pytest.raises(ValueError, match="num_envs"):
        seads.SeadsVectorEnv("lightsout-cursor", 0)


def test_a_manipulator_takes_its_own_options_only():
    jaco = seads.SeadsEnv("lightsout-jaco", manipulator={"physics_substeps": 5})
    jaco.reset(seed=0)
    jaco.step(np.zeros(jaco.action_space.shape, dtype=np.float32))
    with pytest.raises(ValueError, match="invalid manipulator options.*physics_substeps"):
        seads.SeadsEnv("lightsout-cursor", manipulator={"physics_substeps": 5})
    with pytest.raises(ValueError, match="invalid manipulator options"):
        seads.SeadsEnv("lightsout-jaco", manipulator={"physics_substeps": 0})


def test_wrong_boards_and_moves_are_value_errors():
    game = seads.Game("lightsout")
    with pytest.raises(ValueError):
        game.solve([2] * 25)
    with pytest.raises(ValueError):
        game.depth([0] * 24)
    with pytest.raises(ValueError, match="move 25"):
        game.apply(game.goal(), 25)
    with pytest.raises(ValueError):
        seads.Game("tileswap").depth([0] * 9)
    with pytest.raises(ValueError, match="split"):
        game.boards(2, "validation")
    with pytest.raises(ValueError, match="game"):
        seads.Game("chess")
    with pytest.raises(ValueError, match="bit"):
        seads.Env("lightsout-cursor").set_state(np.full(27, 0.5, dtype=np.float32))


@pytest.mark.parametrize("shape", ["list", "uint8", "int64", "float32", "bool", "square", "tuple"])
def test_a_board_may_come_in_any_whole_number_form(shape):
    """A board is its values, row-major, in any array-like of whole numbers: a list, an integer,
    float or bool array, a slice of an observation, or the 5 x 5 square."""
    game = seads.Game("lightsout")
    values = game.apply(game.apply(game.goal(), 3), 17)
    form = {
        "list": [int(v) for v in values],
        "uint8": values,
        "int64": values.astype(np.int64),
        "float32": np.concatenate([[0.3, 0.7], values.astype(np.float32), [1.0]])[2:-1],
        "bool": values.astype(bool),
        "square": values.reshape(5, 5),
        "tuple": tuple(int(v) for v in values),
    }[shape]
    assert game.depth(form) == 2
    assert game.solve(form) == [3, 17]
    assert seads.plan(game, form) == [3, 17]
    assert np.array_equal(game.apply(form, 3), game.apply(game.goal(), 17))


@pytest.mark.parametrize("bad,message", [
    (np.full(25, 0.5), "board value 0.5 at field 0"),
    (np.full(25, np.nan), "not a field value"),
    (np.full(25, -1), "board value -1"),
    (np.zeros((5, 4)), "shape"),
    (np.zeros((2, 5, 5)), "shape"),
    (np.array(["a"] * 25), "whole numbers"),
    ([[0, 1], [0]], "a board"),
    (np.zeros(24, dtype=np.uint8), "25"),
    (np.full(25, 2), "0 or 1"),
])
def test_a_malformed_board_is_a_value_error_saying_what_is_wrong(bad, message):
    game = seads.Game("lightsout")
    with pytest.raises(ValueError, match=message):
        game.depth(bad)


def test_a_negative_or_too_large_move_is_a_value_error():
    game = seads.Game("tileswap")
    for mv in (-1, 12, 10**6):
        with pytest.raises(ValueError, match=f"move {mv}: the game has moves 0 to 11"):
            game.apply(game.goal(), mv)


def test_a_panic_of_ours_is_a_runtime_error_that_except_exception_catches():
    """A defect in the Rust half never reaches Python as pyo3's ``PanicException``, a
    ``BaseException`` that ``except Exception`` misses (issue 82): every fallible call guards
    its body (the tidy test ``every_fallible_python_method_guards_its_body`` lists them)."""
    try:
        seads._seads._panic("a defect")
    except Exception as e:  # noqa: BLE001 -- the point: an ordinary exception
        assert isinstance(e, RuntimeError), type(e)
        assert "a defect" in str(e)
    else:
        raise AssertionError("no exception")
