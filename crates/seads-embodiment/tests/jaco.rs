//! Jaco: a scripted Cartesian controller with its own forward kinematics (transcribed from the
//! MJCF, independent of the environment's code) moves the tool centre point above a field or
//! pivot, points the hand down and descends until the press registers.
#![allow(clippy::approx_constant)] // the MJCF's rounded quaternion literals
#![allow(clippy::print_stderr)] // the full sweep reports its measured success
#![cfg(feature = "jaco")]

use rand::SeedableRng;
use rapier3d::math::{Rotation, Vector};
use rapier3d::na::{DMatrix, DVector};
use seads_embodiment::{
    EnvConfig, Environment, Jaco, JacoBoard, Layout, Manipulator, Push, SkillPolicy, Touch,
    execute_skill, make_env,
};
use seads_games::MoveId;

/// MJCF frames of b_1 … b_6: offset and (w, x, y, z) orientation relative to the parent.
const FRAMES: [([f32; 3], [f32; 4]); 6] = [
    ([0.0, 0.0, 0.15675], [0.0, 0.0, 1.0, 0.0]),
    ([0.0, 0.0016, -0.11875], [0.0, 0.0, -0.707107, 0.707107]),
    ([0.0, -0.41, 0.0], [0.0, 0.0, 1.0, 0.0]),
    ([0.0, 0.2073, -0.0114], [0.0, 0.0, -0.707107, 0.707107]),
    ([0.0, -0.03703, -0.06414], [0.0, 0.0, 0.5, 0.866025]),
    ([0.0, -0.03703, -0.06414], [0.0, 0.0, 0.5, 0.866025]),
];
const CTRL_MAX: [f32; 6] = [0.62832, 0.62832, 0.62832, 0.83776, 0.83776, 0.83776];

/// Tool centre point and hand z axis for arm joint angles `q`.
fn forward(q: &[f32; 6]) -> (Vector, Vector) {
    let (mut p, mut r) = (Vector::new(0.0, 0.4, 0.0), Rotation::IDENTITY);
    for (i, (pos, quat)) in FRAMES.iter().enumerate() {
        p += r * Vector::from_array(*pos);
        r = r
            * Rotation::from_xyzw(quat[1], quat[2], quat[3], quat[0]).normalize()
            * Rotation::from_rotation_z(q[i]);
    }
    (p + r * Vector::new(0.0, -0.0001, -0.159), r * Vector::Z)
}

/// Joint angles from the observation's (sin, cos) pairs.
fn angles(obs: &[f32]) -> [f32; 6] {
    std::array::from_fn(|j| obs[2 * j].atan2(obs[2 * j + 1]))
}

/// Damped least squares on [position (3), hand z axis x/y (2)]: joint velocities towards `target`.
fn controller(target: Vector, obs: &[f32]) -> Vec<f32> {
    let q = angles(obs);
    let task = |q: &[f32; 6]| {
        let (p, z) = forward(q);
        [p.x, p.y, p.z, z.x, z.y]
    };
    let now = task(&q);
    let goal = [target.x, target.y, target.z, 0.0, 0.0];
    let mut jac = DMatrix::<f32>::zeros(5, 6);
    for j in 0..6 {
        let mut qq = q;
        qq[j] += 1e-3;
        let t = task(&qq);
        for r in 0..5 {
            jac[(r, j)] = (t[r] - now[r]) / 1e-3;
        }
    }
    let err = DVector::from_iterator(5, (0..5).map(|r| (goal[r] - now[r]) * 3.0));
    let jjt = &jac * jac.transpose() + DMatrix::identity(5, 5) * 0.01;
    let qd = jac.transpose() * jjt.lu().solve(&err).expect("damped system is regular");
    let mut action: Vec<f32> = (0..6)
        .map(|j| (qd[j] / CTRL_MAX[j]).clamp(-1.0, 1.0))
        .collect();
    action.extend([1.0; 3]); // close the hand: open fingers splay ±9 cm and would press neighbours
    action
}

