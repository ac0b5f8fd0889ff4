"""Type stubs of ``seads._seads``, the Rust half of the package (see ``seads.gym`` for the
Gymnasium environments built on it)."""

from typing import Any, Sequence, final

from typing_extensions import Self

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "__version__",
    "env_names",
    "env_titles",
    "game_names",
    "Env",
    "VecEnv",
    "Game",
    "Agent",
    "plan",
    "_panic",
]

_Board = Sequence[int] | npt.ArrayLike
"""A board's values: 1-D (row-major) or square (N x N), whole numbers (ints, bools or integral
floats)."""

def env_names() -> list[str]:
    """The names of the registered environments (``lightsout-cursor``, …)."""

def env_titles() -> dict[str, str]:
    """Each environment's name in CamelCase (``lightsout-cursor`` -> ``LightsOutCursor``)."""

def game_names() -> list[str]:
    """The names of the registered games (``lightsout``, ``tileswap``, ``sliding``)."""

def _panic(message: str) -> None:
    """For the tests only: panics with ``message`` inside a guarded call; it arrives as a
    ``RuntimeError``."""

@final
class Env:
    """One environment in skill mode (episodes end at a move or the step limit, reward 0) or
    task mode (``task=True``: reward 1 when the board is solved)."""

    def __new__(cls, name: str, options: str | None = None, task: bool = False) -> Self:
        """``options`` is the JSON text of the environment's options; unknown ones raise
        ``ValueError``."""
    def spec(self) -> dict[str, Any]:
        """name, game, board_size, obs_dim, action_dim, action_low, action_high,
        manipulator_dim, state_low, state_high, symbolic_len, num_moves, step_limit."""
    def seed(self, seed: int) -> None:
        """Re-seeds the board's and the manipulator's random streams."""
    def reset(self) -> npt.NDArray[np.float32]:
        """Starts an episode; returns the observation."""
    def step(
        self, action: npt.NDArray[np.float32]
    ) -> tuple[npt.NDArray[np.float32], float, bool, bool, int]:
        """(observation, reward, terminated, truncated, move); move -1 for none."""
    def observation(self) -> npt.NDArray[np.float32]:
        """[manipulator state, board bits, remaining time]."""
    def board(self) -> npt.NDArray[np.uint8]:
        """The board's values, row-major."""
    def set_state(self, state: npt.NDArray[np.float32]) -> None:
        """Puts the environment into an episode file's ``initial_obs`` (skill mode only)."""
    def depth(self) -> int | None:
        """The task's solution depth S (``None`` in skill mode)."""
    def render(self, size: int = 256) -> npt.NDArray[np.uint8]:
        """A top view, ``size`` x ``size`` x 3 RGB."""

@final
class VecEnv:
    """``num_envs`` environments stepped in parallel, writing into the caller's arrays."""

    def __new__(
        cls,
        name: str,
        num_envs: int,
        options: str | None = None,
        task: bool = False,
        autoreset: str = "next_step",
    ) -> Self:
        """``autoreset``: ``next_step``, ``same_step`` or ``disabled``; ``MemoryError`` if the
        environments do not fit the memory the process may use."""
    def __len__(self) -> int: ...
    @property
    def chunk_size(self) -> int:
        """Environments one parallel piece of work steps."""
    @property
    def board_len(self) -> int:
        """Values of one board."""
    def spec(self) -> dict[str, Any]:
        """As ``Env.spec``."""
    def reset(
        self,
        obs: npt.NDArray[np.float32],
        board: npt.NDArray[np.uint8],
        depth: npt.NDArray[np.int64],
        seeds: Sequence[int] | None = None,
        mask: npt.NDArray[np.bool_] | None = None,
    ) -> None:
        """Seeds environment i with ``seeds[i]`` when given and resets those ``mask`` selects
        (all without one), writing their rows of ``obs``, ``board`` and ``depth``."""
    def step(
        self,
        actions: npt.NDArray[np.float32],
        obs: npt.NDArray[np.float32],
        reward: npt.NDArray[np.float32],
        terminated: npt.NDArray[np.bool_],
        truncated: npt.NDArray[np.bool_],
        game_move: npt.NDArray[np.int64],
        board: npt.NDArray[np.uint8],
        depth: npt.NDArray[np.int64],
        final_obs: npt.NDArray[np.float32],
        final_board: npt.NDArray[np.uint8],
        ended: npt.NDArray[np.bool_],
    ) -> None:
        """Steps every environment, resetting ended ones as the autoreset mode says."""
    def boards(self) -> npt.NDArray[np.uint8]:
        """Every environment's board values, one row each."""
    def render(self, index: int, size: int = 256) -> npt.NDArray[np.uint8]:
        """Environment ``index``'s top view."""

