//! Exhaustive checks: BFS depths against brute force and against the GF(2) solver.

use seads_games::{
    BoardGame, Enumerable, Gf2Solver, LightsOut, SymbolicState, TileSwap, enumerate,
};

/// On 3×3 and 4×4, the BFS depth of every board equals the weight of the lightest move set that
/// produces it, found by trying all 2^(N²) move sets.
#[test]
fn bfs_depth_equals_brute_force_on_small_boards() {
    for n in [3, 4] {
        let g = LightsOut::new(n).unwrap();
        let moves = n * n;
        let mut lightest = vec![u32::MAX; 1 << moves];
        for set in 0u32..(1 << moves) {
            let board = (0..moves)
                .filter(|m| set >> m & 1 == 1)
                .fold(g.goal(), |b, m| g.apply(b, m));
            let i = g.index_of(board) as usize;
            lightest[i] = lightest[i].min(set.count_ones());
        }
        let e = enumerate(&g, None).unwrap();
        let mut seen = 0;
        for d in 0..=e.max_depth() {
            for &i in e.layer(d) {
                assert_eq!(lightest[i as usize], d as u32, "{n}×{n} board {i}");
                seen += 1;
            }
        }
        assert_eq!(seen, lightest.iter().filter(|&&w| w != u32::MAX).count());
    }
}

/// On 5×5, the GF(2) solver agrees with the BFS on every one of the 2^25 boards: the 2^23
/// reachable ones have solver depth = BFS layer, the others are reported unsolvable.
#[test]
fn gf2_solver_agrees_with_bfs_on_all_5x5_boards() {
    let g = LightsOut::new(5).unwrap();
    let solver = Gf2Solver::new(&g);
    let e = enumerate(&g, None).unwrap();
    assert_eq!(e.total(), 1 << 23);
    for d in 0..=e.max_depth() {
        for &i in e.layer(d) {
            assert_eq!(solver.depth(g.board_at(i)).unwrap(), d, "board {i}");
        }
    }
    let solvable = (0u32..1 << 25)
        .filter(|&i| solver.is_solvable(SymbolicState::from_u64(i as u64)))
        .count();
    assert_eq!(solvable, 1 << 23);
}

/// Each game's own solver (`BoardGame::solve`, `solution_depth`) against the breadth-first layers:
/// every TileSwap board, every reachable 4×4 LightsOut board; each solution reaches the goal in
/// as many moves as the depth says.
#[test]
fn each_games_own_solver_agrees_with_breadth_first_search() {
    fn check<G: Enumerable>(game: &G, every: usize) {
        let e = enumerate(game, None).unwrap();
        for d in 0..=e.max_depth() {
            for &i in e.layer(d).iter().step_by(every) {
                let board = game.board_at(i);
                assert_eq!(game.solution_depth(board).unwrap().unwrap(), d, "board {i}");
                let moves = game.solve(board).unwrap().unwrap();
                assert_eq!(moves.len(), d);
                assert!(game.is_goal(game.apply_all(board, &moves)), "board {i}");
            }
        }
    }
    check(&TileSwap::new(), 1);
    check(&LightsOut::new(4).unwrap(), 1);
    // An unreachable 4×4 board (4×4 LightsOut has 2^12 of 2^16) is said to be unsolvable.
    let g = LightsOut::new(4).unwrap();
    let unreachable = (0u64..1 << 16)
        .map(SymbolicState::from_u64)
        .find(|&b| !Gf2Solver::new(&g).is_solvable(b))
        .unwrap();
    assert!(g.solution_depth(unreachable).unwrap().is_err());
    // Not a TileSwap board at all: an error, not a panic.
    assert!(
        TileSwap::new()
            .solution_depth(SymbolicState::ZERO)
            .unwrap()
            .is_err()
    );
}
