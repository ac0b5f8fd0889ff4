"""Speed of the agent without libtorch (seads.Agent) against the `seads` binary (libtorch):
actions per second for batches of 1,024 observations, and the search time of a plan at depth 5,
`Agent.plan` against `seads solve --json`'s `planning_s` on the same boards (breadth-first, the
most likely plan, 2^22 expanded states, one search thread each). Prints JSON.

Usage: python scripts/bench/agent_speed.py RUN SEADS_BINARY [BOARDS]
"""

import json
import subprocess
import sys
import time

import numpy as np

import seads

run, binary = sys.argv[1], sys.argv[2]
boards_n = int(sys.argv[3]) if len(sys.argv) > 3 else 10
agent = seads.Agent.load(run)
env = seads.Env(agent.env)
obs = []
for seed in range(1024):
    env.seed(seed)
    obs.append(env.reset())
obs = np.stack(obs)
skills = np.arange(1024) % agent.num_skills
agent.act(obs, skills.tolist())  # warm up
rounds = 20
start = time.perf_counter()
for _ in range(rounds):
    agent.act(obs, skills.tolist())
act_s = time.perf_counter() - start
game = seads.Game("lightsout")
boards = game.boards(5, "test")[:boards_n]
light, torch = [], []
for board in boards:
    start = time.perf_counter()
    agent.plan(board)
    light.append(time.perf_counter() - start)
    text = ",".join(str(int(v)) for v in board)
    out = subprocess.run([binary, "solve", "--run", run, "--board", text, "--json"],
                         capture_output=True, text=True, check=True)
    torch.append(json.loads(out.stdout)["planning_s"])
result = {
    "run": run,
    "actions_per_s": rounds * len(obs) / act_s,
    "batch": len(obs),
    "plan_depth_5_s": {"agent": float(np.mean(light)), "seads_solve": float(np.mean(torch)),
                       "ratio": float(np.mean(light) / np.mean(torch)), "boards": len(boards)},
}
print(json.dumps(result, indent=1))