/// Aims at board point `target` (world x, y): above it first, then down. Returns the move made
/// and where the path ends (after a move, the touch on the board: `Environment::move_point`).
fn press(
    env: &mut dyn Environment,
    seed: u64,
    target: [f32; 2],
    top: f32,
) -> (Option<MoveId>, [f64; 2]) {
    env.seed(seed);
    env.reset().unwrap();
    let run = execute_skill(env, &Reach::new(target, top), 0).unwrap();
    (run.outcome.game_move(), run.path[run.steps])
}

/// The scripted reach as a one-skill policy: towards board point `target` (world x, y) at a
/// field top `top`, approaching from above, then descending (and staying so) once over it.
struct Reach {
    target: [f32; 2],
    top: f32,
    descending: std::cell::Cell<bool>,
}

impl Reach {
    fn new(target: [f32; 2], top: f32) -> Self {
        Self {
            target,
            top,
            descending: std::cell::Cell::new(false),
        }
    }
}

impl SkillPolicy for Reach {
    fn num_skills(&self) -> usize {
        1
    }

    fn act(&self, observations: &[f32], _skills: &[usize], actions: &mut [f32]) {
        let (tcp, _) = forward(&angles(observations));
        let over = (tcp.x - self.target[0]).hypot(tcp.y - self.target[1]) < 0.02;
        self.descending.set(self.descending.get() || over);
        let z = if self.descending.get() {
            (tcp.z - 0.05).max(self.top - 0.05)
        } else {
            self.top + 0.10
        };
        let goal = Vector::new(self.target[0], self.target[1], z);
        actions.copy_from_slice(&controller(goal, observations));
    }
}

/// The arm is re-initialised within the step of a move (as in the reference), so the end
/// effector after that step is the new pose; a skill's path (the skill figures) ends where the
/// move was made, at the touch on the pressed field (the reference's contact mark), not at the
/// new pose.
#[test]
fn a_skill_path_ends_at_the_press_not_at_the_re_initialised_arm() {
    let mut env = make_env("lightsout-jaco", &EnvConfig::default()).unwrap();
    env.seed(1);
    env.reset().unwrap();
    // Field 0 (row 0, column 0) is centred at world (-0.2, 0.2): board coordinates (0.1, 0.1),
    // fields 0.2 wide in board units.
    let run = execute_skill(env.as_mut(), &Reach::new([-0.2, 0.2], 0.02), 0).unwrap();
    assert_eq!(run.outcome.game_move(), Some(0), "{:?}", run.outcome);
    assert_eq!(run.pushes.last(), Some(&run.steps));
    let field = [0.1, 0.1];
    let distance = |p: [f64; 2]| (p[0] - field[0]).hypot(p[1] - field[1]);
    let end = run.path[run.steps];
    assert_eq!(env.move_point(), Some(end));
    // It ends where the hand touched the field: inside its touch sensor (70 % of the field's
    // 0.2 board units).
    assert!(
        (end[0] - field[0]).abs() <= 0.07 && (end[1] - field[1]).abs() <= 0.07,
        "the path ends at {end:?}, off the pressed field's sensor"
    );
    // The re-initialised arm stands above the board's middle (TCP within ±0.1 m of its centre).
    let now = env.end_effector();
    assert!(
        distance(now) > 0.15,
        "the arm was not re-initialised: {now:?}"
    );
    // A step without a move has no move point.
    env.reset_step_counter();
    env.step(&[0.0; 9]).unwrap();
    assert_eq!(env.move_point(), None);
}

/// The scene reports the fields' heights: LightsOut3DJaco's rise from the centre (2, 6 and
/// 10 cm tops: half-heights 1, 3 and 5 cm by Chebyshev distance), the flat board's are equal.
#[test]
fn scenes_carry_the_fields_heights() {
    let heights = |name: &str| -> Vec<f64> {
        let env = make_env(name, &EnvConfig::default()).unwrap();
        env.scene().fields.iter().map(|f| f.height).collect()
    };
    let stairs = heights("lightsout3d-jaco");
    assert_eq!(stairs.len(), 25);
    for (i, h) in stairs.iter().enumerate() {
        let ring = (i / 5).abs_diff(2).max((i % 5).abs_diff(2));
        let expected = [0.02, 0.06, 0.10][ring];
        assert!(
            (h - expected).abs() < 1e-6,
            "field {i}: {h} m, expected {expected}"
        );
    }
    assert!(
        heights("lightsout-jaco")
            .iter()
            .all(|&h| (h - 0.02).abs() < 1e-6)
    );
}

