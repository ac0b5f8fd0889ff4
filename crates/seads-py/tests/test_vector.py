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


def _sync(name, n, task, mode):
    """Gymnasium's own vector environment over single environments: the reference."""
    from functools import partial

    return gymnasium.vector.SyncVectorEnv(
        [partial(seads.SeadsEnv, name, task=task) for _ in range(n)], autoreset_mode=mode
    )


def _same_info(ours, ref, keys):
    for key in keys:
        assert np.array_equal(ours[f"_{key}"], ref[f"_{key}"]), key
        mask = ref[f"_{key}"]
        assert np.array_equal(np.asarray(ours[key])[mask], np.asarray(ref[key])[mask]), key


@pytest.mark.parametrize("mode", [gymnasium.vector.AutoresetMode.NEXT_STEP,
                                  gymnasium.vector.AutoresetMode.SAME_STEP,
                                  gymnasium.vector.AutoresetMode.DISABLED])
@pytest.mark.parametrize("name,task", [("lightsout-cursor", True), ("tileswap-cursor", False)])
def test_every_autoreset_mode_equals_gymnasiums_sync_vector(mode, name, task):
    """Observations, rewards, flags and the whole info (board, move, task depth, and under
    same-step autoreset the final observation and info) equal Gymnasium's SyncVectorEnv over
    single environments, step for step; under disabled autoreset both reset the ended
    environments through a reset mask."""
    n, steps = 5, 150
    ours = gymnasium.make_vec(seads.gym_id(name), num_envs=n, vectorization_mode="vector_entry_point",
                              task=task, autoreset_mode=mode)
    ref = _sync(name, n, task, mode)
    assert ours.metadata["autoreset_mode"] == mode
    keys = ["board", "depth"] if task else ["board"]
    (o1, i1), (o2, i2) = ours.reset(seed=3), ref.reset(seed=3)
    assert np.array_equal(o1, o2)
    _same_info(i1, i2, keys)
    rng = np.random.default_rng(1)
    low, high = ours.single_action_space.low, ours.single_action_space.high
    finals = 0
    for t in range(steps):
        actions = rng.uniform(low, high, size=(n, len(low))).astype(np.float32)
        a, b = ours.step(actions), ref.step(actions)
        for x, y, what in zip(a[:4], b[:4], ["obs", "reward", "terminated", "truncated"]):
            assert np.array_equal(x, y), f"step {t}: {what}"
        _same_info(a[4], b[4], keys + ["move"])
        assert ("final_obs" in a[4]) == ("final_obs" in b[4]), f"step {t}"
        if "final_obs" in b[4]:
            finals += 1
            mask = b[4]["_final_obs"]
            assert np.array_equal(a[4]["_final_obs"], mask)
            assert np.array_equal(np.stack(a[4]["final_obs"][mask]), np.stack(b[4]["final_obs"][mask]))
            _same_info(a[4]["final_info"], b[4]["final_info"], keys + ["move"])
        if mode == gymnasium.vector.AutoresetMode.DISABLED:
            ended = a[2] | a[3]
            if ended.any():
                finals += 1
                (o1, i1), (o2, i2) = (ours.reset(options={"reset_mask": ended}),
                                      ref.reset(options={"reset_mask": ended}))
                assert np.array_equal(o1, o2)
                _same_info(i1, i2, keys)
    if mode != gymnasium.vector.AutoresetMode.NEXT_STEP:
        assert finals > 2, "episodes ended and were reset"


def test_disabled_autoreset_refuses_to_step_an_ended_environment():
    vec = seads.SeadsVectorEnv("lightsout-cursor", 2, autoreset_mode="disabled", step_limit=1)
    vec.reset(seed=0)
    vec.step(np.zeros((2, 3), dtype=np.float32))
    with pytest.raises(ValueError, match="reset_mask"):
        vec.step(np.zeros((2, 3), dtype=np.float32))
    with pytest.raises(ValueError, match="reset_mask"):
        vec.reset(options={"reset_mask": np.array([1, 0])})  # not bools
    with pytest.raises(ValueError, match="reset_mask"):
        vec.reset(options={"reset_mask": np.array([True, False, True])})  # not one per environment
    vec.reset(options={"reset_mask": np.array([True, True])})
    vec.step(np.zeros((2, 3), dtype=np.float32))


def test_a_vector_steps_only_between_reset_and_close():
    vec = seads.SeadsVectorEnv("lightsout-cursor", 2)
    with pytest.raises(gymnasium.error.ResetNeeded):
        vec.step(np.zeros((2, 3), dtype=np.float32))
    vec.reset(seed=0)
    vec.step(np.zeros((2, 3), dtype=np.float32))
    vec.close()
    with pytest.raises(gymnasium.error.ClosedEnvironmentError):
        vec.step(np.zeros((2, 3), dtype=np.float32))
    with pytest.raises(gymnasium.error.ClosedEnvironmentError):
        vec.reset()
    with pytest.raises(ValueError, match="autoreset_mode"):
        seads.SeadsVectorEnv("lightsout-cursor", 2, autoreset_mode="sometimes")
    with pytest.raises(ValueError, match="reset options"):
        seads.SeadsVectorEnv("lightsout-cursor", 2).reset(options={"board": 3})


def test_a_small_vector_of_slow_environments_is_shared_among_threads():
    """64 Jaco arms are cut into pieces of work for every thread (they were one piece: a
    64-environment Jaco vector stepped on one thread)."""
    import os

    vec = seads.SeadsVectorEnv("lightsout-jaco", 64)
    threads = min(os.cpu_count() or 1, 64)
    assert vec._core.chunk_size <= max(1, 64 // (2 * threads)) or threads == 1


def test_a_vector_too_large_for_the_memory_limit_raises_memory_error():
    """With 512 MB of address space left beyond what the interpreter holds once the package is
    imported, 100,000 Jaco environments (about 10 GB) stop with a MemoryError while they are
    built, and the interpreter lives on (it aborted: exit 134)."""
    import subprocess
    import sys

    code = (
        "import resource\n"
        "import seads\n"
        "held = int(open('/proc/self/status').read().split('VmSize:')[1].split()[0]) << 10\n"
        "resource.setrlimit(resource.RLIMIT_AS, (held + (512 << 20), held + (512 << 20)))\n"
        "try:\n"
        "    seads.SeadsVectorEnv('lightsout-jaco', 100000)\n"
        "except MemoryError as e:\n"
        "    print('MemoryError:', e)\n"
        "print('alive')\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    assert "MemoryError: 100000 lightsout-jaco environments do not fit" in result.stdout
    assert result.stdout.rstrip().endswith("alive")
