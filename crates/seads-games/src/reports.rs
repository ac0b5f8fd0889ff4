//! What `seads games` shows of a game: boards per solution depth, the train/test split per
//! depth, and the optimal solution of a board, each as JSON (serde) or as a small table.

use std::fmt::Write as _;

use serde::Serialize;

use crate::{BoardDataset, BoardGame, GameError, GameKind, MoveId, Split, enumerate};

/// `game` at `size`, refused where its boards cannot all be listed.
fn listed(game: GameKind, size: usize) -> Result<Box<dyn BoardGame>, GameError> {
    let g = game.build(size)?;
    if g.enumerable().is_none() {
        return Err(GameError::TooLargeToEnumerate {
            game: game.name(),
            size,
        });
    }
    Ok(g)
}

/// Boards per solution depth of a whole game.
#[derive(Debug, Clone, Serialize)]
pub struct DepthsReport {
    /// The game.
    pub game: GameKind,
    /// Its size.
    pub size: usize,
    /// Boards per depth; index = depth, entry 0 is the goal.
    pub counts: Vec<u64>,
}

impl DepthsReport {
    /// Enumerates `game` at `size` from its goal.
    ///
    /// ```
    /// use seads_games::{DepthsReport, GameKind};
    /// let report = DepthsReport::of(GameKind::named("lightsout").unwrap(), 3).unwrap();
    /// assert_eq!(report.counts.iter().sum::<u64>(), 512);
    /// assert!(report.table().ends_with(" total         512"));
    /// ```
    pub fn of(game: GameKind, size: usize) -> Result<Self, GameError> {
        let g = listed(game, size)?;
        let e = g.enumerable().expect("checked by listed");
        Ok(Self {
            game,
            size,
            counts: enumerate(e, None)?.depth_counts(),
        })
    }

    /// A table: one line per depth and the total.
    pub fn table(&self) -> String {
        let total: u64 = self.counts.iter().sum();
        let mut s = format!(
            "{} {}×{}: boards per solution depth\n depth      boards\n",
            self.game, self.size, self.size
        );
        for (d, c) in self.counts.iter().enumerate() {
            let _ = writeln!(s, "{d:>6} {c:>11}");
        }
        s + &format!(" total {total:>11}")
    }
}

/// Boards per depth in each split; index 0 is depth 1.
#[derive(Debug, Clone, Serialize)]
pub struct SplitReport {
    /// Training boards per depth.
    pub train: Vec<usize>,
    /// Test boards per depth.
    pub test: Vec<usize>,
}

impl SplitReport {
    /// The split of `game` at `size` up to `max_depth` (at least 1), which must not lie beyond
    /// the game's farthest board: the enumeration stops there, and the table is allocated only
    /// once the depth is known to exist.
    ///
    /// ```
    /// use seads_games::{GameError, GameKind, SplitReport};
    /// let lightsout = GameKind::named("lightsout").unwrap();
    /// assert_eq!(SplitReport::of(lightsout, 3, 9)?.train.len(), 9);
    /// let beyond = SplitReport::of(lightsout, 3, usize::MAX).unwrap_err();
    /// assert!(matches!(beyond, GameError::DepthBeyondGame { max: 9, .. }), "{beyond}");
    /// # Ok::<(), GameError>(())
    /// ```
    pub fn of(game: GameKind, size: usize, max_depth: usize) -> Result<Self, GameError> {
        let g = listed(game, size)?;
        let data = BoardDataset::build(g.enumerable().expect("checked by listed"), max_depth)?;
        if max_depth > data.max_depth() {
            return Err(GameError::DepthBeyondGame {
                game: game.name(),
                size,
                depth: max_depth,
                max: data.max_depth(),
            });
        }
        let count = |s| (1..=max_depth).map(|d| data.boards(d, s).len()).collect();
        Ok(Self {
            train: count(Split::Train),
            test: count(Split::Test),
        })
    }

    /// A table: one line per depth.
    pub fn table(&self) -> String {
        let mut s = String::from(" depth  train   test\n");
        for (i, (a, b)) in self.train.iter().zip(&self.test).enumerate() {
            let _ = writeln!(s, "{:>6} {a:>6} {b:>6}", i + 1);
        }
        s.trim_end().to_owned()
    }
}

/// An optimal solution of a board.
#[derive(Debug, Clone, Serialize)]
pub struct SolveReport {
    /// The game.
    pub game: GameKind,
    /// Its size.
    pub size: usize,
    /// The board, as the game writes it.
    pub board: String,
    /// Solution depth = length of `moves`.
    pub depth: usize,
    /// Move ids in order (LightsOut: row·N + col pressed; TileSwap: the swap ids of SPEC §1.2).
    pub moves: Vec<MoveId>,
    /// The moves in words, as the game describes them.
    #[serde(skip)]
    pub described: Vec<String>,
}

impl SolveReport {
    /// Solves `board` (the game's text form) optimally by the game's own solver (GF(2) for
    /// LightsOut, depth tables for TileSwap and the 8-puzzle, IDA* for the 15-puzzle), or from a
    /// depth table where the game has none.
    ///
    /// ```
    /// use seads_games::{GameKind, SolveReport};
    /// let lightsout = GameKind::named("lightsout").unwrap();
    /// let report = SolveReport::of(lightsout, 3, "1,1,0,1,0,0,0,0,0").unwrap();
    /// assert_eq!((report.depth, report.moves.clone()), (1, vec![0]));
    /// assert!(report.table().ends_with("0 (press row 0 col 0)"));
    /// ```
    pub fn of(game: GameKind, size: usize, board: &str) -> Result<Self, GameError> {
        Self::of_within(game, size, board, &crate::SolveControl::default())
    }

    /// [`of`](Self::of), a searching solver (the 15-puzzle's) within `control`: its bound of
    /// nodes, stopped and its progress watched from another thread.
    pub fn of_within(
        game: GameKind,
        size: usize,
        board: &str,
        control: &crate::SolveControl,
    ) -> Result<Self, GameError> {
        let g = game.build(size)?;
        let z = g.parse(board)?;
        let moves = match g.solve_within(z, control) {
            Some(moves) => moves?,
            None => {
                let e = listed(game, size)?;
                crate::DepthTable::build(e.enumerable().expect("checked by listed"))?
                    .solve(e.enumerable().expect("checked by listed"), z)?
            }
        };
        debug_assert!(g.is_goal(g.apply_all(z, &moves)));
        Ok(Self {
            game,
            size,
            board: g.format(z),
            depth: moves.len(),
            described: moves.iter().map(|&m| g.describe_move(m)).collect(),
            moves,
        })
    }

    /// Two lines: the board, and the moves in words.
    pub fn table(&self) -> String {
        let moves = &self.described;
        format!(
            "{} {}×{} board {}\nsolution depth {}: {}",
            self.game,
            self.size,
            self.size,
            self.board,
            self.depth,
            if moves.is_empty() {
                "already solved".to_owned()
            } else {
                moves.join(", ")
            }
        )
    }
}
