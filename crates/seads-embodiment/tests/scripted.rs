//! Proof that the embodiments work: scripted controllers (written here, independent of the
//! environments' code) drive each manipulator to every field or pivot and push, and every one of
//! the K ground-truth moves happens within the skill's step limit, on several seeds.

use seads_embodiment::{EnvConfig, Environment, Layout, Push, env_names, make_env};
use seads_games::MoveId;

const SEEDS: [u64; 20] = [
    1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20,
];

/// Where to push for each move, in normalised board coordinates: the pivot of the move where
/// the layout has pivots (TileSwap), else the centre of the move's field.
fn targets(layout: Layout, moves: usize) -> Vec<(MoveId, [f64; 2])> {
    let pivots = layout.pivots();
    let fields = layout.fields();
    (0..moves)
        .map(|m| {
            let target = match pivots
                .iter()
                .find(|&&(u, v)| layout.locate(u, v) == Some(m))
            {
                Some(&(u, v)) => [u, v],
                None => {
                    let [u0, v0, u1, v1] = fields[m];
                    [(u0 + u1) / 2.0, (v0 + v1) / 2.0]
                }
            };
            (m, target)
        })
        .collect()
}

/// Every registered environment of a manipulator (`-cursor`, `-reacher`): every game.
fn envs_of(manipulator: &str) -> Vec<&'static str> {
    let names: Vec<_> = env_names()
        .into_iter()
        .filter(|n| n.ends_with(manipulator))
        .collect();
    assert!(names.len() >= 3, "{manipulator}: {names:?}");
    names
}

/// Runs `controller` from a fresh reset until the skill ends; returns the move it made.
fn run_skill<const A: usize>(
    env: &mut dyn Environment,
    seed: u64,
    mut controller: impl FnMut(&[f32]) -> [f32; A],
) -> Option<MoveId> {
    env.seed(seed);
    env.reset().unwrap();
    let limit = env.spec().step_limit.unwrap();
    for _ in 0..limit {
        let obs = env.observation();
        let action = controller(&obs);
        let outcome = env.step(&action).unwrap();
        if outcome.done() {
            return outcome.game_move();
        }
    }
    panic!("the step limit must end the skill")
}

/// Aims `controller` at every move that changes the reset board (all of them but in games
/// whose moves depend on the state), on every seed; each must be made.
fn check_all_moves<const A: usize>(
    name: &str,
    controller: impl Fn(Layout, MoveId, [f64; 2], &[f32]) -> [f32; A],
) {
    let mut env = make_env(name, &EnvConfig::default()).unwrap();
    let spec = env.spec().clone();
    let game = spec.game.build(spec.board_size).unwrap();
    let layout = Layout::standard(game.as_ref()).unwrap();
    for seed in SEEDS {
        env.seed(seed);
        env.reset().unwrap();
        let board = env.board();
        for (mv, target) in targets(layout, game.num_moves()) {
            if !game.changes(board, mv) {
                continue;
            }
            let made = run_skill(env.as_mut(), seed, |obs| {
                controller(layout, mv, target, obs)
            });
            assert_eq!(made, Some(mv), "{name}, seed {seed}: aiming at move {mv}");
        }
    }
}

/// Cursor: move straight to the target in steps of at most 0.2 and push on arrival.
fn cursor_controller(_: Layout, _: MoveId, target: [f64; 2], obs: &[f32]) -> [f32; 3] {
    let d = [target[0] - obs[0] as f64, target[1] - obs[1] as f64];
    let arrive = d[0].abs() <= 0.2 && d[1].abs() <= 0.2;
    [
        d[0].clamp(-0.2, 0.2) as f32,
        d[1].clamp(-0.2, 0.2) as f32,
        if arrive { 1.0 } else { -1.0 },
    ]
}

#[test]
fn cursor_produces_every_move() {
    for name in envs_of("-cursor") {
        check_all_moves(name, cursor_controller);
    }
}

/// Reacher: inverse kinematics to the target, a PD law on the joints (gains sized for the 0.04 s
/// control period), push when the fingertip is well inside the target's region and nearly still.
/// The centre field lies within the wrist's ±160° limit circle except at its corners, so there
/// the wrist is pressed against its soft limit and only the shoulder aims.
fn reacher_controller(
    layout: Layout,
    target_move: MoveId,
    target: [f64; 2],
    obs: &[f32],
) -> [f32; 3] {
    const L: f64 = 0.12;
    let (q, qd) = (
        [obs[0] as f64, obs[1] as f64],
        [obs[2] as f64, obs[3] as f64],
    );
    let p = [target[0] * 0.3 - 0.15, target[1] * 0.3 - 0.15];
    let wrap = |a: f64| a - (a / std::f64::consts::TAU).round() * std::f64::consts::TAU;
    let side = if q[1] >= 0.0 { 1.0 } else { -1.0 };
    let u = if p[0].hypot(p[1]) < 0.04 {
        // Aim the tip (at whatever radius the wrist gives) along the diagonal of the centre field.
        let direction = (1.0f64).atan2(1.0);
        let q1 = direction - (L * q[1].sin()).atan2(L + L * q[1].cos());
        [(1.0 * wrap(q1 - q[0]) - 0.1 * qd[0]).clamp(-1.0, 1.0), side]
    } else {
        let c2 = ((p[0] * p[0] + p[1] * p[1] - 2.0 * L * L) / (2.0 * L * L)).clamp(-1.0, 1.0);
        let q2 = c2.acos() * side;
        let q1 = p[1].atan2(p[0]) - (L * q2.sin()).atan2(L + L * q2.cos());
        [
            (1.0 * wrap(q1 - q[0]) - 0.1 * qd[0]).clamp(-1.0, 1.0),
            (1.0 * (q2 - q[1]) - 0.05 * qd[1]).clamp(-1.0, 1.0),
        ]
    };
    // Check the fingertip now and where it will be after the step (the push is evaluated there).
    let tip = |q: [f64; 2]| {
        let t = [
            L * q[0].cos() + L * (q[0] + q[1]).cos(),
            L * q[0].sin() + L * (q[0] + q[1]).sin(),
        ];
        ((t[0] + 0.15) / 0.3, (t[1] + 0.15) / 0.3)
    };
    let next = [q[0] + 0.04 * qd[0], q[1] + 0.04 * qd[1]];
    let inside = well_inside(layout, target_move, [tip(q), tip(next)]);
    // Far beyond ±160° the soft wrist limit yanks the arm back within the step: no push then
    // (slightly beyond is the resting pose of a wrist pressed against its limit).
    let still = qd[0].abs() + qd[1].abs() < 0.3 && q[1].abs() < 2.95;
    [
        u[0] as f32,
        u[1] as f32,
        if inside && still { 1.0 } else { -1.0 },
    ]
}

