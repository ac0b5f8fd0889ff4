//! The search from both ends against independent sources: the GF(2) solver's optimal lengths on
//! LightsOut, breadth-first search's plans where the skills are not masks (TileSwap) or the goal
//! cannot be reached, and the forward model itself along every plan of a model whose skills act
//! by board.

use proptest::prelude::*;
use seads_games::{
    BoardGame, GameSuccessor, Gf2Solver, LightsOut, Successor, SymbolicState, TileSwap,
};
use seads_planner::{PlanChoice, PlanError, PlannerConfig, Search, bfs_plan, find_plan, meet_plan};
use std::sync::LazyLock;

static LIGHTSOUT: LazyLock<LightsOut> = LazyLock::new(|| LightsOut::new(5).unwrap());

fn config(plan: PlanChoice) -> PlannerConfig {
    PlannerConfig {
        plan,
        ..PlannerConfig::default()
    }
}

/// The boards a plan passes through under `successor`, from `start`.
fn roll(
    successor: &mut dyn Successor,
    start: SymbolicState,
    skills: &[usize],
) -> Vec<SymbolicState> {
    let k = successor.num_skills();
    let mut z = start;
    let mut out = Vec::new();
    skills
        .iter()
        .map(|&skill| {
            out.clear();
            successor.successors(&[z], &mut out);
            z = out[skill];
            assert!(skill < k);
            z
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// On LightsOut's rules, plans from both ends are as short as the GF(2) solver says a
    /// solution can be, to depth 12 (where breadth-first search would take minutes), they reach
    /// the goal, and they predict every board on the way.
    #[test]
    fn plans_from_both_ends_are_optimal_on_lightsout(
        moves in proptest::collection::vec(0usize..25, 1..13),
        first in any::<bool>(),
    ) {
        let lo = &*LIGHTSOUT;
        let board = lo.apply_all(lo.goal(), &moves);
        let depth = Gf2Solver::new(lo).depth(board).unwrap();
        prop_assume!(depth > 0);
        let choice = if first { PlanChoice::FirstFound } else { PlanChoice::MostLikely };
        let mut successor = GameSuccessor::new(lo);
        let plan = meet_plan(&mut successor, board, lo.goal(), &config(choice)).unwrap();
        prop_assert_eq!(plan.skills.len(), depth);
        prop_assert_eq!(&roll(&mut successor, board, &plan.skills), &plan.predicted);
        prop_assert_eq!(plan.predicted.last(), Some(&lo.goal()));
    }
}

/// Every 3×3 LightsOut board (all 512 are solvable): the optimal length, as GF(2) elimination
/// computes it, and the same length breadth-first search finds.
#[test]
fn every_three_by_three_board_gets_a_shortest_plan() {
    let game = LightsOut::new(3).unwrap();
    let solver = Gf2Solver::new(&game);
    let mut successor = GameSuccessor::new(&game);
    for bits in 1u32..512 {
        let board =
            SymbolicState::from_bools(&(0..9).map(|d| bits >> d & 1 == 1).collect::<Vec<_>>());
        let depth = solver.depth(board).unwrap();
        let plan = meet_plan(
            &mut successor,
            board,
            game.goal(),
            &PlannerConfig::default(),
        )
        .unwrap();
        assert_eq!(plan.skills.len(), depth, "board {bits:09b}");
        assert_eq!(
            game.apply_all(board, &plan.skills),
            game.goal(),
            "board {bits:09b}"
        );
        let bfs = bfs_plan(
            &mut successor,
            board,
            game.goal(),
            &PlannerConfig::default(),
        )
        .unwrap();
        assert_eq!(bfs.skills.len(), depth, "board {bits:09b}");
    }
}

/// A 4×4 LightsOut board with one light is not always solvable (its moves span 12 of 16
/// dimensions): both searches agree, board by board, on whether a plan exists and how long the
/// shortest is, and a board without a plan ends in `NotFound` once the forward side has seen
/// every reachable board.
#[test]
fn both_searches_agree_on_unreachable_goals() {
    let game = LightsOut::new(4).unwrap();
    let mut successor = GameSuccessor::new(&game);
    let mut unreachable = 0;
    for light in 0..16 {
        let mut board = game.goal();
        board.flip(light);
        let bfs = bfs_plan(
            &mut successor,
            board,
            game.goal(),
            &PlannerConfig::default(),
        );
        let meet = meet_plan(
            &mut successor,
            board,
            game.goal(),
            &PlannerConfig::default(),
        );
        match (bfs, meet) {
            (Ok(b), Ok(m)) => assert_eq!(b.skills.len(), m.skills.len(), "light {light}"),
            (Err(PlanError::NotFound { .. }), Err(PlanError::NotFound { .. })) => unreachable += 1,
            (b, m) => panic!("light {light}: {b:?} against {m:?}"),
        }
    }
    assert!(
        unreachable > 0,
        "some one-light 4×4 boards have no solution"
    );
}

/// TileSwap's swaps move tiles, so no skill is a mask: beyond the first two layers (which both
/// searches expand alike, and where a plan of length 1 or 2 is found before the masks are read),
/// the search from both ends is breadth-first search, plan for plan and count for count.
#[test]
fn where_skills_are_not_masks_the_search_is_breadth_first() {
    let ts = TileSwap::new();
    let mut compared = 0;
    for swaps in [
        vec![0],
        vec![3, 7],
        vec![1, 5, 9, 2],
        vec![0, 4, 8, 11, 6, 2],
        vec![2, 10, 7],
    ] {
        let board = ts.apply_all(ts.goal(), &swaps);
        let mut successor = GameSuccessor::new(&ts);
        let bfs = bfs_plan(&mut successor, board, ts.goal(), &PlannerConfig::default()).unwrap();
        let meet = meet_plan(&mut successor, board, ts.goal(), &PlannerConfig::default()).unwrap();
        if bfs.skills.len() > 2 {
            assert_eq!(meet, bfs, "{swaps:?}");
            compared += 1;
        } else {
            assert_eq!(meet.skills.len(), bfs.skills.len(), "{swaps:?}");
        }
    }
    assert!(compared >= 2, "{compared}");
}

/// A model in which skill 0 acts by board: it makes move 0 where field 24 is off, move 1 where
/// it is on. Its mask holds on half the boards, so joined plans through it are sometimes wrong.
/// Every plan returned is one the model predicts to solve the board (checked by running the
/// model along it), none is shorter than breadth-first search's, and deep boards take far fewer
/// expansions than breadth-first search's.
struct ByBoard<'a>(&'a LightsOut);

impl Successor for ByBoard<'_> {
    fn num_skills(&self) -> usize {
        25
    }
    fn symbolic_len(&self) -> usize {
        25
    }
    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        for &z in states {
            out.extend((0..25).map(|k| {
                let m = if k == 0 && z.get(24) { 1 } else { k };
                self.0.apply(z, m)
            }));
        }
    }
}

