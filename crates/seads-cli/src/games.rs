//! `seads games …`: depth tables, split tables and optimal solutions of the discrete games.

use anyhow::Result;
use clap::{Args, Subcommand};
use seads_games::{DepthsReport, GameKind, SolveControl, SolveReport, SplitReport};
use serde::Serialize;

use crate::bad_input;

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
        /// ("1,0,0,…", N² values), TileSwap the tile id of each cell ("3,1,2,0,4,5,6,7,8"), the
        /// sliding puzzle likewise with 0 for the gap ("1,2,3,4,5,6,7,0,8").
        #[arg(long)]
        board: String,
    },
}

/// Which game and size, and the output format.
#[derive(Debug, Args)]
pub struct GameArgs {
    /// The game: lightsout, tileswap or sliding (the 8-puzzle, or the 15-puzzle at size 4).
    #[arg(long)]
    game: GameKind,
    /// Board side length (default: 5 for LightsOut, 3 for TileSwap and the sliding puzzle).
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
            let report = DepthsReport::of(args.game, args.size()).map_err(bad_input)?;
            print_report(&report, args.json, |r| r.table())
        }
        GamesCommand::Split { game, max_depth } => {
            if max_depth == 0 {
                return Err(bad_input(anyhow::anyhow!("--max-depth must be at least 1")).into());
            }
            let report = SplitReport::of(game.game, game.size(), max_depth).map_err(bad_input)?;
            print_report(&report, game.json, |r| r.table())
        }
        GamesCommand::Solve { game, board } => {
            let report = solve_with_spinner(&game, &board).map_err(bad_input)?;
            print_report(&report, game.json, |r| r.table())
        }
    }
}

/// Solves `board`, while a spinner counts the nodes a searching solver (the 15-puzzle's IDA*,
/// which may take minutes on a deep board) has expanded, out of its bound; the spinner is not
/// drawn where the error output is no terminal, and cleared when the solve ends.
fn solve_with_spinner(game: &GameArgs, board: &str) -> Result<SolveReport, seads_games::GameError> {
    let control = SolveControl::default();
    let spinner = indicatif::ProgressBar::new_spinner().with_style(
        indicatif::ProgressStyle::with_template("{spinner} solving: {msg} [{elapsed}]")
            .expect("a valid template"),
    );
    std::thread::scope(|scope| {
        let main = std::thread::current();
        let control = &control;
        let solving = scope.spawn(move || {
            let report = SolveReport::of_within(game.game, game.size(), board, control);
            main.unpark();
            report
        });
        while !solving.is_finished() {
            let expanded = control.expanded();
            if expanded > 0 {
                spinner.set_message(format!(
                    "{expanded} of at most {} search nodes expanded",
                    control.max_nodes()
                ));
            }
            spinner.tick();
            std::thread::park_timeout(std::time::Duration::from_millis(100));
        }
        spinner.finish_and_clear();
        solving
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

fn print_report<T: Serialize>(report: &T, json: bool, table: impl Fn(&T) -> String) -> Result<()> {
    if json {
        outln!("{}", serde_json::to_string(report)?);
    } else {
        outln!("{}", table(report));
    }
    Ok(())
}
