//! The board games of the games' registry and breadth-first planning with the true game model,
//! NumPy boards in and out: a board is its values, row-major (LightsOut: 0/1 per field;
//! TileSwap and the sliding puzzle: the tile on each field, 0 the sliding puzzle's gap).

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use seads_games::{
    BoardDataset, BoardGame, Enumerable, GameKind, GameSuccessor, SolveControl, Split,
    SymbolicState, enumerate, split_of,
};
use seads_planner::{PlannerConfig, bfs_plan};

use crate::{Values, move_arg, value_error};

/// A board game: `Game("lightsout", 5)`, `Game("tileswap")`, `Game("sliding", 4)`.
#[pyclass(module = "seads._seads", frozen)]
pub struct Game {
    rules: Box<dyn BoardGame>,
}

impl Game {
    fn game(&self) -> &dyn BoardGame {
        self.rules.as_ref()
    }

    /// The game as one whose boards can be listed, or a `ValueError` where they cannot.
    fn enumerable(&self) -> PyResult<&dyn Enumerable> {
        self.rules.enumerable().ok_or_else(|| {
            value_error(format!(
                "{} {}×{} has too many boards to list",
                self.rules.kind(),
                self.rules.size(),
                self.rules.size()
            ))
        })
    }

    /// `values` as a board of this game, or a `ValueError` saying what is wrong.
    fn board(&self, values: Values) -> PyResult<SymbolicState> {
        self.game()
            .board_from_values(&values.0)
            .map_err(value_error)
    }

    fn array<'py>(&self, py: Python<'py>, board: SymbolicState) -> Bound<'py, PyArray1<u8>> {
        PyArray1::from_vec(py, self.game().values(board))
    }
}

/// A split's name as the games crate knows it.
fn parse_split(split: &str) -> PyResult<Split> {
    match split {
        "train" => Ok(Split::Train),
        "test" => Ok(Split::Test),
        other => Err(value_error(format!(
            "split {other:?}: must be \"train\" or \"test\""
        ))),
    }
}

#[pymethods]
impl Game {
    /// `Game(name, size=None)`: a game of `game_names()` — `"lightsout"` (size 5 by default; 3
    /// to 13), `"tileswap"` (size 3) or `"sliding"` (size 3, the 8-puzzle, or 4, the 15-puzzle).
    #[new]
    #[pyo3(signature = (name, size=None))]
    fn new(name: &str, size: Option<usize>) -> PyResult<Self> {
        crate::guarded(|| {
            let kind = GameKind::named(name).map_err(value_error)?;
            let rules = kind
                .build(size.unwrap_or(kind.default_size()))
                .map_err(value_error)?;
            Ok(Self { rules })
        })
    }

