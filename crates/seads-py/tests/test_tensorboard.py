"""A run's TensorBoard events, read by TensorBoard's own reader, hold its metrics.jsonl: every
line an event at its environment step, every number a scalar.

It trains a tiny run with the ``seads`` binary, so it is switched on by ``SEADS_BIN`` (the
binary's path; ``cargo xtask ci`` sets it) and fails when that names no binary."""

import json
import math
import os
import pathlib
import subprocess

import pytest

BIN = os.environ.get("SEADS_BIN")
ROOT = pathlib.Path(__file__).resolve().parents[3]

pytestmark = [
    pytest.mark.without_gymnasium,
    pytest.mark.skipif(BIN is None, reason="SEADS_BIN (the seads binary) is not set"),
]


def tiny_config(path: pathlib.Path) -> None:
    """The Cursor's preset layer on LightsOut with small networks and a budget of 600 steps,
    evaluated every 5 epochs (as the end-to-end tests' tiny run)."""
    layer = (ROOT / "configs" / "cursor.toml").read_text()
    for old, new in [
        ("env_steps = 500000", "env_steps = 600"),
        ("hidden = [256, 256]", "hidden = [32, 32]"),
        ("sampled_episodes = 256", "sampled_episodes = 32"),
        ("recent_episodes = 256", "recent_episodes = 16"),
        ("eval_every = 100", "eval_every = 5"),
        ("checkpoint_every = 100", "checkpoint_every = 5"),
        ("eval_seeds = 20", "eval_seeds = 1"),
        ("sac_threads_alone = 2", "sac_threads_alone = 0"),
    ]:
        assert old in layer, old
        layer = layer.replace(old, new)
    path.write_text('env = "lightsout-cursor"\n' + layer)


def test_tensorboard_reads_a_runs_metrics(tmp_path):
    assert pathlib.Path(BIN).is_file(), f"SEADS_BIN={BIN} is no file"
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    config = tmp_path / "tiny.toml"
    tiny_config(config)
    run = tmp_path / "run"
    subprocess.run([BIN, "train", "--config", str(config), "--out", str(run), "--quiet"],
                   check=True, capture_output=True)
    lines = [json.loads(line) for line in (run / "metrics.jsonl").read_text().splitlines()]
    assert len(lines) >= 2, lines

    events = EventAccumulator(str(run), size_guidance={"scalars": 0})
    events.Reload()
    tags = set(events.Tags()["scalars"])
    expected = {
        name for name, value in lines[-1].items()
        if isinstance(value, (int, float)) and not isinstance(value, bool)
        and name not in ("epoch", "env_steps", "wall_s")
    }
    expected |= {f"timings/{name}" for name in lines[-1]["timings"]}
    assert {"skill_coverage", "mean_reward", "steps_per_s", "timings/collect"} <= expected
    assert tags == expected, (tags, expected)
    for tag in sorted(expected):
        scalars = events.Scalars(tag)
        if "/" in tag:
            table, name = tag.split("/")
            values = [line[table][name] for line in lines]
        else:
            values = [line[tag] for line in lines]
        assert [s.step for s in scalars] == [line["env_steps"] for line in lines], tag
        assert [s.wall_time for s in scalars] == [line["wall_s"] for line in lines], tag
        for s, v in zip(scalars, values):
            # Stored as float32.
            assert math.isclose(s.value, v, rel_tol=1e-6, abs_tol=1e-30), (tag, s.value, v)
