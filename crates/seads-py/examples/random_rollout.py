"""A random-policy rollout with rendering: steps LightsOutReacher with random actions, prints each
game move, and keeps the frames (saved as frames.npy; `imageio.mimsave("rollout.gif", frames)`
makes a GIF where imageio is installed)."""

import gymnasium
import numpy as np

import seads  # noqa: F401  (registers the environments)


def rollout(steps: int = 200, seed: int = 0) -> np.ndarray:
    env = gymnasium.make("seads/LightsOutReacher-v0", render_mode="rgb_array")
    env.action_space.seed(seed)
    obs, info = env.reset(seed=seed)
    frames = [env.render()]
    for t in range(steps):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        frames.append(env.render())
        if terminated:
            print(f"step {t}: move {info['move']}, board now {''.join(map(str, info['board']))}")
        if terminated or truncated:
            obs, info = env.reset()
    return np.stack(frames)


if __name__ == "__main__":
    frames = rollout()
    np.save("frames.npy", frames)
    print(f"{len(frames)} frames of {frames.shape[1]}×{frames.shape[2]} pixels in frames.npy")
