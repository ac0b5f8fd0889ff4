//! Board games of SEADS: LightsOut N×N, TileSwap 3×3 (SPEC §1) and the sliding-tile puzzle
//! (the 8- and 15-puzzle), listed by name in one registry ([`GameKind`]).
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
mod perm;
mod registry;
mod reports;
mod sliding;
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
pub use registry::{GameEntry, GameKind};
pub use reports::{DepthsReport, SolveReport, SplitReport};
pub use sliding::SlidingPuzzle;
pub use split::{Split, board_string, split_of};
pub use successor::{GameSuccessor, Successor};
pub use tileswap::TileSwap;

/// Every game, in listing order: the one place that names them (each game's file holds its
/// [`GameEntry`]).
static GAMES: &[&GameEntry] = &[&lightsout::ENTRY, &tileswap::ENTRY, &sliding::ENTRY];

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
    /// A board of tiles that is not a permutation of its tiles.
    #[error(
        "a {game} board must hold each tile 0..{last} exactly once; tile {tile} appears {count} times"
    )]
    NotPermutation {
        /// Game name.
        game: &'static str,
        /// The largest tile id.
        last: u8,
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
        "enumerating every {game} board of size {size} is infeasible (more than 2^32 boards); LightsOut up to 5×5, TileSwap 3×3 and the 8-puzzle are enumerated"
    )]
    TooLargeToEnumerate {
        /// Game name.
        game: &'static str,
        /// Board size.
        size: usize,
    },
    /// A solver that stopped at its bound of search nodes without a solution.
    #[error(
        "the {game} solver stopped after {nodes} search nodes without a solution (a board this \
         far from the goal needs a larger bound)"
    )]
    SearchLimit {
        /// Game name.
        game: &'static str,
        /// The nodes it expanded.
        nodes: u64,
    },
    /// A solver stopped by another thread (Ctrl-C in Python).
    #[error("the {game} solver was interrupted")]
    Interrupted {
        /// Game name.
        game: &'static str,
    },
    /// A solution depth beyond the farthest board of the game.
    #[error(
        "depth {depth} is beyond every {game} board of size {size}: the farthest is {max} moves from the goal"
    )]
    DepthBeyondGame {
        /// Game name.
        game: &'static str,
        /// Board size.
        size: usize,
        /// The depth asked for.
        depth: usize,
        /// The largest solution depth of any board.
        max: usize,
    },
    /// No registered game has this name.
    #[error("unknown game {name:?} (valid: {valid})")]
    UnknownGame {
        /// The name given.
        name: String,
        /// The registered names.
        valid: String,
    },
}

/// Search nodes a game's searching solver (the 15-puzzle's IDA*) may expand to solve one board
/// by default ([`BoardGame::solve`]; [`BoardGame::solve_within`] sets another bound): tens of
/// seconds, enough for 15-puzzle boards up to about 60 moves; the hardest take 80 moves and far
/// more nodes.
pub const SOLVE_NODES: u64 = 4_000_000_000;

/// The bound and the live state of a game's searching solver (the 15-puzzle's IDA*,
/// [`BoardGame::solve_within`]): how many search nodes it may expand, a flag another thread
/// raises to stop it (Ctrl-C), and the nodes it has expanded so far, which it updates as it goes
/// so that another thread can show progress.
#[derive(Debug)]
pub struct SolveControl {
    max_nodes: u64,
    stop: std::sync::atomic::AtomicBool,
    expanded: std::sync::atomic::AtomicU64,
}

impl SolveControl {
    /// A search bounded by `max_nodes` nodes, not stopped, nothing expanded.
    pub fn new(max_nodes: u64) -> Self {
        Self {
            max_nodes,
            stop: std::sync::atomic::AtomicBool::new(false),
            expanded: std::sync::atomic::AtomicU64::new(0),
        }
    }

    /// The bound of search nodes.
    pub fn max_nodes(&self) -> u64 {
        self.max_nodes
    }

    /// Stops the search at its next look (from any thread).
    pub fn stop(&self) {
        self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
    }

