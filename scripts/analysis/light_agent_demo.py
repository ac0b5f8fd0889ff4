"""The light agent (seads.Agent, no libtorch) against `seads evaluate` (libtorch) on the demo
agent: every task of the demo's evaluation with re-planning (20 boards per depth 1-5, the
default search limits), replayed in Python, compared task by task (solved, skills executed,
manipulator steps). Usage: python scripts/analysis/light_agent_demo.py runs/demo OUT.json"""

import json
import sys

import seads

run, out = sys.argv[1], sys.argv[2]
agent = seads.Agent.load(run)
rows = [json.loads(line) for line in open(f"{run}/evaluation-replan-tasks.jsonl")]
same, solved_light, solved_torch, differ = 0, 0, 0, []
for task in rows:
    options = {"reset_split": "test", "max_solution_depth": task["depth"], "random_solution_depth": False}
    env = seads.Env(agent.env, json.dumps(options))
    env.seed(task["seed"])
    env.reset()
    result = agent.solve(env)
    equal = (result["solved"], result["skills"], result["steps"]) == (
        task["solved"], task["executed"], sum(task["skill_steps"]) if task["solved"] else result["steps"])
    same += equal
    solved_light += result["solved"]
    solved_torch += task["solved"]
    if not equal:
        differ.append({"depth": task["depth"], "seed": task["seed"], "torch": task["executed"], "light": result["skills"]})
summary = {"run": run, "epoch": agent.epoch, "tasks": len(rows), "same_outcome_and_skills": same,
           "solved_light": solved_light, "solved_libtorch": solved_torch, "differ": differ}
json.dump(summary, open(out, "w"), indent=1)
print(json.dumps({k: v for k, v in summary.items() if k != "differ"}))
