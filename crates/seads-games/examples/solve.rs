//! An optimal solution of a board: LightsOut by linear algebra over GF(2), TileSwap by its
//! depth table.
//!
//! ```sh
//! cargo run -p seads-games --example solve -- "1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0"
//! cargo run -p seads-games --example solve -- "3,1,2,0,4,5,6,7,8"       # 9 values: TileSwap
//! ```
#![allow(clippy::print_stdout)] // an example prints

use seads_games::{BoardGame, DepthTable, GameError, Gf2Solver, LightsOut, TileSwap};

fn run(board: &str) -> Result<Vec<usize>, GameError> {
    let fields = board.split(',').count();
    let (game, moves): (Box<dyn BoardGame>, Vec<usize>) = if fields == 9 {
        let game = TileSwap::new();
        let z = game.parse(board)?;
        let moves = DepthTable::build(&game)?.solve(&game, z)?;
        (Box::new(game), moves)
    } else {
        let game = LightsOut::new((fields as f64).sqrt().round() as usize)?;
        let z = game.parse(board)?;
        let moves = Gf2Solver::new(&game).solve(z)?;
        (Box::new(game), moves)
    };
    let mut z = game.parse(board)?;
    println!("{} moves: {moves:?}", moves.len());
    for &m in &moves {
        z = game.apply(z, m);
        println!("  move {m:>2} -> {}", game.format(z));
    }
    assert!(game.is_goal(z));
    Ok(moves)
}

fn main() -> Result<(), GameError> {
    let board = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0".into());
    run(&board).map(|_| ())
}

#[test]
fn runs() {
    assert_eq!(
        run("1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0").unwrap(),
        [0]
    );
    assert_eq!(run("3,1,2,0,4,5,6,7,8").unwrap().len(), 1);
    assert!(run("1,2").is_err());
}
