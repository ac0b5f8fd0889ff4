//! `seads games …`: depth tables, split tables and optimal solutions of the discrete games.

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use seads_games::{
    BoardDataset, DepthTable, Enumerable, GameKind, Gf2Solver, LightsOut, MoveId, Split, TileSwap,
    enumerate,
};
use serde::Serialize;

use crate::BadInput;

/// Subcommands of `seads games`.
#[derive(Debug, Subcommand)]
pub enum GamesCommand {
    /// Number of boards at each solution depth (breadth-first search from the goal).
    Depths(GameArgs),
    /// Number of train and test boards per depth under the CRC32 split of the paper.
    Split {
        #[command(flatten)]
        game: GameArgs,
        /// Largest solution depth to count.
        #[arg(long, default_value_t = 5)]
        max_depth: usize,
    },
    /// An optimal (shortest) move sequence that brings a board to the goal.
    Solve {
        #[command(flatten)]
        game: GameArgs,
        /// The board, row-major, values separated by commas: LightsOut 0/1 per field
        /// ("1,0,0,…", N² values), TileSwap the tile id of each cell ("3,1,2,0,4,5,6,7,8").
        #[arg(long)]
        board: String,
    },
}

/// Which game and size, and the output format.
#[derive(Debug, Args)]
pub struct GameArgs {
    /// The game: lightsout or tileswap.
    #[arg(long)]
    game: GameKind,
    /// Board side length (default: 5 for LightsOut, 3 for TileSwap).
    #[arg(long)]
    size: Option<usize>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

impl GameArgs {
    fn size(&self) -> usize {
        self.size.unwrap_or(self.game.default_size())
    }
}

/// Runs a `seads games` subcommand.
pub fn run(cmd: GamesCommand) -> Result<()> {
    match cmd {
        GamesCommand::Depths(args) => {
            let report = depths(args.game, args.size())?;
            print_report(&report, args.json, |r| r.table())
        }
        GamesCommand::Split { game, max_depth } => {
            let report = split(game.game, game.size(), max_depth)?;
            print_report(&report, game.json, |r| r.table())
        }
        GamesCommand::Solve { game, board } => {
            let report = solve(game.game, game.size(), &board)?;
            print_report(&report, game.json, |r| r.table())
        }
    }
}

fn print_report<T: Serialize>(report: &T, json: bool, table: impl Fn(&T) -> String) -> Result<()> {
    if json {
        outln!("{}", serde_json::to_string(report)?);
    } else {
        outln!("{}", table(report));
    }
    Ok(())
}

fn build_game(game: GameKind, size: usize) -> Result<Box<dyn EnumerableGame>> {
    Ok(match game {
        GameKind::LightsOut => Box::new(LightsOut::new(size).map_err(|e| BadInput(e.into()))?),
        GameKind::TileSwap => Box::new(TileSwap::with_size(size).map_err(|e| BadInput(e.into()))?),
    })
}

/// A game that can also be enumerated (both games are).
trait EnumerableGame: Enumerable {}
impl<T: Enumerable> EnumerableGame for T {}

/// Output of `seads games depths`.
#[derive(Debug, Serialize)]
pub struct DepthsReport {
    game: GameKind,
    size: usize,
    /// Boards per depth; index = depth, entry 0 is the goal.
    counts: Vec<u64>,
}

impl DepthsReport {
    fn table(&self) -> String {
        let total: u64 = self.counts.iter().sum();
        let mut s = format!(
            "{} {}×{}: boards per solution depth\n depth      boards\n",
            self.game, self.size, self.size
        );
        for (d, c) in self.counts.iter().enumerate() {
            s += &format!("{d:>6} {c:>11}\n");
        }
        s + &format!(" total {total:>11}")
    }
}

fn depths(game: GameKind, size: usize) -> Result<DepthsReport> {
    let g = build_game(game, size)?;
    let e = enumerate(g.as_ref(), None).map_err(|e| BadInput(e.into()))?;
    Ok(DepthsReport {
        game,
        size,
        counts: e.depth_counts(),
    })
}

/// Output of `seads games split`: index 0 = depth 1.
#[derive(Debug, Serialize)]
pub struct SplitReport {
    train: Vec<usize>,
    test: Vec<usize>,
}

impl SplitReport {
    fn table(&self) -> String {
        let mut s = String::from(" depth  train   test\n");
        for (i, (a, b)) in self.train.iter().zip(&self.test).enumerate() {
            s += &format!("{:>6} {a:>6} {b:>6}\n", i + 1);
        }
        s.trim_end().to_owned()
    }
}

fn split(game: GameKind, size: usize, max_depth: usize) -> Result<SplitReport> {
    if max_depth == 0 {
        return Err(BadInput(anyhow::anyhow!("--max-depth must be at least 1")).into());
    }
    let g = build_game(game, size)?;
    let data = BoardDataset::build(g.as_ref(), max_depth).map_err(|e| BadInput(e.into()))?;
    let count = |s| (1..=max_depth).map(|d| data.boards(d, s).len()).collect();
    Ok(SplitReport {
        train: count(Split::Train),
        test: count(Split::Test),
    })
}

/// Output of `seads games solve`.
#[derive(Debug, Serialize)]
pub struct SolveReport {
    game: GameKind,
    size: usize,
    board: String,
    /// Solution depth = length of `moves`.
    depth: usize,
    /// Move ids in order (LightsOut: row·N + col pressed; TileSwap: the swap ids of SPEC §1.2).
    moves: Vec<MoveId>,
}

impl SolveReport {
    fn table(&self) -> String {
        let moves: Vec<String> = self.moves.iter().map(|m| self.describe(*m)).collect();
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

    fn describe(&self, mv: MoveId) -> String {
        match self.game {
            GameKind::LightsOut => {
                format!("{mv} (press row {} col {})", mv / self.size, mv % self.size)
            }
            GameKind::TileSwap => {
                let (p, q) = TileSwap::swap_cells(mv);
                format!("{mv} (swap ({},{})↔({},{}))", p / 3, p % 3, q / 3, q % 3)
            }
        }
    }
}

fn solve(game: GameKind, size: usize, board: &str) -> Result<SolveReport> {
    let g = build_game(game, size)?;
    let z = g.parse(board).map_err(|e| BadInput(e.into()))?;
    let moves = match game {
        GameKind::LightsOut => {
            let lo = LightsOut::new(size)?;
            Gf2Solver::new(&lo)
                .solve(z)
                .map_err(|e| BadInput(e.into()))?
        }
        GameKind::TileSwap => {
            let table = DepthTable::build(g.as_ref()).context("enumerating TileSwap")?;
            table.solve(g.as_ref(), z).map_err(|e| BadInput(e.into()))?
        }
    };
    debug_assert!(g.is_goal(g.apply_all(z, &moves)));
    Ok(SolveReport {
        game,
        size,
        board: g.format(z),
        depth: moves.len(),
        moves,
    })
}
