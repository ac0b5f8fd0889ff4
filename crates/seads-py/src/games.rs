//! The board games and breadth-first planning with the true game model, NumPy boards in and
//! out: a board is its values, row-major (LightsOut: 0/1 per field; TileSwap: the tile on each
//! field).

use std::sync::OnceLock;

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use seads_games::{
    BoardDataset, BoardGame, DepthTable, Enumerable, GameSuccessor, Gf2Solver, LightsOut, Split,
    SymbolicState, TileSwap, enumerate, split_of,
};
use seads_planner::{PlannerConfig, bfs_plan};

use crate::value_error;

/// One of the two games.
enum Rules {
    LightsOut(LightsOut, Gf2Solver),
    TileSwap(TileSwap),
}

/// A board game: `Game("lightsout", 5)` or `Game("tileswap")`.
#[pyclass(module = "seads._seads", frozen)]
pub struct Game {
    rules: Rules,
    /// TileSwap's depth table, built on first use.
    table: OnceLock<DepthTable>,
}

impl Game {
    fn game(&self) -> &dyn BoardGame {
        match &self.rules {
            Rules::LightsOut(g, _) => g,
            Rules::TileSwap(g) => g,
        }
    }

    fn enumerable(&self) -> &dyn Enumerable {
        match &self.rules {
            Rules::LightsOut(g, _) => g,
            Rules::TileSwap(g) => g,
        }
    }

    /// `values` as a board of this game, or a `ValueError` saying what is wrong.
    fn board(&self, values: Vec<u8>) -> PyResult<SymbolicState> {
        self.game().board_from_values(&values).map_err(value_error)
    }

    fn array<'py>(&self, py: Python<'py>, board: SymbolicState) -> Bound<'py, PyArray1<u8>> {
        PyArray1::from_vec(py, self.game().values(board))
    }

    fn depth_table(&self) -> PyResult<&DepthTable> {
        if let Some(table) = self.table.get() {
            return Ok(table);
        }
        let table = DepthTable::build(self.enumerable()).map_err(value_error)?;
        Ok(self.table.get_or_init(|| table))
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
    /// `Game(name, size=None)`: `"lightsout"` (size 5 by default; 3 to 13) or `"tileswap"`
    /// (size 3).
    #[new]
    #[pyo3(signature = (name, size=None))]
    fn new(name: &str, size: Option<usize>) -> PyResult<Self> {
        let rules = match name {
            "lightsout" => {
                let game = LightsOut::new(size.unwrap_or(5)).map_err(value_error)?;
                let solver = Gf2Solver::new(&game);
                Rules::LightsOut(game, solver)
            }
            "tileswap" => {
                Rules::TileSwap(TileSwap::with_size(size.unwrap_or(3)).map_err(value_error)?)
            }
            other => {
                return Err(value_error(format!(
                    "game {other:?}: must be \"lightsout\" or \"tileswap\""
                )));
            }
        };
        Ok(Self {
            rules,
            table: OnceLock::new(),
        })
    }

    /// `"lightsout"` or `"tileswap"`.
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
        board: Vec<u8>,
        r#move: usize,
    ) -> PyResult<Bound<'py, PyArray1<u8>>> {
        let board = self.board(board)?;
        if r#move >= self.game().num_moves() {
            return Err(value_error(format!(
                "move {}: the game has moves 0 to {}",
                r#move,
                self.game().num_moves() - 1
            )));
        }
        Ok(self.array(py, self.game().apply(board, r#move)))
    }

    /// Whether `board` is solved.
    fn is_goal(&self, board: Vec<u8>) -> PyResult<bool> {
        Ok(self.game().is_goal(self.board(board)?))
    }

    /// An optimal (shortest) move sequence that solves `board`; a `ValueError` if none does.
    fn solve(&self, board: Vec<u8>) -> PyResult<Vec<usize>> {
        let board = self.board(board)?;
        match &self.rules {
            Rules::LightsOut(_, solver) => solver.solve(board).map_err(value_error),
            Rules::TileSwap(game) => self.depth_table()?.solve(game, board).map_err(value_error),
        }
    }

    /// The board's solution depth (length of an optimal solution); a `ValueError` if it has
    /// none.
    fn depth(&self, board: Vec<u8>) -> PyResult<usize> {
        let board = self.board(board)?;
        match &self.rules {
            Rules::LightsOut(_, solver) => solver.depth(board).map_err(value_error),
            Rules::TileSwap(game) => self
                .depth_table()?
                .depth(game, board)
                .map(usize::from)
                .ok_or_else(|| value_error("the board cannot be solved")),
        }
    }

    /// Number of boards per solution depth 0, 1, … (up to `max_depth` when given), by
    /// breadth-first enumeration from the goal.
    #[pyo3(signature = (max_depth=None))]
    fn depth_counts(&self, py: Python<'_>, max_depth: Option<usize>) -> PyResult<Vec<u64>> {
        let game = self.enumerable();
        py.detach(|| enumerate(game, max_depth).map(|e| e.depth_counts()))
            .map_err(value_error)
    }

    /// `"train"` or `"test"`: the board's part of the split, by the CRC-32 of its values written
    /// as comma-separated text: `"train"` where it is 0 modulo 3 (a third of the boards), else
    /// `"test"` (two thirds).
    fn split(&self, board: Vec<u8>) -> PyResult<&'static str> {
        let board = self.board(board)?;
        Ok(split_of(&self.game().values(board)).name())
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
        let split = parse_split(split)?;
        if depth > 12 {
            return Err(value_error(format!(
                "depth {depth}: boards are listed up to depth 12"
            )));
        }
        let game = self.enumerable();
        let data = py
            .detach(|| BoardDataset::build(game, depth))
            .map_err(value_error)?;
        let rows: Vec<Vec<u8>> = data
            .boards(depth, split)
            .iter()
            .map(|&b| self.game().values(b))
            .collect();
        if rows.is_empty() {
            return Ok(PyArray2::zeros(py, [0, self.game().symbolic_len()], false));
        }
        PyArray2::from_vec2(py, &rows).map_err(value_error)
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
    board: Vec<u8>,
    goal: Option<Vec<u8>>,
    timeout_s: Option<f64>,
    max_expanded: Option<usize>,
    max_depth: usize,
) -> PyResult<Vec<usize>> {
    let start = game.board(board)?;
    let goal = match goal {
        Some(values) => game.board(values)?,
        None => game.game().goal(),
    };
    if start == goal {
        return Ok(Vec::new());
    }
    // LightsOut's moves flip fields, so a plan to `goal` exists iff `start ^ goal` can be
    // solved: the GF(2) solver says at once where the search would run to its limit.
    if let Rules::LightsOut(_, solver) = &game.rules {
        solver.depth(start ^ goal).map_err(value_error)?;
    }
    let config = PlannerConfig {
        max_layers: max_depth,
        timeout_s,
        max_expanded,
        ..PlannerConfig::default()
    };
    let rules = game.game();
    py.detach(|| {
        let mut successor = GameSuccessor::new(rules);
        bfs_plan(&mut successor, start, goal, &config)
    })
    .map(|plan| plan.skills)
    .map_err(value_error)
}
