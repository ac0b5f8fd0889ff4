//! The depth and split tables written to `data/` by `cargo xtask gen-splits` (the example
//! `tables`; SPEC §1.3, §1.4).

use std::fmt::Write as _;

use crate::{Enumerable, LightsOut, Split, TileSwap, enumerate, split_of};

/// The games whose depth counts are tabulated: LightsOut 3×3 to 5×5 and TileSwap 3×3.
fn depth_games() -> Vec<Box<dyn Enumerable>> {
    let mut games: Vec<Box<dyn Enumerable>> = (3..=5)
        .map(|n| Box::new(LightsOut::new(n).expect("supported size")) as Box<dyn Enumerable>)
        .collect();
    games.push(Box::new(TileSwap::new()));
    games
}

/// `data/depth_counts.csv`: `game,size,depth,count`, one row per reachable depth.
pub fn depth_counts_csv() -> String {
    let mut csv = String::from("game,size,depth,count\n");
    for game in depth_games() {
        let e = enumerate(game.as_ref(), None).expect("these games are enumerable");
        for (depth, count) in e.depth_counts().iter().enumerate() {
            writeln!(csv, "{},{},{depth},{count}", game.kind(), game.size()).expect("String write");
        }
    }
    csv
}

/// `data/split_counts.csv`: `game,depth,split,count` for LightsOut 5×5 and TileSwap 3×3, depth ≥ 1.
pub fn split_counts_csv() -> String {
    let games: [Box<dyn Enumerable>; 2] = [
        Box::new(LightsOut::new(5).expect("5×5")),
        Box::new(TileSwap::new()),
    ];
    let mut csv = String::from("game,depth,split,count\n");
    for game in games {
        let e = enumerate(game.as_ref(), None).expect("these games are enumerable");
        for depth in 1..=e.max_depth() {
            let train = e
                .layer(depth)
                .iter()
                .filter(|&&i| split_of(&game.values(game.board_at(i))) == Split::Train)
                .count();
            let test = e.layer(depth).len() - train;
            for (split, count) in [(Split::Train, train), (Split::Test, test)] {
                writeln!(csv, "{},{depth},{split},{count}", game.kind()).expect("String write");
            }
        }
    }
    csv
}
