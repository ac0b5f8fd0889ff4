"""SEADS's physically embedded board games for Python.

The environments of the Rust workspace ``seads`` (LightsOut and TileSwap under a 2-D cursor, a
planar Reacher arm or a Kinova Jaco arm) as Gymnasium environments, registered as
``seads/<Name>-v0`` (for example ``gymnasium.make("seads/LightsOutCursor-v0")``), with a vector
environment that steps many of them in parallel in Rust (``gymnasium.make_vec``); the board
games (:class:`Game`) and breadth-first planning with the true game model (:func:`plan`).

Trained SEADS agents are not loaded into Python (that would put a second libtorch beside
PyTorch's in one process): train, evaluate and solve with the ``seads`` command, and read its
run directories and episode files from Python.
"""

import gymnasium

from ._seads import Env, Game, VecEnv, __version__, env_names, plan
from .gym import SeadsEnv, SeadsVectorEnv, gym_id

__all__ = [
    "Env",
    "Game",
    "SeadsEnv",
    "SeadsVectorEnv",
    "VecEnv",
    "__version__",
    "env_names",
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
