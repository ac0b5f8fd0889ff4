"""Ctrl-C stops a long computation, in a real Python process (issue 82: the 15-puzzle's solver,
``Agent.solve`` and ``Agent.plan`` held the GIL, or ran to their end, long after SIGINT). The
child starts a search far longer than this test, the test waits until the child is busy inside
it (its CPU time grows), sends SIGINT, and the child must end with ``KeyboardInterrupt``; the
time limit below only keeps a broken build from hanging the suite."""

import os
import pathlib
import signal
import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.without_gymnasium

# The tiles 1-15 reversed, two swapped so that the board can reach the goal (an even number of
# inversions with the gap on the last row): some 60 or more slides from the goal, far beyond
# what IDA* with the Manhattan distance solves in minutes.
FAR = [14, 15, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0]

CHILD = textwrap.dedent(
    f"""
    import signal
    import threading
    import time

    import seads

    # Ctrl-C raises KeyboardInterrupt even where this process was started with SIGINT ignored
    # (a job started in the background by a non-interactive shell inherits that, and Python then
    # installs no handler).
    signal.signal(signal.SIGINT, signal.default_int_handler)

    game = seads.Game("sliding", 4)
    # A thread that ticks while it may: it goes on during the search only if the search has
    # released the GIL.
    ticks = []

    def tick():
        while True:
            ticks.append(1)
            time.sleep(0.001)

    threading.Thread(target=tick, daemon=True).start()
    print("ready", flush=True)
    before = len(ticks)
    try:
        game.solve({FAR})
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted", len(ticks) > before + 10, flush=True)
    """
)


def cpu_seconds(pid):
    """User and system CPU time of process `pid` and its threads (Linux)."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_ctrl_c_stops_the_fifteen_puzzles_solver():
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout.readline().strip() == "ready"
        # Busy inside the search: a second of CPU beyond what it had used when it said so.
        start = cpu_seconds(child.pid)
        while cpu_seconds(child.pid) < start + 1.0:
            assert child.poll() is None, child.stderr.read()
            os.sched_yield()
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=120)
    finally:
        child.kill()
    assert out.split() == ["interrupted", "True"], (out, err)
    assert child.returncode == 0, err


RUN = pathlib.Path(__file__).with_name("data") / "agent-run"

MEMORY_CHILD = textwrap.dedent(
    f"""
    import resource

    import numpy as np
    import seads

    agent = seads.Agent.load({str(RUN)!r})
    obs = np.zeros((10_000_000, 28), dtype=np.float32)  # 1.1 GB
    with open("/proc/self/status") as f:
        size = next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmSize:"))

    def limit(extra_mib):
        resource.setrlimit(resource.RLIMIT_AS, (size + extra_mib * 2**20, resource.RLIM_INFINITY))

    # Room for the actions (80 MB) but not for another copy of the observations: a copy of them
    # was an abort of the interpreter.
    width = len(agent.act(obs[0], 3))
    limit(600)
    print(agent.act(obs, 3).shape == (len(obs), width), flush=True)
    # No room for the actions: a MemoryError, and the interpreter goes on.
    limit(40)
    try:
        agent.act(obs, 3)
    except MemoryError:
        print("memory error", flush=True)
    """
)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_actions_of_many_observations_fit_the_memory_or_raise_memory_error():
    """Issue 82: ``act`` on 10⁷ observations under an address-space limit aborted the
    interpreter (exit 134); it works on chunks of rows, and where even the actions do not fit it
    raises ``MemoryError``."""
    child = subprocess.run(
        [sys.executable, "-c", MEMORY_CHILD], capture_output=True, text=True, timeout=600
    )
    assert child.returncode == 0, child.stderr
    assert child.stdout.split("\n")[:2] == ["True", "memory error"], child.stdout


PLAN_CHILD = textwrap.dedent(
    """
    import resource

    import seads

    game = seads.Game("lightsout", 7)
    board = game.goal()
    for move in range(0, 49, 3):
        board = game.apply(board, move)
    with open("/proc/self/status") as f:
        size = next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmSize:"))
    # Far less than the search's own bound (4 GiB): the machine runs out first.
    resource.setrlimit(resource.RLIMIT_AS, (size + 300 * 2**20, resource.RLIM_INFINITY))
    try:
        seads.plan(game, board, max_expanded=None)
        print("planned", flush=True)
    except MemoryError:
        print("memory error", flush=True)
    """
)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_search_without_memory_raises_memory_error():
    """Issue 82: ``plan(max_expanded=None)`` under an address-space limit aborted the interpreter
    (exit 134). A 7×7 LightsOut board 17 presses from the goal, searched breadth-first with the
    true rules, outgrows 300 MB long before its own bound: a ``MemoryError``."""
    child = subprocess.run(
        [sys.executable, "-c", PLAN_CHILD], capture_output=True, text=True, timeout=600
    )
    assert child.returncode == 0, child.stderr
    assert child.stdout.strip() == "memory error", child.stdout