@final
class Game:
    """``Game("lightsout", size=5)``, ``Game("tileswap")`` or ``Game("sliding", 4)`` (a name of
    ``game_names()``); boards are uint8 arrays."""

    def __new__(cls, name: str, size: int | None = None) -> Self: ...
    @property
    def name(self) -> str: ...
    @property
    def size(self) -> int: ...
    @property
    def num_moves(self) -> int: ...
    def goal(self) -> npt.NDArray[np.uint8]:
        """The solved board."""
    def apply(self, board: _Board, move: int) -> npt.NDArray[np.uint8]:
        """The board after ``move``."""
    def is_goal(self, board: _Board) -> bool: ...
    def solve(self, board: _Board) -> list[int]:
        """An optimal move sequence."""
    def depth(self, board: _Board) -> int:
        """The solution depth."""
    def depth_counts(self, max_depth: int | None = None) -> list[int]:
        """_Boards per solution depth 0, 1, …"""
    def split(self, board: _Board) -> str:
        """``"train"`` or ``"test"`` (CRC32 of the board string mod 3)."""
    def boards(self, depth: int, split: str = "test") -> npt.NDArray[np.uint8]:
        """Every board of solution depth ``depth`` in ``split``, one per row."""

def plan(
    game: Game,
    board: _Board,
    goal: _Board | None = None,
    timeout_s: float | None = None,
    max_expanded: int | None = None,
    max_depth: int = 20,
) -> list[int]:
    """Breadth-first search with the true game model: a shortest move sequence."""

@final
class Agent:
    """A trained SEADS agent from its run directory: the skill policy and the forward model,
    evaluated in Rust without libtorch."""

    @staticmethod
    def load(run_dir: str, checkpoint: int | None = None) -> "Agent":
        """The agent of ``run_dir`` at its latest checkpoint or the one of epoch ``checkpoint``;
        ``ValueError`` for a missing or damaged run."""
    @property
    def env(self) -> str:
        """The environment it was trained on."""
    @property
    def epoch(self) -> int:
        """The checkpoint's epoch."""
    @property
    def num_skills(self) -> int:
        """The number of skills K."""
    def act(
        self,
        obs: npt.NDArray[np.float32],
        skill: int | Sequence[int],
        deterministic: bool = True,
        seed: int | None = None,
    ) -> npt.NDArray[np.float32]:
        """Actions for one observation or rows of observations, executing ``skill`` (one, or
        one per row): the deterministic action, or a sample drawn from ``seed``."""
    def successors(self, board: _Board) -> npt.NDArray[np.uint8]:
        """The board the forward model predicts after each skill (K rows)."""
    def plan(
        self,
        board: _Board,
        goal: _Board | None = None,
        max_depth: int = 20,
        max_expanded: int | None = ...,
        search: str = "breadth",
        choice: str = "most-likely",
    ) -> list[int]:
        """The skills of a plan the forward model predicts to reach ``goal`` (the solved board);
        ``ValueError`` if there is none within the limits."""
    def solve(
        self,
        env: Any,
        board: _Board | None = None,
        replan: bool = True,
        max_expanded: int | None = ...,
        search: str = "breadth",
        choice: str = "most-likely",
        render: bool = False,
        size: int = 256,
    ) -> dict[str, Any]:
        """Plans from the environment's board (or ``board``) and executes the skills in ``env``
        (a ``seads`` Gymnasium environment or ``Env`` of the agent's kind, skill mode),
        re-planning after a deviation: solved, skills, moves, path, steps, plans, failure; with
        ``render=True`` also frames (``size`` x ``size`` x 3 RGB, the start and every step)."""
    def clip(self, env: Any, skill: int, size: int = 256) -> dict[str, Any]:
        """Executes ``skill`` once from where ``env`` stands: frames (the start and every step),
        move (-1 for none), steps."""