/// Physics steps per 0.1 s environment step compared with the reference: its own 50 (2 ms), and
/// the 25 (4 ms) the Jaco presets train with, which must follow the reference as closely.
const SUBSTEPS: [usize; 2] = [50, 25];

/// The recorded reference episodes (`data/reference/jaco/`, written by
/// `scripts/reference/jaco_record.py` from the authors' environments in MuJoCo), with our board
/// for each.
fn references() -> Vec<(&'static str, JacoBoard, serde_json::Value)> {
    [
        ("lightsout", JacoBoard::LightsOut { stairs: false }),
        ("lightsout3d", JacoBoard::LightsOut { stairs: true }),
        ("tileswap", JacoBoard::TileSwap),
    ]
    .into_iter()
    .map(|(name, board)| {
        let path = format!(
            "{}/../../data/reference/jaco/{name}_jaco.json",
            env!("CARGO_MANIFEST_DIR")
        );
        let text = std::fs::read_to_string(&path).unwrap();
        (name, board, serde_json::from_str(&text).unwrap())
    })
    .collect()
}

fn floats(v: &serde_json::Value) -> Vec<f32> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() as f32)
        .collect()
}

/// At every recorded joint configuration, the kinematic chain transcribed here (and tied to the
/// environment's own by the test below) puts the tool centre point where MuJoCo's grip site is,
/// in the same world frame (board centre at the origin, fields 10 cm apart).
#[test]
fn forward_kinematics_matches_the_reference_simulation() {
    let mut worst = 0.0f32;
    let mut checked = 0;
    for (name, _, data) in references() {
        // The fields' centres (a site each; TileSwap's board has one site, at its centre) lie on
        // our grid: 10 cm apart around the origin. (LightsOut3D lists them column by column, and
        // numbers its fields so: `Layout::ColumnMajor`.)
        let sites: Vec<Vec<f32>> = data["field_sites"]
            .as_array()
            .unwrap()
            .iter()
            .map(floats)
            .collect();
        let side = (sites.len() as f64).sqrt().round() as usize;
        assert_eq!(side * side, sites.len(), "{name}");
        let centre = (side - 1) as f32 / 2.0;
        for row in 0..side {
            for col in 0..side {
                let (x, y) = ((col as f32 - centre) * 0.1, (centre - row as f32) * 0.1);
                assert!(
                    sites
                        .iter()
                        .any(|p| (p[0] - x).abs() < 1e-5 && (p[1] - y).abs() < 1e-5),
                    "{name}: no field centre at ({x}, {y})"
                );
            }
        }
        for episode in data["episodes"].as_array().unwrap() {
            for step in episode["steps"].as_array().unwrap() {
                let q = floats(&step["qpos"]);
                let grip = floats(&step["grip"]);
                let (tcp, _) = forward(&[q[0], q[1], q[2], q[3], q[4], q[5]]);
                worst = worst.max((tcp - Vector::new(grip[0], grip[1], grip[2])).length());
                checked += 1;
            }
        }
    }
    assert!(checked >= 5000, "{checked} configurations");
    // Measured: 1.2 µm at worst (the data has 6 decimals, 1 µm). 10 µm is float tolerance.
    assert!(
        worst < 1e-5,
        "worst tool-centre-point error {worst} m over {checked} configurations"
    );
}

/// Our Jaco from the reference's reset pose under the reference's actions follows MuJoCo's
/// arm-joint trajectory within 0.01 rad over the first 5 steps (0.5 s) and 0.03 rad over the
/// first 10 of every recorded episode on every board (up to a press, after which the reference
/// re-initialises its arm). Later some trajectories part, mostly while the hand touches the
/// board (numbers in docs/RESULTS.md; `--nocapture` prints them).
#[test]
fn joint_trajectories_follow_the_reference_simulation() {
    for substeps in SUBSTEPS {
        joint_trajectories_follow_the_reference_simulation_at(substeps);
    }
}

