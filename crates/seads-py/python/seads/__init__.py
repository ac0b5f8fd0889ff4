"""SEADS's physically embedded board games for Python.

The environments of the Rust workspace ``seads`` (LightsOut, TileSwap and the sliding puzzle under a 2-D cursor, a
planar Reacher arm or a Kinova Jaco arm) as Gymnasium environments, registered as
``seads/<Name>-v0`` (for example ``gymnasium.make("seads/LightsOutCursor-v0")``), with a vector
environment that steps many of them in parallel in Rust (``gymnasium.make_vec``); the board
games (:class:`Game`) and breadth-first planning with the true game model (:func:`plan`); and
trained agents (:class:`Agent`): load a run directory that the ``seads`` command trained, act
with its skills, plan with its forward model and solve boards in an environment. Agents are
evaluated in Rust without libtorch, so they sit safely beside PyTorch in one process.
"""

import gymnasium

from ._seads import Agent, Env, Game, VecEnv, __version__, env_names, game_names, plan
from .gym import SeadsEnv, SeadsVectorEnv, gym_id

__all__ = [
    "Agent",
    "Env",
    "Game",
    "SeadsEnv",
    "SeadsVectorEnv",
    "VecEnv",
    "__version__",
    "env_names",
    "game_names",
    "gym_id",
    "plan",
]

for _name in env_names():
    gymnasium.register(
        id=gym_id(_name),
        entry_point="seads.gym:SeadsEnv",
        vector_entry_point="seads.gym:SeadsVectorEnv",
        kwargs={"env_name": _name},
        disable_env_checker=False,
    )