#[test]
fn joined_plans_are_verified_with_the_model() {
    let lo = &*LIGHTSOUT;
    let mut model = ByBoard(lo);
    let mut fewer = 0;
    for moves in [
        vec![0],
        vec![0, 24],
        vec![0, 5, 24],
        vec![0, 1, 12, 24],
        vec![0, 3, 9, 17, 24],
        vec![0, 2, 6, 13, 19, 24],
        vec![0, 4, 8, 10, 15, 21, 24],
    ] {
        let board = lo.apply_all(lo.goal(), &moves);
        let bfs = bfs_plan(&mut model, board, lo.goal(), &PlannerConfig::default()).unwrap();
        let meet = meet_plan(&mut model, board, lo.goal(), &PlannerConfig::default()).unwrap();
        assert_eq!(
            roll(&mut model, board, &meet.skills),
            meet.predicted,
            "{moves:?}"
        );
        assert_eq!(meet.predicted.last(), Some(&lo.goal()), "{moves:?}");
        assert!(meet.skills.len() >= bfs.skills.len(), "{moves:?}");
        fewer += usize::from(meet.expanded * 10 < bfs.expanded);
    }
    assert!(fewer >= 2, "the deep boards are searched from both ends");
}

/// Two skills make move 7, one of which the model doubts: from both ends as breadth-first, the
/// most likely plan takes the sure one, and the first found the lower-numbered.
struct TwoForSeven<'a>(&'a LightsOut);

