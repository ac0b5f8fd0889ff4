//! Board games of SEADS: LightsOut N×N and TileSwap 3×3 (SPEC §1).
//!
//! A board *is* its symbolic state z ([`SymbolicState`], bit-packed), so the one game trait,
//! [`BoardGame`], is object safe and every later stage (environments, forward model, planner)
//! speaks the same currency. On top of the rules this crate holds the breadth-first enumeration of
//! all boards by solution depth ([`enumerate`]), an optimal LightsOut solver over GF(2)
//! ([`Gf2Solver`]), the CRC32 train/test split ([`split_of`]) and board sampling by depth and split
//! ([`BoardDataset`]).
//!
//! Architecture invariant: this crate knows nothing of physics, tensors or IO; its functions are
//! pure and only parsing user input returns `Result`.
//!
//! # Example: parse a board and solve it
//!
//! ```
//! use seads_games::{BoardGame, DepthTable, Gf2Solver, LightsOut, TileSwap};
//!
//! // LightsOut 5×5: a board is 25 values, row-major; pressing field 0 toggles it and its
//! // right and lower neighbours.
//! let game = LightsOut::new(5)?;
//! let board = game.parse("1,1,0,0,0, 1,0,0,0,0, 0,0,0,0,0, 0,0,0,0,0, 0,0,0,0,0")?;
//! let moves = Gf2Solver::new(&game).solve(board)?; // an optimal move sequence
//! assert_eq!(moves, vec![0]);
//! assert!(game.is_goal(game.apply_all(board, &moves)));
//!
//! // TileSwap 3×3: a permutation of the tiles; 12 swap moves; solved by the depth table.
//! let tileswap = TileSwap::new();
//! let board = tileswap.parse("1,0,2,3,4,5,6,7,8")?;
//! let table = DepthTable::build(&tileswap)?;
//! assert_eq!(table.depth(&tileswap, board), Some(1));
//! let moves = table.solve(&tileswap, board)?;
//! assert!(tileswap.is_goal(tileswap.apply_all(board, &moves)));
//! # Ok::<(), seads_games::GameError>(())
//! ```
//!
//! The examples (`cargo run -p seads-games --example depths`, `--example solve`) print the
//! boards per solution depth and solve a board given on the command line.

mod bits;
mod dataset;
mod enumerate;
mod gf2;
mod lightsout;
mod reports;
mod split;
mod successor;
pub mod tables;
mod tileswap;

pub use bits::SymbolicState;
pub use dataset::{
    BoardDataset, FEW_MOVE_SETS, MAX_DRAWS, action_sampling_boards, sample_by_action_sampling,
};
pub use enumerate::{DepthTable, Enumerable, Enumeration, enumerate};
pub use gf2::Gf2Solver;
pub use lightsout::LightsOut;
pub use reports::{DepthsReport, SolveReport, SplitReport};
pub use split::{Split, board_string, split_of};
pub use successor::{GameSuccessor, Successor};
pub use tileswap::TileSwap;

/// Identifier of a game move (SPEC §1: LightsOut `row·N + col`, TileSwap ids 0..11).
pub type MoveId = usize;

/// Errors for boards and games built from user input.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GameError {
    /// The board string or value list has the wrong number of fields.
    #[error("a {game} board has {expected} fields, got {found}")]
    WrongLength {
        /// Game name.
        game: &'static str,
        /// Number of fields the game expects.
        expected: usize,
        /// Number of fields given.
        found: usize,
    },
    /// A field holds a symbol the game does not allow.
    #[error("field {index} of the {game} board: {symbol:?} is not one of {allowed}")]
    BadSymbol {
        /// Game name.
        game: &'static str,
        /// 0-based field index (row-major).
        index: usize,
        /// The offending text.
        symbol: String,
        /// The allowed values, in words.
        allowed: &'static str,
    },
    /// A TileSwap board that is not a permutation of the tiles 0..8.
    #[error(
        "a tileswap board must hold each tile 0..8 exactly once; tile {tile} appears {count} times"
    )]
    NotPermutation {
        /// A tile id that is missing or repeated.
        tile: u8,
        /// How often it appears.
        count: usize,
    },
    /// A symbolic state that encodes no board of the game.
    #[error("the symbolic state is not a valid {game} board")]
    InvalidSymbolic {
        /// Game name.
        game: &'static str,
    },
    /// The board cannot be brought to the goal by any sequence of moves.
    #[error("this {game} board cannot be solved: no sequence of moves reaches the goal")]
    Unsolvable {
        /// Game name.
        game: &'static str,
    },
    /// A board size the game does not support.
    #[error("{game} does not support size {size} (allowed: {allowed})")]
    UnsupportedSize {
        /// Game name.
        game: &'static str,
        /// The requested size.
        size: usize,
        /// The allowed sizes, in words.
        allowed: &'static str,
    },
    /// Enumerating every board is infeasible for this game.
    #[error(
        "enumerating every {game} board of size {size} is infeasible ({space} states); only LightsOut up to 5×5 and TileSwap 3×3 are enumerated"
    )]
    TooLargeToEnumerate {
        /// Game name.
        game: &'static str,
        /// Board size.
        size: usize,
        /// Size of the state space, in words.
        space: String,
    },
}

