"""Gymnasium wrappers of the Rust environments: :class:`SeadsEnv` and :class:`SeadsVectorEnv`.

Two modes. Skill mode (the default) is what SEADS's skills see: an episode ends with the first
game move (``terminated``) or at the skill's step limit T_max (``truncated``), and the reward is
always 0 (the environments are reward-free; ``info["move"]`` says which move a step made).
Task mode (``task=True``) is the flat baselines' setting: the board has solution depth S (from
``max_solution_depth`` and ``random_solution_depth``), the step that solves it pays 1 and
terminates, and the episode is truncated after T_max·S steps.

Environment options are keyword arguments: ``max_solution_depth``, ``random_solution_depth``,
``reset_split`` ("train" or "test"), ``board_size`` and ``spacing`` (LightsOutCursor),
``step_limit``, and ``manipulator``: a dict of the manipulator's own options (the Jaco's
``physics_substeps``; the Cursor and the Reachers have none).
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import gymnasium
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import _seads

_TITLES: dict[str, str] = _seads.env_titles()


def gym_id(env_name: str) -> str:
    """The Gymnasium id of a Rust environment name: ``lightsout-cursor`` -> ``seads/LightsOutCursor-v0``."""
    try:
        return f"seads/{_TITLES[env_name]}-v0"
    except KeyError:
        raise ValueError(f"unknown environment {env_name!r}; one of {sorted(_TITLES)}") from None


def _options(options: dict[str, Any]) -> str | None:
    return json.dumps(options) if options else None


def _spaces(spec: dict[str, Any]) -> tuple[spaces.Box, spaces.Box]:
    """Observation ``[manipulator state, board bits, remaining time]`` and action spaces."""
    m, obs_dim = spec["manipulator_dim"], spec["obs_dim"]
    low = np.zeros(obs_dim, dtype=np.float32)
    high = np.ones(obs_dim, dtype=np.float32)
    low[:m] = np.asarray(spec["state_low"], dtype=np.float32)
    high[:m] = np.asarray(spec["state_high"], dtype=np.float32)
    observation = spaces.Box(low=low, high=high, dtype=np.float32)
    action = spaces.Box(
        low=np.asarray(spec["action_low"], dtype=np.float32),
        high=np.asarray(spec["action_high"], dtype=np.float32),
        dtype=np.float32,
    )
    return observation, action


def _autoreset_mode(mode: AutoresetMode | str) -> AutoresetMode:
    """Gymnasium's autoreset mode from itself, its value (``"NextStep"``) or its name in any case
    (``"next_step"``)."""
    if isinstance(mode, AutoresetMode):
        return mode
    key = str(mode).replace("_", "").lower()
    for m in AutoresetMode:
        if key in (m.value.lower(), m.name.replace("_", "").lower()):
            return m
    raise ValueError(f"autoreset_mode {mode!r}: one of {[m.value for m in AutoresetMode]}")


def _seed_from(rng: np.random.Generator) -> int:
    return int(rng.integers(0, 2**63))


class SeadsEnv(gymnasium.Env):
    """One environment (see the module's docstring for the modes and options).

    ``info`` holds ``board`` (the board's values, uint8, row-major: LightsOut 0/1 per field,
    TileSwap the tile on each field), ``move`` (the game move a step made, -1 for none) and, in
    task mode, ``depth`` (the board's solution depth S).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, env_name: str, render_mode: str | None = None, task: bool = False, **options: Any):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode {render_mode!r}: only 'rgb_array' is supported")
        self.env_name = env_name
        self.task = task
        self.render_mode = render_mode
        self._options = dict(options)
        self._core = _seads.Env(env_name, _options(options), task)
        self.spec_dict = self._core.spec()
        self.observation_space, self.action_space = _spaces(self.spec_dict)
        self._seeded = False

    def __getstate__(self) -> dict[str, Any]:
        # The Rust environment is rebuilt from its arguments: a pickled environment (sent to a
        # worker process, say) arrives as a new one, to be reset before its first step.
        return {"env_name": self.env_name, "render_mode": self.render_mode, "task": self.task,
                "options": self._options}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(state["env_name"], state["render_mode"], state["task"], **state["options"])

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        if seed is not None:
            self._core.seed(seed)
            self._seeded = True
        elif not self._seeded:
            self._core.seed(_seed_from(self.np_random))
            self._seeded = True
        obs = self._core.reset()
        return obs, self._info(-1)

    def step(self, action):
        action = np.asarray(action, dtype=np.float32)
        if action.shape != self.action_space.shape:
            raise ValueError(
                f"{self.env_name}: an action has shape {self.action_space.shape}, got {action.shape}"
            )
        obs, reward, terminated, truncated, move = self._core.step(np.ascontiguousarray(action))
        return obs, float(reward), terminated, truncated, self._info(move)

    def render(self):
        if self.render_mode == "rgb_array":
            return self._core.render()
        return None

    def board(self) -> np.ndarray:
        """The board's values (see ``info["board"]``)."""
        return self._core.board()

    def set_state(self, initial_obs) -> None:
        """Puts the environment into the state an episode file's ``initial_obs`` describes (the
        manipulator state, then the board's bits; skill mode) and lifts the step limit, as
        ``seads replay`` does: the recorded actions then give the recorded observations. A
        ``ValueError`` for a state of the wrong length or one the manipulator cannot take."""
        self._core.set_state(np.ascontiguousarray(initial_obs, dtype=np.float32).reshape(-1))

    def _info(self, move: int) -> dict[str, Any]:
        info: dict[str, Any] = {"board": self._core.board(), "move": move}
        if self.task:
            info["depth"] = self._core.depth()
        return info


class SeadsVectorEnv(VectorEnv):
    """``num_envs`` environments stepped in parallel in Rust, writing into NumPy arrays.

    ``autoreset_mode`` is one of Gymnasium's (``AutoresetMode`` or its value): ``NEXT_STEP``
    (the default: the step after an episode ended resets that environment and returns its first
    observation with reward 0), ``SAME_STEP`` (the ending step resets at once; ``info`` then holds
    ``final_obs`` and ``final_info``) or ``DISABLED`` (reset ended environments yourself with
    ``reset(options={"reset_mask": mask})``). ``info`` holds ``board`` (each environment's board
    values), ``move`` (each step's game move, -1 for none) and, in task mode, ``depth``, each with
    its ``_``-prefixed mask as Gymnasium's vector environments give them; :meth:`boards` returns
    every board.
    """

    metadata = {"render_modes": ["rgb_array"], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        env_name: str,
        num_envs: int,
        render_mode: str | None = None,
        task: bool = False,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        **options: Any,
    ):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode {render_mode!r}: only 'rgb_array' is supported")
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise ValueError(f"num_envs {num_envs!r}: must be a positive integer")
        mode = _autoreset_mode(autoreset_mode)
        self.env_name = env_name
        self.num_envs = int(num_envs)
        self.render_mode = render_mode
        self.task = task
        self.autoreset_mode = mode
        self.metadata = {**type(self).metadata, "autoreset_mode": mode}
        self._core = _seads.VecEnv(env_name, self.num_envs, _options(options), task, mode.value)
        self.spec_dict = self._core.spec()
        self.single_observation_space, self.single_action_space = _spaces(self.spec_dict)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        n, obs_dim, board_len = self.num_envs, self.spec_dict["obs_dim"], self._core.board_len
        self._obs = np.zeros((n, obs_dim), dtype=np.float32)
        self._reward = np.zeros(n, dtype=np.float32)
        self._terminated = np.zeros(n, dtype=np.bool_)
        self._truncated = np.zeros(n, dtype=np.bool_)
        self._move = np.full(n, -1, dtype=np.int64)
        self._board = np.zeros((n, board_len), dtype=np.uint8)
        self._depth = np.full(n, -1, dtype=np.int64)
        self._final_obs = np.zeros((n, obs_dim), dtype=np.float32)
        self._final_board = np.zeros((n, board_len), dtype=np.uint8)
        self._ended = np.zeros(n, dtype=np.bool_)
        # The mask of an info entry every environment has: shared, so read-only.
        self._every = np.ones(n, dtype=np.bool_)
        self._every.flags.writeable = False
        self._seeded = False
        self._started = False
        self._closed = False

    def reset(self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None):
        self._check_open()
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if options:
            raise ValueError(f"reset options {sorted(options)}: only 'reset_mask' is known")
        if mask is not None:
            mask = np.asarray(mask)
            if mask.dtype != np.bool_ or mask.shape != (self.num_envs,):
                raise ValueError(
                    f"reset_mask: a bool array of shape ({self.num_envs},), got {mask.dtype} {mask.shape}"
                )
            if not self._started and not mask.all():
                raise ValueError("reset_mask: the first reset resets every environment")
            mask = np.ascontiguousarray(mask)
        if isinstance(seed, (list, tuple)):
            if len(seed) != self.num_envs:
                raise ValueError(f"{len(seed)} seeds for {self.num_envs} environments")
            super().reset(seed=None)
            seeds = [int(s) for s in seed]
        else:
            super().reset(seed=seed)
            if seed is not None:
                seeds = [int(seed) + i for i in range(self.num_envs)]
            elif not self._seeded:
                seeds = [_seed_from(self.np_random) for _ in range(self.num_envs)]
            else:
                seeds = None
        self._seeded = True
        self._core.reset(self._obs, self._board, self._depth, seeds, mask)
        self._started = True
        reset = self._every if mask is None else mask.copy()
        self._move[reset] = -1
        return self._obs.copy(), self._info(reset)

    def step(self, actions):
        self._check_open()
        if not self._started:
            raise gymnasium.error.ResetNeeded("reset the vector environment before its first step")
        actions = np.ascontiguousarray(actions, dtype=np.float32)
        if actions.shape != self.action_space.shape:
            raise ValueError(
                f"{self.env_name}: actions have shape {self.action_space.shape}, got {actions.shape}"
            )
        same_step = self.autoreset_mode == AutoresetMode.SAME_STEP
        depth_before = self._depth.copy() if same_step and self.task else None
        self._core.step(
            actions, self._obs, self._reward, self._terminated, self._truncated, self._move,
            self._board, self._depth, self._final_obs, self._final_board, self._ended,
        )
        info = self._info(self._every)
        info["move"], info["_move"] = self._move.copy(), self._every
        if same_step and self._ended.any():
            ended = self._ended.copy()
            final_obs = np.empty(self.num_envs, dtype=object)
            for i in np.flatnonzero(ended):
                final_obs[i] = self._final_obs[i].copy()
            final_info: dict[str, Any] = {
                "board": self._final_board.copy(), "_board": ended,
                "move": self._move.copy(), "_move": ended,
            }
            if self.task:
                final_info["depth"], final_info["_depth"] = depth_before, ended
            # As Gymnasium's vector environments: the ending step's info is the final one, and
            # the environment's own info is its reset's (no move yet).
            info["move"][ended] = -1
            info.update(final_obs=final_obs, _final_obs=ended, final_info=final_info, _final_info=ended)
        return (
            self._obs.copy(),
            self._reward.copy(),
            self._terminated.copy(),
            self._truncated.copy(),
            info,
        )

    def close_extras(self, **kwargs: Any) -> None:
        self._closed = True

    def _check_open(self) -> None:
        if self._closed:
            raise gymnasium.error.ClosedEnvironmentError(f"{self.env_name}: the vector environment is closed")

    def _info(self, valid: np.ndarray) -> dict[str, Any]:
        info: dict[str, Any] = {"board": self._board.copy(), "_board": valid}
        if self.task:
            info["depth"], info["_depth"] = self._depth.copy(), valid
        return info

    def boards(self) -> np.ndarray:
        """Every environment's board values (num_envs x board values, uint8)."""
        return self._core.boards()

    def render(self):
        """The first environment's top view (RGB), as Gymnasium's vector environments do."""
        if self.render_mode == "rgb_array":
            return self._core.render(0)
        return None
