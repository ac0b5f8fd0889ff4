"""Summed environment steps per second from Python with random actions.

``python -m seads.bench`` steps 1,024 LightsOutCursor and 1,024 LightsOutReacher environments
through :class:`seads.SeadsVectorEnv` (stepped in parallel in Rust), then the same loop over
Gymnasium's ``SyncVectorEnv`` of single :class:`seads.SeadsEnv` environments (a Python loop over
environments) for the ratio, and, where ``dm_control`` is installed, the authors' kind of
environment (a dm_control suite task stepped one at a time) for scale. Random actions are drawn
up front (64 batches, used in turn), so that the clock measures stepping, not the generator.
Build the package in release mode (``pip install crates/seads-py``) before measuring.
"""

from __future__ import annotations

import argparse
import json
import os
import time

import gymnasium
import numpy as np

from .gym import SeadsEnv, SeadsVectorEnv


def _actions(space, batches: int, rng: np.random.Generator) -> list[np.ndarray]:
    low, high = space.low, space.high
    return [rng.uniform(low, high).astype(np.float32) for _ in range(batches)]


def _rate(env, num_envs: int, batches: int, seconds: float) -> float:
    """Summed steps per second of a vector environment under random actions."""
    env.reset(seed=0)
    actions = _actions(env.action_space, batches, np.random.default_rng(0))
    steps, start = 0, time.perf_counter()
    while (elapsed := time.perf_counter() - start) < seconds:
        for a in actions:
            env.step(a)
        steps += len(actions) * num_envs
    return steps / elapsed


def vector(name: str, num_envs: int, seconds: float) -> float:
    """Steps per second of ``num_envs`` environments in one :class:`SeadsVectorEnv`."""
    return _rate(SeadsVectorEnv(name, num_envs), num_envs, 64, seconds)


def sync_vector(name: str, num_envs: int, seconds: float) -> float:
    """Steps per second of Gymnasium's ``SyncVectorEnv`` over single environments."""
    env = gymnasium.vector.SyncVectorEnv([lambda: SeadsEnv(name) for _ in range(num_envs)])
    return _rate(env, num_envs, 8, seconds)


def dm_control(seconds: float) -> float | None:
    """Steps per second of dm_control's suite reacher (one environment), if installed."""
    try:
        from dm_control import suite
    except ImportError:
        return None
    env = suite.load("reacher", "easy", task_kwargs={"random": 0})
    spec = env.action_spec()
    rng = np.random.default_rng(0)
    env.reset()
    steps, start = 0, time.perf_counter()
    while (elapsed := time.perf_counter() - start) < seconds:
        step = env.step(rng.uniform(spec.minimum, spec.maximum))
        if step.last():
            env.reset()
        steps += 1
    return steps / elapsed


def processor() -> str:
    """The processor's model name (Linux), else what the platform module says."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    import platform

    return platform.processor() or "unknown"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m seads.bench", description=__doc__.split("\n\n")[0])
    parser.add_argument("--num-envs", type=int, default=1024, help="environments per vector (1024)")
    parser.add_argument("--seconds", type=float, default=3.0, help="measuring time per row (3 s)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    rows = []
    for name in ["lightsout-cursor", "lightsout-reacher"]:
        rows.append((name, "SeadsVectorEnv (Rust, parallel)", vector(name, args.num_envs, args.seconds)))
        rows.append((name, "SyncVectorEnv of SeadsEnv (Python loop)", sync_vector(name, args.num_envs, args.seconds)))
    dm = dm_control(args.seconds)
    if dm is not None:
        rows.append(("dm_control reacher-easy", "one environment", dm))
    if args.json:
        print(json.dumps({"processor": processor(), "cores": os.cpu_count(), "num_envs": args.num_envs,
                          "rows": [{"env": e, "how": h, "steps_per_s": s} for e, h, s in rows]}))
        return
    print(f"{args.num_envs} environments per vector, {os.cpu_count()} cores ({processor()})")
    for env, how, rate in rows:
        print(f"{env:24} {how:40} {rate:14,.0f} steps/s")


if __name__ == "__main__":
    try:
        main()
    except BrokenPipeError:  # a closed pipe (`| head`) ends the output quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