fn joint_trajectories_follow_the_reference_simulation_at(substeps: usize) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    for (name, board, data) in references() {
        // Worst arm-joint error so far (radians, wrapped) after 1, 5, 10, 20, 50 steps, per kind.
        let horizons = [1usize, 5, 10, 20, 50];
        let mut worst = [[0.0f32; 5]; 2];
        let mut within_at_end = [0usize; 2];
        let mut episodes = [0usize; 2];
        for episode in data["episodes"].as_array().unwrap() {
            let kind = usize::from(episode["kind"] == "constant");
            episodes[kind] += 1;
            let q0 = floats(&episode["qpos0"]);
            let mut jaco = Jaco::new(board, substeps);
            jaco.set_joint_positions(&q0.clone().try_into().unwrap());
            let mut error_so_far = 0.0f32;
            for (t, step) in episode["steps"].as_array().unwrap().iter().enumerate() {
                if step["pressed"].as_i64() != Some(-1) {
                    // A press ends the reference's episode and re-initialises its arm within the
                    // step: the recorded joints after it are the new pose, not the trajectory.
                    break;
                }
                let mut touch = |_: Touch| Push::None;
                assert!(jaco.step(&floats(&step["action"]), &mut rng, &mut touch));
                let (q, _) = jaco.joints();
                let theirs = floats(&step["qpos"]);
                for j in 0..6 {
                    let d = (q[j] - theirs[j]).rem_euclid(std::f32::consts::TAU);
                    error_so_far = error_so_far.max(d.min(std::f32::consts::TAU - d));
                }
                for (h, &horizon) in horizons.iter().enumerate() {
                    if t < horizon {
                        worst[kind][h] = worst[kind][h].max(error_so_far);
                    }
                }
            }
            within_at_end[kind] += usize::from(error_so_far < 0.05);
        }
        for (kind, actions) in ["random actions", "held commands"].iter().enumerate() {
            let w = worst[kind];
            eprintln!(
                "{name}-jaco ({substeps} substeps) vs reference, {actions}: worst arm-joint error after 1/5/10/20/50 steps: {:.4} / {:.4} / {:.4} / {:.4} / {:.4} rad; {} of {} episodes within 0.05 rad to their end",
                w[0], w[1], w[2], w[3], w[4], within_at_end[kind], episodes[kind]
            );
            // Measured worst: 0.0031 after 5 steps, 0.026 after 10 (LightsOut3D, held commands).
            assert!(w[1] < 0.01 && w[2] < 0.03, "{name}, {actions}: {w:?}");
        }
    }
}

/// Presses under the reference's actions on the LightsOut boards: on how many steps our Jaco
/// presses the same field as MuJoCo's (or, like it, none), and which of the reference's presses
/// it reproduces. (TileSwap: `tileswap_touches_agree_with_the_reference_simulation`.)
#[test]
fn presses_agree_with_the_reference_simulation() {
    for substeps in SUBSTEPS {
        presses_agree_with_the_reference_simulation_at(substeps);
    }
}

