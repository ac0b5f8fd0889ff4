"""A trained agent in Python (``seads.Agent``, no libtorch) against the ``seads`` binary
(libtorch) on the same checkpoint: the first plan of every task and the outcome of every task of
``seads evaluate`` with re-planning, executed step by step in a Python environment; and bad input
as exceptions."""

import json
import pathlib
import shutil

import gymnasium
import numpy as np
import pytest

import seads

DATA = pathlib.Path(__file__).with_name("data")
RUN = DATA / "agent-run"
TASKS = [json.loads(line) for line in open(RUN / "evaluation-replan-tasks.jsonl")]
# The bound of every search of that evaluation (`make_agent_run.sh`): a search that finds no plan
# stops here, as the binary's did.
MAX_EXPANDED = 2000


@pytest.fixture(scope="module")
def agent():
    return seads.Agent.load(str(RUN))


def board(task):
    return np.array([int(v) for v in task["board"].split(",")], dtype=np.uint8)


def test_the_agent_names_its_run(agent):
    assert (agent.env, agent.epoch, agent.num_skills) == ("lightsout-cursor", 510, 25)


@pytest.mark.without_gymnasium
def test_plans_are_the_binarys_first_plans(agent):
    for task in TASKS:
        if task["plan_found"]:
            assert agent.plan(board(task), max_expanded=MAX_EXPANDED) == task["first_plan"], task
        else:
            with pytest.raises(ValueError):
                agent.plan(board(task), max_expanded=MAX_EXPANDED)


@pytest.mark.without_gymnasium
def test_tasks_end_as_the_binarys_evaluation_task_for_task(agent):
    solved = 0
    for task in TASKS:
        options = {"reset_split": "test", "max_solution_depth": task["depth"], "random_solution_depth": False}
        env = seads.Env("lightsout-cursor", json.dumps(options))
        env.seed(task["seed"])
        env.reset()
        assert list(env.board()) == list(board(task))
        result = agent.solve(env, max_expanded=MAX_EXPANDED)
        assert result["solved"] == task["solved"], task
        assert result["skills"] == task["executed"], task
        assert result["steps"] == sum(task["skill_steps"]), task
        solved += result["solved"]
    assert solved == sum(t["solved"] for t in TASKS) > 0


def test_a_gymnasium_environment_is_solved_in_place(agent):
    task = next(t for t in TASKS if t["solved"] and t["depth"] >= 2)
    env = gymnasium.make("seads/LightsOutCursor-v0")
    env.reset(seed=1)
    result = agent.solve(env, board=board(task), max_expanded=MAX_EXPANDED)
    assert result["solved"]
    assert len(result["moves"]) == len(result["skills"]) >= task["depth"]
    assert env.unwrapped.board().sum() == 0, "the environment's board is solved"
    assert len(result["path"]) > len(result["skills"])


def test_actions_and_successors(agent):
    env = seads.Env("lightsout-cursor")
    env.seed(3)
    obs = env.reset()
    one = agent.act(obs, 4)
    assert one.shape == (3,) and one.dtype == np.float32
    rows = agent.act(np.stack([obs, obs]), [4, 5])
    assert rows.shape == (2, 3)
    np.testing.assert_array_equal(rows[0], one)
    sampled = agent.act(obs, 4, deterministic=False, seed=7)
    np.testing.assert_array_equal(sampled, agent.act(obs, 4, deterministic=False, seed=7))
    assert not np.array_equal(sampled, one)
    # Each skill's predicted board differs from the board by the move the model thinks it makes.
    start = env.board()
    succ = agent.successors(start)
    assert succ.shape == (25, 25) and succ.dtype == np.uint8
    task = next(t for t in TASKS if t["depth"] == 1 and t["solved"])
    after = agent.successors(board(task))[task["executed"][0]]
    assert after.sum() == 0, "the skill that solved the depth-1 board is predicted to solve it"


def test_bad_input_raises_value_errors(agent, tmp_path):
    with pytest.raises(ValueError, match="reading"):
        seads.Agent.load(str(tmp_path / "none"))
    with pytest.raises(ValueError, match="no checkpoint of epoch 7"):
        seads.Agent.load(str(RUN), checkpoint=7)
    damaged = tmp_path / "damaged"
    shutil.copytree(RUN, damaged)
    model = next(damaged.glob("checkpoints/*/forward_model.safetensors"))
    model.write_bytes(model.read_bytes()[:100])
    with pytest.raises(ValueError, match="forward_model"):
        seads.Agent.load(str(damaged))
    with pytest.raises(ValueError, match="values"):
        agent.plan(np.zeros(9, dtype=np.uint8))
    with pytest.raises(ValueError):
        agent.plan(np.full(25, 2, dtype=np.uint8))
    obs = np.zeros(28, dtype=np.float32)
    with pytest.raises(ValueError, match="skill 25"):
        agent.act(obs, 25)
    with pytest.raises(ValueError, match="shape"):
        agent.act(np.zeros(5, dtype=np.float32), 0)
    with pytest.raises(ValueError, match="NaN"):
        agent.act(np.full(28, np.nan, dtype=np.float32), 0)
    with pytest.raises(ValueError, match="seed"):
        agent.act(obs, 0, deterministic=False)
    with pytest.raises(ValueError, match="search"):
        agent.plan(np.ones(25, dtype=np.uint8), search="sideways")
    with pytest.raises(ValueError, match="tileswap-cursor"):
        agent.solve(seads.Env("tileswap-cursor"))
    with pytest.raises(ValueError, match="task mode"):
        agent.solve(seads.Env("lightsout-cursor", task=True))
    with pytest.raises(ValueError, match="seads environment"):
        agent.solve(object())


