"""The vector environment equals N single environments, with Gymnasium's next-step autoreset."""

import gymnasium
import numpy as np
import pytest

import seads


@pytest.mark.parametrize("name,task", [("lightsout-cursor", False), ("tileswap-reacher", False),
                                       ("lightsout-cursor", True)])
def test_the_vector_environment_equals_single_environments(name, task):
    n, steps = 6, 120
    vec = gymnasium.make_vec(seads.gym_id(name), num_envs=n, vectorization_mode="vector_entry_point",
                             task=task)
    singles = [seads.SeadsEnv(name, task=task) for _ in range(n)]
    obs, _ = vec.reset(seed=100)
    expected = [env.reset(seed=100 + i)[0] for i, env in enumerate(singles)]
    assert np.array_equal(obs, np.stack(expected))
    rng = np.random.default_rng(0)
    low, high = vec.single_action_space.low, vec.single_action_space.high
    ended = [False] * n
    episodes_ended = 0
    for t in range(steps):
        actions = rng.uniform(low, high, size=(n, len(low))).astype(np.float32)
        obs, reward, terminated, truncated, info = vec.step(actions)
        for i, env in enumerate(singles):
            if ended[i]:
                # Next-step autoreset: this step resets environment i and ignores its action.
                o, r, te, tr, mv = env.reset()[0], 0.0, False, False, -1
            else:
                o, r, te, tr, inf = env.step(actions[i])
                mv = inf["move"]
            assert np.array_equal(obs[i], o), f"env {i} step {t}"
            assert (reward[i], terminated[i], truncated[i], info["move"][i]) == (r, te, tr, mv)
            ended[i] = te or tr
            episodes_ended += te or tr
    assert episodes_ended > n, "autoreset was exercised"
    assert np.array_equal(vec.unwrapped.boards(), np.stack([e.board() for e in singles]))


def test_reset_takes_a_seed_per_environment_and_the_arrays_are_the_callers():
    vec = seads.SeadsVectorEnv("lightsout-cursor", 3)
    a, _ = vec.reset(seed=[7, 8, 9])
    b, _ = vec.reset(seed=7)
    assert np.array_equal(a, b)
    obs, *_ = vec.step(np.zeros((3, 3), dtype=np.float32))
    again, *_ = vec.step(np.zeros((3, 3), dtype=np.float32))
    assert obs is not again and not np.shares_memory(obs, again)
    image = vec.render() if vec.render_mode else vec.unwrapped._core.render(2)
    assert image.shape == (256, 256, 3)