    /// Whether the search was told to stop.
    pub fn is_stopped(&self) -> bool {
        self.stop.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The nodes the search has expanded, as of its last look (it looks every few tens of
    /// thousands of nodes, and when it ends).
    pub fn expanded(&self) -> u64 {
        self.expanded.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Records how many nodes the search has expanded.
    pub(crate) fn set_expanded(&self, nodes: u64) {
        self.expanded
            .store(nodes, std::sync::atomic::Ordering::Relaxed);
    }
}

impl Default for SolveControl {
    /// Bounded by [`SOLVE_NODES`].
    fn default() -> Self {
        Self::new(SOLVE_NODES)
    }
}

/// Where on the board a move is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoveSite {
    /// By pushing one field (row-major index): LightsOut's and the sliding puzzle's moves.
    Field(usize),
    /// By pushing the edge between two edge-adjacent fields (row-major indices): TileSwap's
    /// swaps.
    Edge(usize, usize),
}

/// How a field's value is shown.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldMark {
    /// A light, on or off (LightsOut).
    Light(bool),
    /// A label (a tile's number).
    Label(String),
    /// Nothing (the sliding puzzle's gap).
    Blank,
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
    /// The field values a board may hold, in words (for error messages: "0 or 1").
    fn allowed_values(&self) -> &'static str;
    /// Where on the board move `mv` is made.
    fn move_site(&self, mv: MoveId) -> MoveSite;
    /// How a field holding `value` is shown.
    fn field_mark(&self, value: u8) -> FieldMark;
    /// Move `mv` in words, for listings ("12 (press row 2 col 2)").
    fn describe_move(&self, mv: MoveId) -> String {
        match self.move_site(mv) {
            MoveSite::Field(f) => format!(
                "{mv} (push row {} col {})",
                f / self.size(),
                f % self.size()
            ),
            MoveSite::Edge(p, q) => {
                let n = self.size();
                format!(
                    "{mv} (between ({},{}) and ({},{}))",
                    p / n,
                    p % n,
                    q / n,
                    q % n
                )
            }
        }
    }
    /// A uniformly random valid board ([`BoardGame::is_valid`]), reachable from the goal or not.
    fn random_board(&self, rng: &mut dyn rand::Rng) -> SymbolicState;

    /// The game as one whose boards can be listed densely, where enumerating every board is
    /// feasible (LightsOut up to 5×5, TileSwap, the 8-puzzle); `None` otherwise.
    fn enumerable(&self) -> Option<&dyn Enumerable> {
        None
    }

    /// A board about `depth` moves from the goal that lies in `split`, for a game too large to
    /// enumerate; `None` where `split` holds none. By default `depth` distinct random moves from
    /// the goal, redrawn until the split matches (the reference's action sampling: the true depth
    /// may be smaller); a game with a solver may draw boards of exactly that depth.
    fn sample_at_depth(
        &self,
        depth: usize,
        split: Split,
        rng: &mut dyn rand::Rng,
    ) -> Option<SymbolicState> {
        dataset::sample_by_action_sampling(self, depth, split, rng)
    }

    /// Whether [`BoardGame::sample_at_depth`] can draw no board of `depth` in `split` (a depth
    /// that few move sets reach may have none there), said without drawing.
    fn lacks_boards(&self, depth: usize, split: Split) -> bool {
        dataset::action_sampling_boards(self, depth, split).is_some_and(|b| b.is_empty())
    }

    /// Whether a sequence of moves takes `from` to `to`, where the game can tell at once;
    /// `None` where only a search finds out. By default through the game's solver when `to` is
    /// the goal.
    fn can_reach(&self, from: SymbolicState, to: SymbolicState) -> Option<bool> {
        if to == self.goal() {
            self.solution_depth(from).map(|d| d.is_ok())
        } else {
            None
        }
    }

    /// Whether move `mv` changes `board` (a sliding puzzle's push of a tile away from the gap
    /// does not).
    fn changes(&self, board: SymbolicState, mv: MoveId) -> bool {
        self.apply(board, mv) != board
    }

    /// A shortest move sequence from `board` to the goal by the game's own solver, `None` where
    /// the game has none (then only a search finds one). An error if `board` cannot reach the
    /// goal.
    fn solve(&self, _board: SymbolicState) -> Option<Result<Vec<MoveId>, GameError>> {
        None
    }

    /// [`solve`](Self::solve), by a solver that searches (the 15-puzzle's IDA*) within
    /// `control`: bounded by its nodes (past them, [`GameError::SearchLimit`]), stopped by
    /// another thread ([`GameError::Interrupted`]), its progress counted there. A game whose
    /// solver does not search solves as `solve` does.
    fn solve_within(
        &self,
        board: SymbolicState,
        _control: &SolveControl,
    ) -> Option<Result<Vec<MoveId>, GameError>> {
        self.solve(board)
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
                    allowed: self.allowed_values(),
                })
            })
            .collect::<Result<Vec<u8>, _>>()?;
        self.board_from_values(&values)
    }
}