/// Whether every point (board coordinates: the fingertip now and after the next step, where
/// the push is evaluated) lies in the region of `target_move` with a margin of 0.01 all round.
fn well_inside(layout: Layout, target_move: MoveId, points: [(f64, f64); 2]) -> bool {
    let margin = 0.01;
    points.iter().all(|&(u, v)| {
        [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
            .iter()
            .all(|(du, dv)| layout.locate(u + du * margin, v + dv * margin) == Some(target_move))
    })
}

#[test]
fn reacher_produces_every_move() {
    for name in envs_of("-reacher") {
        check_all_moves(name, reacher_controller);
    }
}

/// Reacher3: inverse kinematics with the last link along a direction near the target's bearing
/// (the first of a few offsets, and elbow sides, that keeps both limited joints well inside
/// ±160°), a PD law on the three joints, and a push when the fingertip is well inside the
/// target's region and nearly still.
fn reacher3_controller(
    layout: Layout,
    target_move: MoveId,
    target: [f64; 2],
    obs: &[f32],
) -> [f32; 4] {
    const L: f64 = 0.08;
    use std::f64::consts::{PI, TAU};
    let q: [f64; 3] = std::array::from_fn(|i| obs[i] as f64);
    let qd: [f64; 3] = std::array::from_fn(|i| obs[3 + i] as f64);
    let wrap = |a: f64| a - (a / TAU).round() * TAU;
    let p = [target[0] * 0.3 - 0.15, target[1] * 0.3 - 0.15];
    let bearing = p[1].atan2(p[0]);
    let offsets = [0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5, 2.0, -2.0, PI];
    let goal = offsets
        .iter()
        .flat_map(|d| [1.0, -1.0].map(move |side| (bearing + d, side)))
        .find_map(|(phi, side): (f64, f64)| {
            let w = [p[0] - L * phi.cos(), p[1] - L * phi.sin()];
            let c2 = (w[0] * w[0] + w[1] * w[1] - 2.0 * L * L) / (2.0 * L * L);
            if c2.abs() > 1.0 {
                return None;
            }
            let q2 = side * c2.acos();
            let q1 = w[1].atan2(w[0]) - (L * q2.sin()).atan2(L + L * q2.cos());
            let q3 = wrap(phi - q1 - q2);
            (q2.abs() < 2.5 && q3.abs() < 2.5).then_some([q1, q2, q3])
        })
        .expect("every field and pivot of the board is within reach");
    let gains = [(1.0, 0.1), (1.0, 0.05), (1.0, 0.03)];
    let u: [f64; 3] = std::array::from_fn(|j| {
        let error = if j == 0 {
            wrap(goal[0] - q[0])
        } else {
            goal[j] - q[j]
        };
        (gains[j].0 * error - gains[j].1 * qd[j]).clamp(-1.0, 1.0)
    });
    let tip = |q: [f64; 3]| {
        let (mut angle, mut at) = (0.0, [0.0f64; 2]);
        for a in q {
            angle += a;
            at = [at[0] + L * angle.cos(), at[1] + L * angle.sin()];
        }
        ((at[0] + 0.15) / 0.3, (at[1] + 0.15) / 0.3)
    };
    let next: [f64; 3] = std::array::from_fn(|j| q[j] + 0.04 * qd[j]);
    let inside = well_inside(layout, target_move, [tip(q), tip(next)]);
    let still =
        qd.iter().map(|v| v.abs()).sum::<f64>() < 0.3 && q[1..].iter().all(|a| a.abs() < 2.95);
    let push = if inside && still { 1.0 } else { -1.0 };
    [u[0] as f32, u[1] as f32, u[2] as f32, push]
}

#[test]
fn reacher3_produces_every_move() {
    for name in envs_of("-reacher3") {
        check_all_moves(name, reacher3_controller);
    }
}

#[test]
fn a_push_off_every_pivot_is_a_miss_and_the_skill_continues() {
    let mut env = make_env("tileswap-cursor", &EnvConfig::default()).unwrap();
    env.seed(9);
    env.reset().unwrap();
    let before = env.board();
    // Move to the top-left corner (a dead zone) and push there.
    let mut outcome = env.step(&[-0.2, -0.2, -1.0]).unwrap();
    for _ in 0..4 {
        outcome = env.step(&[-0.2, -0.2, 1.0]).unwrap();
    }
    assert_eq!(outcome.push, Push::Miss);
    assert!(!outcome.done());
    assert_eq!(env.board(), before);
}