fn presses_agree_with_the_reference_simulation_at(substeps: usize) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    for (name, board, data) in references() {
        if name == "tileswap" {
            continue;
        }
        let (mut steps, mut agree) = (0usize, 0usize);
        let mut reference_presses = Vec::new();
        // The board's own numbering of the fields, as the environment resolves touches.
        let layout = if name == "lightsout3d" {
            Layout::ColumnMajor { n: 5 }
        } else {
            Layout::Grid { n: 5 }
        };
        for episode in data["episodes"].as_array().unwrap() {
            let q0 = floats(&episode["qpos0"]);
            let mut jaco = Jaco::new(board, substeps);
            jaco.set_joint_positions(&q0.clone().try_into().unwrap());
            for (t, step) in episode["steps"].as_array().unwrap().iter().enumerate() {
                let mut ours: i64 = -1;
                let mut touch = |touch: Touch| {
                    if let (Touch::Field(index), -1) = (touch, ours) {
                        ours = layout.field_move(index).unwrap() as i64;
                    }
                    Push::None
                };
                assert!(jaco.step(&floats(&step["action"]), &mut rng, &mut touch));
                let theirs = step["pressed"].as_i64().unwrap();
                steps += 1;
                agree += usize::from(ours == theirs);
                if theirs >= 0 {
                    reference_presses.push((episode["seed"].as_u64().unwrap(), t, theirs, ours));
                }
            }
        }
        let fraction = agree as f64 / steps as f64;
        let reproduced = reference_presses.iter().filter(|p| p.2 == p.3).count();
        eprintln!(
            "{name}-jaco ({substeps} substeps) vs reference: the same press (or none) on {agree} of {steps} steps ({:.1} %); {reproduced} of its {} presses reproduced (episode, step, field, ours): {reference_presses:?}",
            100.0 * fraction,
            reference_presses.len()
        );
        assert!(!reference_presses.is_empty(), "{name}");
        if name == "lightsout" {
            // Measured: 99.8 %; 3 of 4 (the press in episode 12 is not registered by ours).
            // FIXME: both thresholds are that one measurement (commit 6e914d6's physics, on the
            // reference's recorded actions), not a tolerance derived from how far two correct
            // simulations may drift apart; a change of rapier's version may cross them.
            assert!(fraction > 0.99, "{name}: {fraction}");
            assert!(
                4 * reproduced >= 3 * reference_presses.len(),
                "{name}: {reference_presses:?}"
            );
        } else {
            // Measured: 97.7 % of steps, 3 of 10 presses (none before the reference's column-by-
            // column numbering was followed). The misses come where our hand makes no contact in
            // the press step, most after the joints have drifted by 0.02–0.09 rad (docs/RESULTS.md).
            // FIXME: as above, these thresholds are that one measurement, not a derived tolerance.
            assert!(fraction > 0.97, "{name}: {fraction}");
            assert!(reproduced >= 3, "{name}: {reference_presses:?}");
        }
    }
}

/// TileSwap's presses under the reference's actions: the touch (a position on the board, which
/// the layout turns into a swap) on the same steps, at the same place.
#[test]
fn tileswap_touches_agree_with_the_reference_simulation() {
    for substeps in SUBSTEPS {
        tileswap_touches_agree_with_the_reference_simulation_at(substeps);
    }
}

fn tileswap_touches_agree_with_the_reference_simulation_at(substeps: usize) {
    let (_, board, data) = references()
        .into_iter()
        .find(|(name, _, _)| *name == "tileswap")
        .unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let (mut steps, mut agree) = (0usize, 0usize);
    let mut touches = Vec::new();
    for episode in data["episodes"].as_array().unwrap() {
        let q0 = floats(&episode["qpos0"]);
        let mut jaco = Jaco::new(board, substeps);
        jaco.set_joint_positions(&q0.clone().try_into().unwrap());
        for step in episode["steps"].as_array().unwrap() {
            let mut ours: Option<[f64; 2]> = None;
            let mut touch = |touch: Touch| {
                if let (Touch::At { u, v }, None) = (touch, ours) {
                    ours = Some([u, v]);
                }
                Push::None
            };
            assert!(jaco.step(&floats(&step["action"]), &mut rng, &mut touch));
            let theirs = step["contact"]
                .as_array()
                .map(|c| [c[0].as_f64().unwrap(), c[1].as_f64().unwrap()]);
            steps += 1;
            let same = match (ours, theirs) {
                (None, None) => true,
                (Some(a), Some(b)) => (a[0] - b[0]).hypot(a[1] - b[1]) < 0.05,
                _ => false,
            };
            agree += usize::from(same);
            if theirs.is_some() {
                touches.push((episode["seed"].as_u64().unwrap(), theirs, ours));
            }
        }
    }
    let fraction = agree as f64 / steps as f64;
    eprintln!(
        "tileswap-jaco ({substeps} substeps) vs reference: the same touch (within 5 % of the board) or none on {agree} of {steps} steps ({:.1} %); the reference's touches (episode, theirs, ours): {touches:?}",
        100.0 * fraction
    );
    assert!(!touches.is_empty());
    // Measured: 99.2 %; both reference touches reproduced. The reference reports only touches
    // inside a swap region, ours every touch of the board, which accounts for the rest.
    assert!(fraction > 0.99, "{fraction}");
    assert!(
        touches.iter().all(|(_, t, o)| o.is_some_and(|o| {
            let t = t.expect("a reference touch");
            (o[0] - t[0]).hypot(o[1] - t[1]) < 0.05
        })),
        "{touches:?}"
    );
}

