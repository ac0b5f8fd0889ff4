//! Exhaustive checks: BFS depths against brute force and against the GF(2) solver.

use seads_games::{BoardGame, Enumerable, Gf2Solver, LightsOut, SymbolicState, enumerate};

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
