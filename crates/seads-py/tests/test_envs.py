"""The Gymnasium environments: the checker, the Rust episode files, task mode, rendering."""

import json
import pathlib

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import seads

DATA = pathlib.Path(__file__).parent / "data"


@pytest.mark.parametrize("name", seads.env_names())
def test_every_environment_passes_gymnasiums_checker(name):
    env = gymnasium.make(seads.gym_id(name), render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    assert env.spec.id == seads.gym_id(name)


def test_every_rust_environment_is_registered_under_its_camel_case_name():
    ids = {seads.gym_id(n) for n in seads.env_names()}
    assert {"seads/LightsOutCursor-v0", "seads/TileSwapReacher-v0", "seads/LightsOut3DJaco-v0"} <= ids
    assert ids <= set(gymnasium.registry)


@pytest.mark.parametrize("file", sorted(DATA.glob("*.jsonl")), ids=lambda p: p.stem)
def test_a_python_rollout_repeats_the_rust_episode_file_step_for_step(file):
    """`seads record --seed 11` wrote these episodes (data/README.md): the environment seeded
    with 11, reset before each episode, random actions, no step limit. Python's environment,
    seeded and reset the same way and put into the recorded state where the manipulator can be
    restored (the Jaco's cannot: there the reset must already give it), makes the same
    observations, bit for bit, and the same moves."""
    episodes = [json.loads(line) for line in file.read_text().splitlines()]
    env = seads.SeadsEnv(episodes[0]["env"])
    moves = 0
    for k, episode in enumerate(episodes):
        obs, _ = env.reset(seed=11 if k == 0 else None)
        initial = np.asarray(episode["initial_obs"], dtype=np.float32)
        if "jaco" in file.name:
            assert np.array_equal(obs[:-1], initial), f"{file.name} episode {k}: reset"
        else:
            env.set_state(initial)
        for t, step in enumerate(episode["steps"]):
            obs, reward, terminated, _, info = env.step(np.asarray(step["action"], dtype=np.float32))
            expected = np.asarray(step["obs"], dtype=np.float32)
            assert np.array_equal(obs[:-1], expected), f"{file.name} episode {k} step {t}"
            assert info["move"] == (-1 if step["move"] is None else step["move"]), f"step {t}"
            assert terminated == (step["move"] is not None)
            assert reward == 0.0
            moves += step["move"] is not None
    if "cursor" in file.name:
        assert moves > 0, "the file exercises moves"


def test_the_same_seed_gives_the_same_episode_and_another_seed_another():
    def rollout(seed):
        env = gymnasium.make("seads/LightsOutReacher-v0")
        obs, _ = env.reset(seed=seed)
        env.action_space.seed(seed)
        trace = [obs]
        for _ in range(30):
            obs, *_ = env.step(env.action_space.sample())
            trace.append(obs)
        return np.stack(trace)

    assert np.array_equal(rollout(4), rollout(4))
    assert not np.array_equal(rollout(4), rollout(5))


def test_skill_mode_ends_an_episode_at_a_move_or_the_step_limit():
    env = gymnasium.make("seads/LightsOutCursor-v0")
    obs, info = env.reset(seed=1)
    board = info["board"]
    # The cursor pushes where it is: a push on a field is a move, and it changes the board.
    obs, reward, terminated, truncated, info = env.step(np.array([0.0, 0.0, 1.0], dtype=np.float32))
    assert terminated and not truncated and reward == 0.0
    assert 0 <= info["move"] < 25
    game = seads.Game("lightsout")
    assert np.array_equal(info["board"], game.apply(board, info["move"]))
    # Without pushing, the episode is truncated after T_max = 10 steps.
    env.reset(seed=2)
    for t in range(10):
        *_, terminated, truncated, info = env.step(np.array([0.01, 0.0, -1.0], dtype=np.float32))
        assert not terminated and info["move"] == -1
        assert truncated == (t == 9)


def test_task_mode_pays_one_when_the_board_is_solved():
    env = gymnasium.make("seads/LightsOutCursor-v0", task=True, max_solution_depth=1,
                         random_solution_depth=False, reset_split="test")
    obs, info = env.reset(seed=3)
    assert info["depth"] == 1
    (press,) = seads.Game("lightsout").solve(info["board"])
    # Field `press` (row r, column c) has its centre at ((c + 0.5) / 5, (r + 0.5) / 5); the
    # cursor moves at most 0.2 a step, so 5 steps reach it, and T_lim = 10 · S = 10 steps.
    target = np.array([(press % 5 + 0.5) / 5, (press // 5 + 0.5) / 5], dtype=np.float32)
    for _ in range(5):
        delta = np.clip(target - obs[:2], -0.2, 0.2)
        obs, reward, terminated, truncated, info = env.step(np.array([*delta, -1.0], dtype=np.float32))
        assert (reward, terminated, truncated) == (0.0, False, False)
    obs, reward, terminated, truncated, info = env.step(np.array([0.0, 0.0, 1.0], dtype=np.float32))
    assert (reward, terminated, truncated) == (1.0, True, False)
    assert info["move"] == press and seads.Game("lightsout").is_goal(info["board"])


def test_task_mode_truncates_after_t_max_times_the_depth():
    env = gymnasium.make("seads/TileSwapCursor-v0", task=True, max_solution_depth=2,
                         random_solution_depth=False)
    _, info = env.reset(seed=5)
    assert info["depth"] == 2
    for t in range(20):
        _, reward, terminated, truncated, _ = env.step(np.array([0.0, 0.0, -1.0], dtype=np.float32))
        assert reward == 0.0 and not terminated
        assert truncated == (t == 19)


def test_render_is_an_rgb_image_of_the_board():
    env = gymnasium.make("seads/LightsOutCursor-v0", render_mode="rgb_array")
    env.reset(seed=0)
    image = env.render()
    assert image.shape == (256, 256, 3) and image.dtype == np.uint8
    # Lit fields are drawn in amber, unlit ones in dark grey: both show on a board with lights.
    colours = {tuple(c) for c in image.reshape(-1, 3)}
    assert (245, 190, 40) in colours and (70, 70, 80) in colours


def test_an_environment_pickles_as_a_new_one_with_its_settings():
    import pickle

    env = gymnasium.make("seads/LightsOutCursor-v0", max_solution_depth=3).unwrapped
    copy = pickle.loads(pickle.dumps(env))
    assert (copy.env_name, copy.task, copy._options) == (env.env_name, env.task, {"max_solution_depth": 3})
    first, _ = env.reset(seed=5)
    again, _ = copy.reset(seed=5)
    np.testing.assert_array_equal(first, again)
    action = np.array([0.1, -0.1, 1.0], dtype=np.float32)
    np.testing.assert_array_equal(env.step(action)[0], copy.step(action)[0])


@pytest.mark.parametrize("name", ["lightsout-cursor", "tileswap-cursor"])
def test_the_cursors_observation_is_bounded_and_the_checker_has_no_warning(name):
    """The cursor stays on the board: its part of the observation lies in [0, 1], and
    Gymnasium's checker has nothing to warn about."""
    import warnings

    env = gymnasium.make(seads.gym_id(name))
    space = env.observation_space
    assert np.all(space.low[:2] == 0.0) and np.all(space.high[:2] == 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)


def test_task_mode_reaches_the_deepest_boards_at_once():
    """Task mode at 5 x 5 LightsOut's largest depth, 15: each reset's depth is the game's own
    (it mapped every board up to the depth first: 681 s)."""
    env = seads.SeadsEnv("lightsout-cursor", task=True, max_solution_depth=15,
                         random_solution_depth=False)
    game = seads.Game("lightsout")
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert info["depth"] == game.depth(info["board"]) == 15


def test_a_game_added_in_rust_is_here_without_python_code():
    """The sliding puzzle is one Rust file: its game, environments and Gymnasium ids come from
    the Rust registries."""
    assert seads.game_names() == ["lightsout", "tileswap", "sliding"]
    ids = {seads.gym_id(n) for n in seads.env_names()}
    assert {"seads/SlidingCursor-v0", "seads/SlidingReacher-v0"} <= ids
    # The three-link arm is one Rust file too.
    assert {"seads/LightsOutReacher3-v0", "seads/SlidingReacher3-v0"} <= ids
    game = seads.Game("sliding", 4)
    goal = game.goal()
    assert list(goal) == list(range(1, 16)) + [0]
    # Push field 14 (tile 15 slides right into the gap), then field 10 (tile 11 slides down).
    board = game.apply(game.apply(goal, 14), 10)
    assert game.solve(board) == [14, 15]
    assert seads.plan(game, board) == [14, 15]
    swapped = goal.copy()
    swapped[[0, 1]] = swapped[[1, 0]]
    with pytest.raises(ValueError, match="cannot be solved"):
        seads.plan(game, swapped)
    with pytest.raises(ValueError, match="too many boards"):
        game.boards(3)
    # The 8-puzzle's two boards of depth 1 are both test boards: no training board, and an
    # empty table still has a column per field.
    eight = seads.Game("sliding")
    assert eight.boards(1, "train").shape == (0, 9)
    assert eight.boards(1, "test").shape == (2, 9)