    /// The game's name: `"lightsout"`, `"tileswap"` or `"sliding"`.
    #[getter]
    fn name(&self) -> &'static str {
        self.game().kind().name()
    }

    /// Board side length.
    #[getter]
    fn size(&self) -> usize {
        self.game().size()
    }

    /// Number of moves (LightsOut: one per field; TileSwap 3×3: 12 swaps).
    #[getter]
    fn num_moves(&self) -> usize {
        self.game().num_moves()
    }

    /// The solved board.
    fn goal<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u8>> {
        self.array(py, self.game().goal())
    }

    /// The board after `move`.
    fn apply<'py>(
        &self,
        py: Python<'py>,
        board: Values,
        r#move: i64,
    ) -> PyResult<Bound<'py, PyArray1<u8>>> {
        crate::guarded(|| {
            let board = self.board(board)?;
            let mv = move_arg(r#move, self.game().num_moves())?;
            Ok(self.array(py, self.game().apply(board, mv)))
        })
    }

    /// Whether `board` is solved.
    fn is_goal(&self, board: Values) -> PyResult<bool> {
        crate::guarded(|| Ok(self.game().is_goal(self.board(board)?)))
    }

    /// An optimal (shortest) move sequence that solves `board`; a `ValueError` if none does,
    /// or if the solver's search (the 15-puzzle's) stops at its bound of nodes. Ctrl-C stops it.
    fn solve(&self, py: Python<'_>, board: Values) -> PyResult<Vec<usize>> {
        crate::guarded(|| {
            let board = self.board(board)?;
            let game = self.game();
            let control = SolveControl::default();
            let solved =
                crate::interruptible(py, || game.solve_within(board, &control), || control.stop())?;
            match solved {
                Some(moves) => moves.map_err(value_error),
                None => Err(value_error("this game has no solver")),
            }
        })
    }

    /// The board's solution depth (length of an optimal solution); a `ValueError` if it has
    /// none. Ctrl-C stops a search.
    fn depth(&self, py: Python<'_>, board: Values) -> PyResult<usize> {
        crate::guarded(|| Ok(self.solve(py, board)?.len()))
    }

    /// Number of boards per solution depth 0, 1, … (up to `max_depth` when given), by
    /// breadth-first enumeration from the goal.
    #[pyo3(signature = (max_depth=None))]
    fn depth_counts(&self, py: Python<'_>, max_depth: Option<usize>) -> PyResult<Vec<u64>> {
        crate::guarded(|| {
            let game = self.enumerable()?;
            py.detach(|| enumerate(game, max_depth).map(|e| e.depth_counts()))
                .map_err(value_error)
        })
    }

    /// `"train"` or `"test"`: the board's part of the split, by the CRC-32 of its values written
    /// as comma-separated text: `"train"` where it is 0 modulo 3 (a third of the boards), else
    /// `"test"` (two thirds).
    fn split(&self, board: Values) -> PyResult<&'static str> {
        crate::guarded(|| {
            let board = self.board(board)?;
            Ok(split_of(&self.game().values(board)).name())
        })
    }

    /// Every board of solution depth `depth` in `split`, one per row (uint8), in the order of
    /// the breadth-first enumeration.
    #[pyo3(signature = (depth, split="test"))]
    fn boards<'py>(
        &self,
        py: Python<'py>,
        depth: usize,
        split: &str,
    ) -> PyResult<Bound<'py, PyArray2<u8>>> {
        crate::guarded(|| {
            let split = parse_split(split)?;
            if depth > 12 {
                return Err(value_error(format!(
                    "depth {depth}: boards are listed up to depth 12"
                )));
            }
            let game = self.enumerable()?;
            let data = py
                .detach(|| BoardDataset::build(game, depth))
                .map_err(value_error)?;
            let rows: Vec<Vec<u8>> = data
                .boards(depth, split)
                .iter()
                .map(|&b| self.game().values(b))
                .collect();
            if rows.is_empty() {
                return Ok(PyArray2::zeros(
                    py,
                    [0, self.game().size() * self.game().size()],
                    false,
                ));
            }
            PyArray2::from_vec2(py, &rows).map_err(value_error)
        })
    }
}

/// Breadth-first search with the true game model from `board` to the solved board (or to
/// `goal`): the moves of a shortest plan. Stops after `timeout_s` seconds or `max_expanded`
/// expanded states when given; a `ValueError` if it finds no plan.
#[pyfunction]
#[pyo3(signature = (game, board, goal=None, timeout_s=None, max_expanded=None, max_depth=20))]
pub fn plan(
    py: Python<'_>,
    game: &Game,
    board: Values,
    goal: Option<Values>,
    timeout_s: Option<f64>,
    max_expanded: Option<usize>,
    max_depth: usize,
) -> PyResult<Vec<usize>> {
    crate::guarded(|| {
        let start = game.board(board)?;
        let goal = match goal {
            Some(values) => game.board(values)?,
            None => game.game().goal(),
        };
        if start == goal {
            return Ok(Vec::new());
        }
        // Where the game tells at once that no plan exists, the search does not run to its limit.
        if game.game().can_reach(start, goal) == Some(false) {
            return Err(value_error(seads_games::GameError::Unsolvable {
                game: game.game().kind().name(),
            }));
        }
        let config = PlannerConfig {
            max_layers: max_depth,
            timeout_s,
            max_expanded,
            ..PlannerConfig::default()
        };
        let rules = game.game();
        crate::interruptible(
            py,
            || {
                let mut successor = GameSuccessor::new(rules);
                bfs_plan(&mut successor, start, goal, &config)
            },
            || config.interrupt.raise(),
        )?
        .map(|plan| plan.skills)
        .map_err(crate::plan_error)
    })
}
