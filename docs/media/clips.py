"""Skills that make a move, filmed from Python (seads.Agent.clip), as a GIF: the first six from
seeds 0, 1, ... of a run's latest checkpoint. python docs/media/clips.py RUN OUT.gif (needs Pillow)."""
import sys
from PIL import Image
import seads

run, out = sys.argv[1], sys.argv[2]
agent = seads.Agent.load(run)
env = seads.SeadsEnv(agent.env)
frames, shown = [], []
for skill in range(agent.num_skills):
    env.reset(seed=skill)
    clip = agent.clip(env, skill, size=256)
    if clip["move"] >= 0:
        frames += clip["frames"] + [clip["frames"][-1]] * 4
        shown.append((skill, clip["move"], clip["steps"]))
    if len(shown) == 6:
        break
images = [Image.fromarray(f) for f in frames]
images[0].save(out, save_all=True, append_images=images[1:], duration=80, loop=0, optimize=True)
print(f"epoch {agent.epoch}: skills (skill, move, steps) {shown}, {len(frames)} frames -> {out}")
