//! Boards per solution depth: breadth-first enumeration from the goal.
//!
//! ```sh
//! cargo run -p seads-games --example depths           # LightsOut 5×5 up to depth 6, TileSwap 3×3
//! cargo run -p seads-games --example depths -- 4      # LightsOut 4×4, all depths
//! ```
#![allow(clippy::print_stdout)] // an example prints

use seads_games::{BoardGame, GameError, LightsOut, TileSwap, enumerate};

fn run(size: Option<usize>) -> Result<(), GameError> {
    let (game, max_depth) = match size {
        Some(n) => (LightsOut::new(n)?, None),
        None => (LightsOut::new(5)?, Some(6)),
    };
    let lightsout = enumerate(&game, max_depth)?;
    println!("LightsOut {0}×{0}: boards per depth", game.size());
    for (depth, count) in lightsout.depth_counts().iter().enumerate() {
        println!("  {depth:>2}  {count}");
    }
    let tileswap = enumerate(&TileSwap::new(), None)?;
    println!(
        "TileSwap 3×3: {} boards, deepest {} moves",
        tileswap.total(),
        tileswap.max_depth()
    );
    Ok(())
}

fn main() -> Result<(), GameError> {
    run(std::env::args().nth(1).and_then(|a| a.parse().ok()))
}

#[test]
fn runs() {
    run(None).unwrap();
    run(Some(3)).unwrap();
}