/// Which game, as named on the command line and in configs.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum GameKind {
    /// LightsOut: press a field to toggle it and its four neighbours.
    LightsOut,
    /// TileSwap: swap two edge-adjacent tiles.
    TileSwap,
}

impl GameKind {
    /// The lower-case name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            GameKind::LightsOut => "lightsout",
            GameKind::TileSwap => "tileswap",
        }
    }

    /// The default board size (5 for LightsOut, 3 for TileSwap; SPEC §1).
    pub fn default_size(self) -> usize {
        match self {
            GameKind::LightsOut => 5,
            GameKind::TileSwap => 3,
        }
    }

    /// Builds the game of this kind and size.
    pub fn build(self, size: usize) -> Result<Box<dyn BoardGame>, GameError> {
        Ok(match self {
            GameKind::LightsOut => Box::new(LightsOut::new(size)?),
            GameKind::TileSwap => Box::new(TileSwap::with_size(size)?),
        })
    }
}

impl std::fmt::Display for GameKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for GameKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "lightsout" => Ok(GameKind::LightsOut),
            "tileswap" => Ok(GameKind::TileSwap),
            other => Err(format!(
                "unknown game {other:?} (valid: lightsout, tileswap)"
            )),
        }
    }
}

/// A board game whose boards are identified with their symbolic states z (SPEC §1).
///
/// Moves are numbered `0..num_moves()`; `apply` of an invalid move id panics (move ids come from
/// code, not from users). Every method but the parsing ones is pure and infallible.
pub trait BoardGame: Send + Sync {
    /// Which game this is.
    fn kind(&self) -> GameKind;
    /// Board side length N.
    fn size(&self) -> usize;
    /// Number of moves (K of the ground-truth game).
    fn num_moves(&self) -> usize;
    /// Length D of the symbolic state.
    fn symbolic_len(&self) -> usize;
    /// The goal board.
    fn goal(&self) -> SymbolicState;
    /// The board after move `mv`.
    fn apply(&self, board: SymbolicState, mv: MoveId) -> SymbolicState;
    /// The canonical field values, row-major (LightsOut 0/1, TileSwap the tile id of each cell).
    fn values(&self, board: SymbolicState) -> Vec<u8>;
    /// [`BoardGame::values`] written into `out` (one value per field), without allocating where
    /// the game says how.
    fn write_values(&self, board: SymbolicState, out: &mut [u8]) {
        out.copy_from_slice(&self.values(board));
    }
    /// The board with these canonical field values.
    fn board_from_values(&self, values: &[u8]) -> Result<SymbolicState, GameError>;
    /// Whether `z` encodes a board of this game (TileSwap: a one-hot permutation matrix).
    fn is_valid(&self, z: SymbolicState) -> bool;

    /// A shortest move sequence from `board` to the goal by the game's own solver, `None` where
    /// the game has none (then only a search finds one). An error if `board` cannot reach the
    /// goal.
    fn solve(&self, _board: SymbolicState) -> Option<Result<Vec<MoveId>, GameError>> {
        None
    }

    /// The solution depth of `board` (the length of a shortest solution) by the game's own
    /// solver, `None` where the game has none.
    fn solution_depth(&self, board: SymbolicState) -> Option<Result<usize, GameError>> {
        self.solve(board).map(|moves| moves.map(|m| m.len()))
    }

    /// Whether `board` is the goal.
    fn is_goal(&self, board: SymbolicState) -> bool {
        board == self.goal()
    }

    /// The board after applying `moves` in order.
    fn apply_all(&self, board: SymbolicState, moves: &[MoveId]) -> SymbolicState {
        moves.iter().fold(board, |b, &m| self.apply(b, m))
    }

    /// Canonical board string: the values joined by "," without spaces (SPEC §1.4).
    fn format(&self, board: SymbolicState) -> String {
        board_string(&self.values(board))
    }

    /// Parses a board string of comma-separated field values (spaces around values are allowed).
    fn parse(&self, text: &str) -> Result<SymbolicState, GameError> {
        let game = self.kind().name();
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        let expected = self.size() * self.size();
        if fields.len() != expected {
            return Err(GameError::WrongLength {
                game,
                expected,
                found: fields.len(),
            });
        }
        let values = fields
            .iter()
            .enumerate()
            .map(|(index, f)| {
                f.parse::<u8>().map_err(|_| GameError::BadSymbol {
                    game,
                    index,
                    symbol: (*f).to_owned(),
                    allowed: match self.kind() {
                        GameKind::LightsOut => "0 or 1",
                        GameKind::TileSwap => "a tile id 0..8",
                    },
                })
            })
            .collect::<Result<Vec<u8>, _>>()?;
        self.board_from_values(&values)
    }
}
