//! Property tests of the game rules against naive references (proptest).

use proptest::prelude::*;
use seads_games::{BoardGame, DepthTable, Gf2Solver, LightsOut, SymbolicState, TileSwap};
use std::sync::LazyLock;

static LIGHTSOUT5: LazyLock<LightsOut> = LazyLock::new(|| LightsOut::new(5).unwrap());
static SOLVER5: LazyLock<Gf2Solver> = LazyLock::new(|| Gf2Solver::new(&LIGHTSOUT5));
static TILESWAP_DEPTHS: LazyLock<DepthTable> =
    LazyLock::new(|| DepthTable::build(&TileSwap::new()).unwrap());

/// A LightsOut size and an arbitrary board of that size.
fn lightsout_board() -> impl Strategy<Value = (usize, SymbolicState)> {
    (3usize..=13)
        .prop_flat_map(|n| (Just(n), proptest::collection::vec(any::<bool>(), n * n)))
        .prop_map(|(n, bits)| (n, SymbolicState::from_bools(&bits)))
}

/// A TileSwap board: a uniformly shuffled permutation.
fn tileswap_board() -> impl Strategy<Value = SymbolicState> {
    Just((0u8..9).collect::<Vec<u8>>())
        .prop_shuffle()
        .prop_map(|tiles| TileSwap::new().board_from_values(&tiles).unwrap())
}

/// A solvable 5×5 LightsOut board: the XOR of a random set of moves.
fn solvable_lightsout5() -> impl Strategy<Value = SymbolicState> {
    proptest::collection::vec(0usize..25, 0..20)
        .prop_map(|moves| LIGHTSOUT5.apply_all(LIGHTSOUT5.goal(), &moves))
}

/// The naive rule on a plain grid: toggle the pressed field and its in-board neighbours.
fn naive_press(n: usize, grid: &mut [Vec<bool>], mv: usize) {
    let (r, c) = ((mv / n) as i64, (mv % n) as i64);
    for (dr, dc) in [(0, 0), (-1, 0), (1, 0), (0, -1), (0, 1)] {
        let (rr, cc) = (r + dr, c + dc);
        if (0..n as i64).contains(&rr) && (0..n as i64).contains(&cc) {
            grid[rr as usize][cc as usize] ^= true;
        }
    }
}

proptest! {
    #[test]
    fn lightsout_matches_plain_grid((n, board) in lightsout_board(), mv in 0usize..169) {
        let g = LightsOut::new(n).unwrap();
        let mv = mv % (n * n);
        let mut grid: Vec<Vec<bool>> = (0..n).map(|r| (0..n).map(|c| board.get(r * n + c)).collect()).collect();
        naive_press(n, &mut grid, mv);
        let expected = SymbolicState::from_bools(&grid.concat());
        prop_assert_eq!(g.apply(board, mv), expected);
    }

    #[test]
    fn lightsout_moves_are_involutions_and_commute((n, board) in lightsout_board(), a in 0usize..169, b in 0usize..169) {
        let g = LightsOut::new(n).unwrap();
        let (a, b) = (a % (n * n), b % (n * n));
        prop_assert_eq!(g.apply(g.apply(board, a), a), board);
        prop_assert_eq!(g.apply(g.apply(board, a), b), g.apply(g.apply(board, b), a));
    }

    #[test]
    fn tileswap_moves_are_involutions_and_keep_permutations(board in tileswap_board(), moves in proptest::collection::vec(0usize..12, 1..30)) {
        let g = TileSwap::new();
        for &m in &moves {
            prop_assert_eq!(g.apply(g.apply(board, m), m), board);
        }
        let after = g.apply_all(board, &moves);
        prop_assert!(g.is_valid(after));
        let mut tiles = TileSwap::tiles(after).to_vec();
        tiles.sort_unstable();
        prop_assert_eq!(tiles, (0u8..9).collect::<Vec<_>>());
    }

    #[test]
    fn lightsout_optimal_solution_reaches_goal(board in solvable_lightsout5()) {
        let moves = SOLVER5.solve(board).unwrap();
        prop_assert!(LIGHTSOUT5.is_goal(LIGHTSOUT5.apply_all(board, &moves)));
        prop_assert!(moves.len() <= 15);
    }

    #[test]
    fn tileswap_optimal_solution_reaches_goal(board in tileswap_board()) {
        let g = TileSwap::new();
        let moves = TILESWAP_DEPTHS.solve(&g, board).unwrap();
        prop_assert!(g.is_goal(g.apply_all(board, &moves)));
        prop_assert_eq!(moves.len() as u8, TILESWAP_DEPTHS.depth(&g, board).unwrap());
    }

    #[test]
    fn one_move_changes_depth_by_exactly_one(lo in solvable_lightsout5(), ts in tileswap_board(), a in 0usize..25, b in 0usize..12) {
        let (d0, d1) = (SOLVER5.depth(lo).unwrap(), SOLVER5.depth(LIGHTSOUT5.apply(lo, a)).unwrap());
        prop_assert_eq!(d0.abs_diff(d1), 1);
        let g = TileSwap::new();
        let (t0, t1) = (TILESWAP_DEPTHS.depth(&g, ts).unwrap(), TILESWAP_DEPTHS.depth(&g, g.apply(ts, b)).unwrap());
        prop_assert_eq!(t0.abs_diff(t1), 1);
    }

    #[test]
    fn parse_format_round_trip((n, board) in lightsout_board(), ts in tileswap_board()) {
        let g = LightsOut::new(n).unwrap();
        prop_assert_eq!(g.parse(&g.format(board)).unwrap(), board);
        let t = TileSwap::new();
        prop_assert_eq!(t.parse(&t.format(ts)).unwrap(), ts);
    }
}

proptest! {
    /// `write_values` writes what `values` returns, and `board_from_values` reads it back.
    #[test]
    fn written_values_are_the_values((n, board) in lightsout_board(), tiles in tileswap_board()) {
        let game = LightsOut::new(n).unwrap();
        let mut out = vec![7u8; n * n];
        game.write_values(board, &mut out);
        prop_assert_eq!(&out, &game.values(board));
        prop_assert_eq!(game.board_from_values(&out).unwrap(), board);
        let mut out = [7u8; 9];
        TileSwap::new().write_values(tiles, &mut out);
        prop_assert_eq!(out.to_vec(), TileSwap::new().values(tiles));
    }
}