#[test]
fn forward_kinematics_matches_the_observed_pinch_site() {
    let mut env = make_env("lightsout-jaco", &EnvConfig::default()).unwrap();
    for seed in 0..3 {
        env.seed(seed);
        env.reset().unwrap();
        let obs = env.observation();
        let (tcp, z) = forward(&angles(&obs));
        // Reset puts the tool in the box above the board, pointing down.
        assert!(
            tcp.x.abs() <= 0.11 && tcp.y.abs() <= 0.11 && (0.19..=0.41).contains(&tcp.z),
            "seed {seed}: {tcp:?}"
        );
        assert!(z.z > 0.95, "hand axis {z:?}");
        // The pinch site is 3.4 cm beyond the grip site along the tool axis.
        let pinch = Vector::new(obs[30], obs[31], obs[32]);
        assert!(
            (pinch - tcp).length() < 0.05 && pinch.z < tcp.z,
            "{pinch:?} vs {tcp:?}"
        );
    }
}

/// Presses every move in `moves` from every seed; returns the failures.
fn sweep(name: &str, substeps: usize, seeds: &[u64], moves: &[MoveId]) -> Vec<String> {
    let mut config = EnvConfig::default();
    config
        .manipulator
        .insert("physics_substeps".into(), substeps.into());
    let mut env = make_env(name, &config).unwrap();
    let n = env.spec().board_size;
    let mut failures = Vec::new();
    for &seed in seeds {
        for &mv in moves {
            let (target, top) = match n {
                5 => {
                    // LightsOut3D numbers its fields column by column (`Layout::ColumnMajor`).
                    let stairs = name.starts_with("lightsout3d");
                    let (row, col) = if stairs {
                        (mv % 5, mv / 5)
                    } else {
                        (mv / 5, mv % 5)
                    };
                    let ring = row.abs_diff(2).max(col.abs_diff(2));
                    let top = if stairs {
                        [0.02, 0.06, 0.10][ring]
                    } else {
                        0.02
                    };
                    ([(col as f32 - 2.0) * 0.1, (2.0 - row as f32) * 0.1], top)
                }
                _ => {
                    let (u, v) = Layout::Pivots
                        .pivots()
                        .into_iter()
                        .find(|&(u, v)| Layout::Pivots.locate(u, v) == Some(mv))
                        .unwrap();
                    ([u as f32 * 0.3 - 0.15, (1.0 - v as f32) * 0.3 - 0.15], 0.02)
                }
            };
            let (made, at) = press(env.as_mut(), seed, target, top);
            if made != Some(mv) {
                failures.push(format!("seed {seed}: aimed at {mv}, made {made:?}"));
            }
            // The point a skill figure marks is the touch that made the move: it lies on the
            // pressed field (LightsOut, inside its sensor, 70 % of the field) or within reach of
            // the swapped pivot (TileSwap), as the reference's contact marks do.
            let layout = match name {
                "tileswap-jaco" => Layout::Pivots,
                "lightsout3d-jaco" => Layout::ColumnMajor { n: 5 },
                _ => Layout::Grid { n: 5 },
            };
            if made.is_some() && layout.locate(at[0], at[1]) != made {
                failures.push(format!(
                    "seed {seed}: made {made:?}, but the path ends at {at:?}, off that move"
                ));
            }
        }
    }
    failures
}

fn check(name: &str, seeds: &[u64], moves: &[MoveId]) {
    for substeps in SUBSTEPS {
        let failures = sweep(name, substeps, seeds, moves);
        assert!(
            failures.is_empty(),
            "{name} ({substeps} substeps): {} of {} presses failed: {failures:?}",
            failures.len(),
            seeds.len() * moves.len()
        );
    }
}

/// CI: a few moves of each Jaco environment.
#[test]
fn jaco_presses_fields_and_pivots() {
    check("lightsout-jaco", &[1], &[0, 12, 24]);
    check("tileswap-jaco", &[1], &[2, 7]);
    check("lightsout3d-jaco", &[1], &[6]);
}

