"""Type stubs of ``seads._seads``, the Rust half of the package (see ``seads.gym`` for the
Gymnasium environments built on it)."""

from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

__version__: str

def env_names() -> list[str]:
    """The names of the registered environments (``lightsout-cursor``, …)."""

class Env:
    """One environment in skill mode (episodes end at a move or the step limit, reward 0) or
    task mode (``task=True``: reward 1 when the board is solved)."""

    def __init__(self, name: str, options: str | None = None, task: bool = False) -> None:
        """``options`` is the JSON text of the environment's options; unknown ones raise
        ``ValueError``."""
    def spec(self) -> dict[str, Any]:
        """name, game, board_size, obs_dim, action_dim, action_low, action_high,
        manipulator_dim, symbolic_len, num_moves, step_limit."""
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

class VecEnv:
    """``num_envs`` environments stepped in parallel, writing into the caller's arrays."""

    def __init__(
        self, name: str, num_envs: int, options: str | None = None, task: bool = False
    ) -> None: ...
    def __len__(self) -> int: ...
    def spec(self) -> dict[str, Any]:
        """As ``Env.spec``."""
    def reset(self, obs: npt.NDArray[np.float32], seeds: Sequence[int] | None = None) -> None:
        """Seeds environment i with ``seeds[i]`` when given, resets all, writes ``obs``."""
    def step(
        self,
        actions: npt.NDArray[np.float32],
        obs: npt.NDArray[np.float32],
        reward: npt.NDArray[np.float32],
        terminated: npt.NDArray[np.bool_],
        truncated: npt.NDArray[np.bool_],
        game_move: npt.NDArray[np.int64],
    ) -> None:
        """Steps every environment (resetting those whose episode ended on the last step)."""
    def boards(self) -> npt.NDArray[np.uint8]:
        """Every environment's board values, one row each."""
    def render(self, index: int, size: int = 256) -> npt.NDArray[np.uint8]:
        """Environment ``index``'s top view."""

class Game:
    """``Game("lightsout", size=5)`` or ``Game("tileswap")``; boards are uint8 arrays."""

    def __init__(self, name: str, size: int | None = None) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def size(self) -> int: ...
    @property
    def num_moves(self) -> int: ...
    def goal(self) -> npt.NDArray[np.uint8]:
        """The solved board."""
    def apply(self, board: Sequence[int] | npt.NDArray[np.uint8], move: int) -> npt.NDArray[np.uint8]:
        """The board after ``move``."""
    def is_goal(self, board: Sequence[int] | npt.NDArray[np.uint8]) -> bool: ...
    def solve(self, board: Sequence[int] | npt.NDArray[np.uint8]) -> list[int]:
        """An optimal move sequence."""
    def depth(self, board: Sequence[int] | npt.NDArray[np.uint8]) -> int:
        """The solution depth."""
    def depth_counts(self, max_depth: int | None = None) -> list[int]:
        """Boards per solution depth 0, 1, …"""
    def split(self, board: Sequence[int] | npt.NDArray[np.uint8]) -> str:
        """``"train"`` or ``"test"`` (CRC32 of the board string mod 3)."""
    def boards(self, depth: int, split: str = "test") -> npt.NDArray[np.uint8]:
        """Every board of solution depth ``depth`` in ``split``, one per row."""

def plan(
    game: Game,
    board: Sequence[int] | npt.NDArray[np.uint8],
    goal: Sequence[int] | npt.NDArray[np.uint8] | None = None,
    timeout_s: float | None = None,
    max_expanded: int | None = None,
    max_depth: int = 20,
) -> list[int]:
    """Breadth-first search with the true game model: a shortest move sequence."""

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
    def successors(self, board: npt.NDArray[np.uint8] | Sequence[int]) -> npt.NDArray[np.uint8]:
        """The board the forward model predicts after each skill (K rows)."""
    def plan(
        self,
        board: npt.NDArray[np.uint8] | Sequence[int],
        goal: npt.NDArray[np.uint8] | Sequence[int] | None = None,
        max_depth: int = 20,
        max_expanded: int | None = 4194304,
        search: str = "breadth",
        choice: str = "most-likely",
    ) -> list[int]:
        """The skills of a plan the forward model predicts to reach ``goal`` (the solved board);
        ``ValueError`` if there is none within the limits."""
    def solve(
        self,
        env: Any,
        board: npt.NDArray[np.uint8] | Sequence[int] | None = None,
        replan: bool = True,
        max_expanded: int | None = 4194304,
        search: str = "breadth",
        choice: str = "most-likely",
    ) -> dict[str, Any]:
        """Plans from the environment's board (or ``board``) and executes the skills in ``env``
        (a ``seads`` Gymnasium environment or ``Env`` of the agent's kind, skill mode),
        re-planning after a deviation: solved, skills, moves, path, steps, plans, failure."""