impl TwoForSeven<'_> {
    fn moves(k: usize) -> usize {
        if k == 25 { 7 } else { k }
    }
}

impl Successor for TwoForSeven<'_> {
    fn num_skills(&self) -> usize {
        26
    }
    fn symbolic_len(&self) -> usize {
        25
    }
    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        for &z in states {
            out.extend((0..26).map(|k| self.0.apply(z, Self::moves(k))));
        }
    }
    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        Some(
            steps
                .iter()
                .map(
                    |&(z0, k, zt)| match self.0.apply(z0, Self::moves(k)) == zt {
                        true if k == 7 => -3.0,
                        true => -0.01,
                        false => -50.0,
                    },
                )
                .collect(),
        )
    }
}

#[test]
fn the_most_likely_plan_from_both_ends_takes_the_sure_skill() {
    let lo = &*LIGHTSOUT;
    let mut model = TwoForSeven(lo);
    for moves in [vec![7], vec![7, 12, 20], vec![0, 7, 11, 18, 24, 3, 9]] {
        let board = lo.apply_all(lo.goal(), &moves);
        let likely = meet_plan(
            &mut model,
            board,
            lo.goal(),
            &config(PlanChoice::MostLikely),
        )
        .unwrap();
        let first = meet_plan(
            &mut model,
            board,
            lo.goal(),
            &config(PlanChoice::FirstFound),
        )
        .unwrap();
        assert_eq!(likely.skills.len(), moves.len());
        assert!(
            likely.skills.contains(&25) && !likely.skills.contains(&7),
            "{:?}",
            likely.skills
        );
        assert!(
            first.skills.contains(&7) && !first.skills.contains(&25),
            "{:?}",
            first.skills
        );
        let ll = likely.log_likelihood.unwrap();
        assert!((ll + 0.01 * moves.len() as f32).abs() < 1e-5, "{ll}");
    }
}

/// The state budget counts forward boards and verification steps and ends the search at the
/// same count every time; `find_plan` takes the search the configuration names.
#[test]
fn the_budget_bounds_the_search_from_both_ends() {
    let lo = &*LIGHTSOUT;
    let board = lo.apply_all(lo.goal(), &[0, 3, 7, 11, 14, 18, 22, 24, 9, 5]);
    let mut successor = GameSuccessor::new(lo);
    let full = meet_plan(&mut successor, board, lo.goal(), &PlannerConfig::default()).unwrap();
    assert_eq!(full.skills.len(), Gf2Solver::new(lo).depth(board).unwrap());
    let tight = PlannerConfig {
        max_expanded: Some(full.expanded - 1),
        ..PlannerConfig::default()
    };
    for _ in 0..2 {
        match meet_plan(&mut successor, board, lo.goal(), &tight) {
            Err(PlanError::Budget { expanded }) => assert!(expanded < full.expanded),
            other => panic!("{other:?}"),
        }
    }
    let both = PlannerConfig {
        search: Search::BothEnds,
        ..PlannerConfig::default()
    };
    assert_eq!(
        find_plan(&mut successor, board, lo.goal(), &both).unwrap(),
        full
    );
    let shallow = lo.apply_all(lo.goal(), &[4, 9]);
    assert_eq!(
        find_plan(
            &mut successor,
            shallow,
            lo.goal(),
            &PlannerConfig::default()
        )
        .unwrap(),
        bfs_plan(
            &mut successor,
            shallow,
            lo.goal(),
            &PlannerConfig::default()
        )
        .unwrap()
    );
}