def test_the_agent_takes_its_environment_from_its_run(agent, tmp_path):
    """Issue 82: ``Agent.load`` built its game from the default options, not the run's, so a run
    of 7×7 boards loaded as a 5×5 agent, and a 5×5 agent planned on a 7×7 environment for half a
    minute. With its config set to 7×7 boards, the 5×5 networks of this run no longer fit and the
    load says so; the 5×5 agent refuses a 7×7 environment at once."""
    seven = tmp_path / "seven"
    shutil.copytree(RUN, seven)
    for config in [seven / "config.toml", *seven.glob("checkpoints/*/config.toml")]:
        text = config.read_text()
        assert "[env_config]\n" in text
        config.write_text(text.replace("[env_config]\n", "[env_config]\nboard_size = 7\n"))
    with pytest.raises(ValueError, match="environment of 49 fields"):
        seads.Agent.load(str(seven))
    env = gymnasium.make("seads/LightsOutCursor-v0", board_size=7)
    with pytest.raises(ValueError, match="7×7 board"):
        agent.solve(env)
    with pytest.raises(ValueError, match="7×7 board"):
        agent.clip(env, 3)


def test_observations_are_converted_and_actions_are_finite(agent):
    """Issue 82: float64 observations raised a TypeError, and finite observations of ±3e38 gave
    NaN actions without a word."""
    obs = np.linspace(-1, 1, 28)
    assert obs.dtype == np.float64
    assert np.array_equal(agent.act(obs, 3), agent.act(obs.astype(np.float32), 3))
    with pytest.raises(ValueError, match="float32's range"):
        agent.act(np.array([3e38, -3e38] * 14, dtype=np.float32), 0)
    with pytest.raises(ValueError, match="float32's range"):
        agent.act(np.full(28, 1e39), 0)
    with pytest.raises(ValueError, match="float32"):
        agent.act(np.zeros(28, dtype=np.int64), 0)


def test_one_agent_serves_several_threads(agent):
    """Issue 82: an agent used from two threads raised "Already mutably borrowed", even for its
    epoch, while another thread planned. Threads plan, solve and read it at once, with the
    answers of one thread alone."""
    import threading

    tasks = [t for t in TASKS if t["plan_found"]][:4]
    alone = [agent.plan(board(t), max_expanded=MAX_EXPANDED) for t in tasks]
    errors, plans = [], []

    def plan_all():
        try:
            for _ in range(3):
                plans.append([agent.plan(board(t), max_expanded=MAX_EXPANDED) for t in tasks])
        except Exception as e:  # noqa: BLE001 - any error is the test's failure
            errors.append(e)

    def read_all():
        try:
            for _ in range(300):
                assert agent.epoch == 510
                agent.successors(board(tasks[0]))
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=f) for f in (plan_all, plan_all, read_all)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert plans == [alone] * 6


def test_a_rendered_solution_is_the_same_solution_filmed(agent):
    """``solve(render=True)`` plays exactly the unfilmed solution (same skills, steps and end
    state) and returns a frame before the first step and one after each: the first is the
    environment's view before, the last its view after."""
    task = next(t for t in TASKS if t["solved"] and t["depth"] >= 2)
    plain, filmed = (seads.SeadsEnv("lightsout-cursor", render_mode="rgb_array") for _ in range(2))
    for env in (plain, filmed):
        env.reset(seed=4)
    before = filmed.render()
    a = agent.solve(plain, board=board(task), max_expanded=MAX_EXPANDED)
    b = agent.solve(filmed, board=board(task), max_expanded=MAX_EXPANDED, render=True)
    assert (a["skills"], a["steps"], a["solved"]) == (b["skills"], b["steps"], b["solved"])
    assert "frames" not in a and len(b["frames"]) == b["steps"] + 1
    assert all(f.shape == (256, 256, 3) and f.dtype == np.uint8 for f in b["frames"])
    assert not np.array_equal(b["frames"][0], before), "the board was set before the first frame"
    assert np.array_equal(plain.unwrapped._core.observation(), filmed.unwrapped._core.observation())
    assert np.array_equal(b["frames"][-1], filmed.render())


def test_a_skill_clip_is_the_skill_executed_step_by_step_in_python(agent):
    """``clip(env, k)`` against the skill run by hand: ``act`` for the observation, one step at a
    time, until the episode ends: the same move, the same number of steps, and a frame for the
    start and for each step, the last one the environment's view at the end."""
    for skill in (0, 7, 24):
        by_hand = seads.SeadsEnv("lightsout-cursor", render_mode="rgb_array")
        obs, _ = by_hand.reset(seed=skill)
        frames = [by_hand.render()]
        while True:
            obs, _, terminated, truncated, info = by_hand.step(agent.act(obs, skill))
            frames.append(by_hand.render())
            if terminated or truncated:
                break
        clipped = seads.SeadsEnv("lightsout-cursor", render_mode="rgb_array")
        clipped.reset(seed=skill)
        clip = agent.clip(clipped, skill)
        assert (clip["move"], clip["steps"]) == (info["move"], len(frames) - 1), skill
        assert all(np.array_equal(x, y) for x, y in zip(clip["frames"], frames)), skill
    with pytest.raises(ValueError, match="skill 25"):
        agent.clip(clipped, 25)
    with pytest.raises(ValueError, match="skill -1"):
        agent.clip(clipped, -1)