/// Every move of every Jaco environment on several seeds (minutes), built only when switched on:
/// `SEADS_TEST_JACO_FULL=1 cargo test --release -p seads-embodiment --test jaco full_sweep`.
#[cfg(seads_test_jaco_full)]
#[test]
fn jaco_produces_every_move_full_sweep() {
    // The scripted controller is simple: on the 3-D board the raised outer ring sometimes blocks
    // the hand above an inner field within the 50 steps. Measured: see the closing note.
    let seeds: Vec<u64> = (1..=10).collect();
    for (name, k) in [
        ("lightsout-jaco", 25),
        ("lightsout3d-jaco", 25),
        ("tileswap-jaco", 12),
    ] {
        for substeps in SUBSTEPS {
            let failures = sweep(name, substeps, &seeds, &(0..k).collect::<Vec<_>>());
            eprintln!(
                "{name} ({substeps} substeps): {} of {} presses made the intended move",
                seeds.len() * k - failures.len(),
                seeds.len() * k
            );
            assert!(
                failures.len() * 100 <= seeds.len() * k,
                "{name} ({substeps} substeps): more than 1 % failed: {failures:?}"
            );
        }
    }
}

/// Random initial poses are found by inverse kinematics; the fixed fallback pose is counted
/// (issue 13: it was used uncounted). Over 200 seeded resets of each board it is never needed.
#[test]
fn initial_poses_need_no_fallback() {
    use rand::SeedableRng;
    use seads_embodiment::{Jaco, JacoBoard, Manipulator};
    for board in [
        JacoBoard::LightsOut { stairs: false },
        JacoBoard::LightsOut { stairs: true },
        JacoBoard::TileSwap,
    ] {
        let mut arm = Jaco::new(board, 1);
        for seed in 0..200 {
            arm.reset(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
        }
        assert_eq!(arm.ik_fallbacks(), 0, "{board:?}");
    }
}

/// The two-sample Kolmogorov–Smirnov statistic: the largest gap between the empirical CDFs.
fn ks_statistic(a: &[f64], b: &[f64]) -> f64 {
    let cdf = |xs: &[f64], x: f64| xs.iter().filter(|&&v| v <= x).count() as f64 / xs.len() as f64;
    a.iter()
        .chain(b)
        .map(|&x| (cdf(a, x) - cdf(b, x)).abs())
        .fold(0.0, f64::max)
}

/// Reset poses: our random initial pinch-site positions and the reference's (its 40 recorded
/// resets; the three boards share them) come from the same distribution, coordinate by
/// coordinate (two-sample Kolmogorov–Smirnov at α = 0.001).
#[test]
fn reset_poses_are_distributed_as_the_references() {
    // The statistic by hand: equal samples 0, disjoint ones 1, [0, 1, 2] against [1, 2, 3] 1/3.
    assert_eq!(ks_statistic(&[1.0, 2.0], &[1.0, 2.0]), 0.0);
    assert_eq!(ks_statistic(&[0.0, 1.0], &[2.0, 3.0]), 1.0);
    assert!((ks_statistic(&[0.0, 1.0, 2.0], &[1.0, 2.0, 3.0]) - 1.0 / 3.0).abs() < 1e-12);
    let (_, _, data) = references().into_iter().next().unwrap();
    let theirs: Vec<Vec<f32>> = data["episodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| floats(&e["pinch0"]))
        .collect();
    let mut env = make_env("lightsout-jaco", &EnvConfig::default()).unwrap();
    let ours: Vec<[f32; 3]> = (0..200)
        .map(|seed| {
            env.seed(seed);
            env.reset().unwrap();
            let obs = env.observation();
            [obs[30], obs[31], obs[32]]
        })
        .collect();
    let (n, m) = (ours.len() as f64, theirs.len() as f64);
    // Critical value of the two-sample test at α = 0.001: 1.95·√((n + m)/(n·m)).
    let critical = 1.95 * ((n + m) / (n * m)).sqrt();
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        let a: Vec<f64> = ours.iter().map(|p| f64::from(p[axis])).collect();
        let b: Vec<f64> = theirs.iter().map(|p| f64::from(p[axis])).collect();
        let d = ks_statistic(&a, &b);
        eprintln!("reset pinch site {name}: KS distance {d:.3} (critical {critical:.3})");
        assert!(d < critical, "{name}: D = {d} ≥ {critical}");
    }
}
