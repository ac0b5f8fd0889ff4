//! The driver, the calibration and the environment end to end on the simulated twin, faults
//! included: every failure is a clear error, and the pen is left at hover height.

use seads_embodiment::{EnvError, Environment, Push, record_episode, replay_episode};
use seads_games::{BoardGame, LightsOut};
use seads_uarm::{
    ActionSpace, Calibration, CalibrationFile, DriverConfig, Faults, Observation, RobotSettings,
    Swift, Twin, TwinNoise, UarmConfig, UarmEnv, UarmError, twin_screen_corners,
};

fn driver(twin: &Twin) -> Swift {
    Swift::new(
        twin.transport(),
        DriverConfig {
            ack_timeout: std::time::Duration::from_millis(50),
            ..DriverConfig::default()
        },
    )
}

/// Calibrates the way a person does with the twin: detach, place the pen on each corner by
/// hand, read the position.
fn calibrate(twin: &Twin) -> Calibration {
    let mut arm = driver(twin);
    arm.detach().unwrap();
    let mut corners = [[0.0; 3]; 4];
    for (i, corner) in twin_screen_corners().iter().enumerate() {
        twin.move_by_hand(*corner);
        corners[i] = arm.position().unwrap();
    }
    arm.attach().unwrap();
    Calibration::fit(CalibrationFile {
        corners,
        d_max_mm: 100.0,
    })
    .unwrap()
}

fn env(twin: &Twin, space: ActionSpace) -> UarmEnv {
    env_with(twin, space, true)
}

fn env_with(twin: &Twin, space: ActionSpace, reset_board: bool) -> UarmEnv {
    let config = UarmConfig {
        action_space: space,
        step_limit: if space == ActionSpace::Absolute {
            1
        } else {
            10
        },
        tap_timeout_s: 0.0,
        reset_board,
        ..UarmConfig::default()
    };
    UarmEnv::new(driver(twin), twin.tablet(), calibrate(twin), config).unwrap()
}

#[test]
fn driver_moves_reads_and_recovers_from_noise() {
    let twin = Twin::new(1);
    let mut arm = driver(&twin);
    arm.attach().unwrap();
    arm.move_to([200.0, 10.0, 80.0]).unwrap();
    let p = arm.position().unwrap();
    assert!((p[0] - 200.0).abs() < 0.01 && (p[2] - 80.0).abs() < 0.01);
    twin.inject(Faults {
        garble_at: Some(1),
        ..Faults::default()
    });
    arm.move_to([210.0, 0.0, 90.0]).unwrap();
    assert!(
        arm.skipped_lines() >= 2,
        "a garbled line and a stale reply were skipped"
    );
    assert_eq!(twin.pen(), [210.0, 0.0, 90.0]);
}

#[test]
fn driver_faults_are_clear_errors() {
    let twin = Twin::new(2);
    let mut arm = driver(&twin);
    twin.inject(Faults {
        silent_at: Some(1),
        ..Faults::default()
    });
    assert!(matches!(arm.command("M17"), Err(UarmError::Timeout { .. })));
    // The late line of a timed-out command would not confuse the next one.
    arm.attach().unwrap();
    twin.inject(Faults {
        bad_reply_at: Some(1),
        ..Faults::default()
    });
    assert!(matches!(
        arm.move_to([200.0, 0.0, 50.0]),
        Err(UarmError::CommandFailed { code: 22, .. })
    ));
    twin.inject(Faults {
        bad_reply_at: Some(1),
        ..Faults::default()
    });
    assert!(matches!(arm.position(), Err(UarmError::Protocol(_))));
    twin.inject(Faults {
        disconnect_at: Some(1),
        ..Faults::default()
    });
    assert!(matches!(arm.position(), Err(UarmError::Disconnected)));
    assert!(matches!(arm.attach(), Err(UarmError::Disconnected)));
    // Refused before anything is sent, so not a disconnect.
    assert!(matches!(
        arm.move_to([f64::NAN, 0.0, 0.0]),
        Err(UarmError::Protocol(_))
    ));
}

#[test]
fn calibration_from_the_twin_recovers_its_screen() {
    let twin = Twin::new(3);
    let cal = calibrate(&twin);
    for (i, &(x, y)) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .iter()
        .enumerate()
    {
        let p = cal.to_arm(x, y, 0.0);
        let c = twin_screen_corners()[i];
        assert!(
            (0..3).all(|k| (p[k] - c[k]).abs() < 0.02),
            "corner {i}: {p:?} vs {c:?}"
        );
    }
}

#[test]
fn absolute_pushes_press_the_field_under_the_pen() {
    let twin = Twin::new(4);
    let mut env = env(&twin, ActionSpace::Absolute);
    let game = LightsOut::new(5).unwrap();
    env.seed(5);
    for field in 0..25 {
        env.reset().unwrap();
        let before = env.board();
        let (x, y) = (
            (field % 5) as f32 * 0.2 + 0.1,
            (field / 5) as f32 * 0.2 + 0.1,
        );
        let out = env.step(&[x, y]).unwrap();
        assert_eq!(out.push, Push::Move(field));
        assert!(out.done() && out.truncated);
        assert_eq!(env.board(), game.apply(before, field));
        assert_eq!(twin.board(), env.board());
        assert!(
            (twin.pen_height_mm() - 20.0).abs() < 0.01,
            "back at hover height"
        );
    }
}

#[test]
fn displacements_move_and_press_like_the_cursor() {
    let twin = Twin::new(6);
    let mut env = env(&twin, ActionSpace::Displacement);
    env.seed(1);
    env.reset().unwrap();
    env.restore_manipulator(&[0.5, 0.5]).unwrap();
    let before = env.board();
    let out = env.step(&[0.2, 0.0, -1.0]).unwrap();
    assert_eq!(out.push, Push::None);
    assert_eq!(env.observation()[..2], [0.7, 0.5]);
    assert!((twin.pen_height_mm() - 30.0).abs() < 0.01);
    let out = env.step(&[0.0, 0.0, 1.0]).unwrap();
    assert_eq!(out.push, Push::Move(13));
    assert_eq!(env.board(), LightsOut::new(5).unwrap().apply(before, 13));
}

/// The paper's protocol (SPEC §7.3): an episode starts where the previous one ended, board and
/// pen alike; with `reset_board` the twin draws both anew.
#[test]
fn the_papers_protocol_resets_neither_board_nor_pen() {
    let game = LightsOut::new(5).unwrap();
    for reset_board in [false, true] {
        let twin = Twin::new(8);
        let mut env = env_with(&twin, ActionSpace::Displacement, reset_board);
        env.seed(2);
        env.reset().unwrap();
        let (mut kept_board, mut kept_pen) = (0, 0);
        for episode in 0..20 {
            // Press somewhere new in every episode, so that the board and pen change.
            let x = 0.1 + 0.2 * (episode % 5) as f32;
            env.restore_manipulator(&[x, 0.5]).unwrap();
            let pressed = game.apply(env.board(), 10 + episode % 5);
            assert_eq!(
                env.step(&[0.0, 0.0, 1.0]).unwrap().push,
                Push::Move(10 + episode % 5)
            );
            assert_eq!(env.board(), pressed);
            let (board, pen) = (env.board(), twin.pen());
            env.reset().unwrap();
            kept_board += usize::from(env.board() == board);
            kept_pen += usize::from(twin.pen() == pen && env.observation()[0] == x);
            assert_eq!(twin.board(), env.board());
        }
        if reset_board {
            assert!(kept_board <= 2 && kept_pen == 0, "{kept_board} {kept_pen}");
        } else {
            assert_eq!((kept_board, kept_pen), (20, 20));
        }
    }
}

/// An error and its sources, as the CLI prints them.
fn chain(err: impl std::error::Error + Send + Sync + 'static) -> String {
    format!("{:#}", anyhow::Error::from(err))
}

/// A reset that cannot move the arm is an error (issue 13: resets swallowed hardware errors).
#[test]
fn a_failed_reset_is_an_error() {
    let twin = Twin::new(7);
    let mut env = env(&twin, ActionSpace::Absolute);
    env.seed(2);
    twin.inject(Faults {
        disconnect_at: Some(1),
        ..Faults::default()
    });
    let err = env.reset().unwrap_err();
    assert!(matches!(err, EnvError::Hardware { .. }), "{err}");
    let text = chain(err);
    assert!(text.contains("disconnected"), "{text}");
}

#[test]
fn faults_mid_move_end_in_an_error_with_the_pen_lifted() {
    let twin = Twin::new(7);
    let mut env = env(&twin, ActionSpace::Absolute);
    env.seed(2);
    env.reset().unwrap();
    // The press is commanded but its acknowledgement never comes.
    twin.inject(Faults {
        silent_at: Some(3),
        ..Faults::default()
    });
    let err = env.step(&[0.5, 0.5]).unwrap_err();
    assert!(matches!(err, EnvError::Hardware { .. }), "{err}");
    let text = chain(err);
    assert!(text.contains("did not answer"), "{text}");
    assert!(
        (twin.pen_height_mm() - 20.0).abs() < 0.01,
        "the pen is lifted to hover height"
    );
    // A malformed reply to a position request.
    env.reset_step_counter();
    twin.inject(Faults {
        bad_reply_at: Some(2),
        ..Faults::default()
    });
    assert!(matches!(
        env.step(&[0.3, 0.3]),
        Err(EnvError::Hardware { .. })
    ));
    // A disconnect: an error, no panic, and the environment stays usable for the caller.
    env.reset_step_counter();
    twin.inject(Faults {
        disconnect_at: Some(1),
        ..Faults::default()
    });
    let err = env.step(&[0.3, 0.3]).unwrap_err();
    let text = chain(err);
    assert!(text.contains("disconnected"), "{text}");
    twin.reconnect();
    env.reset_step_counter();
    assert!(env.step(&[0.9, 0.9]).is_ok());
    assert!(matches!(
        env.step(&[0.0]),
        Err(EnvError::ActionLength { .. })
    ));
}

#[test]
fn the_simulated_arm_records_and_replays_exactly() {
    let twin = Twin::new(8);
    let mut env = env(&twin, ActionSpace::Displacement);
    env.seed(3);
    let mut k = 0.0f32;
    let recorded = record_episode(&mut env, 40, |_, a| {
        k += 1.0;
        a.copy_from_slice(&[
            0.15 * k.sin(),
            0.12 * k.cos(),
            if (k as usize).is_multiple_of(4) {
                1.0
            } else {
                -1.0
            },
        ]);
    })
    .unwrap();
    assert!(recorded.steps.iter().any(|s| s.game_move.is_some()));
    env.reset().unwrap();
    let replayed = replay_episode(&mut env, &recorded).unwrap();
    assert_eq!(replayed, recorded);
}

#[test]
fn a_solving_press_leaves_the_solved_board() {
    let twin = Twin::new(9);
    let mut env = env(&twin, ActionSpace::Absolute);
    let game = LightsOut::new(5).unwrap();
    env.set_board(game.apply(game.goal(), 7)).unwrap();
    let out = env.step(&[0.5, 0.3]).unwrap();
    assert_eq!(out.push, Push::Move(7));
    assert!(game.is_goal(env.board()) && game.is_goal(twin.board()));
}

/// Clones of the robot share one board: a trainer's episodes on them must run one after
/// another, so that each records the board its own push started from.
#[test]
fn episodes_on_one_robot_run_one_after_another() {
    use rand::SeedableRng;
    use seads_rl::{Sac, SacConfig, run_episodes};
    let twin = Twin::new(5);
    let mut config_env = env(&twin, ActionSpace::Absolute);
    config_env.reset().unwrap();
    let k = 25;
    let input = config_env.spec().obs_dim + k;
    let spec = config_env.spec().clone();
    let sac = Sac::new(
        input,
        &spec.action_low,
        &spec.action_high,
        &SacConfig::default(),
        tch::Device::Cpu,
        2,
    );
    let mut envs: Vec<Box<dyn Environment>> = (0..6).map(|_| config_env.box_clone()).collect();
    let skills = [0, 3, 7, 11, 19, 24];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let episodes = run_episodes(&mut envs, &skills, &sac, k, Some(&mut rng)).unwrap();
    let game = LightsOut::new(5).unwrap();
    let mut board = episodes[0].z0;
    for e in &episodes {
        assert_eq!(
            e.z0, board,
            "each episode starts where the previous one ended"
        );
        let mv = e
            .game_move
            .expect("an absolute push always presses a field");
        assert_eq!(e.zt, game.apply(e.z0, mv), "one push, one move");
        board = e.zt;
    }
}

/// The robot's board side is every environment's (`BoardState`, `EnvSpec::observe_board`):
/// seeded alike, the twin that resets its board and the LightsOutCursor draw the same boards;
/// given the same board, both observe it and their remaining time alike after every step, with a
/// step limit of 10, of 1, and with none (as when recording).
#[test]
fn the_twin_observes_its_board_and_remaining_time_as_the_cursor_does() {
    let twin = Twin::new(8);
    let mut robot = env(&twin, ActionSpace::Displacement);
    let mut cursor =
        seads_embodiment::make_env("lightsout-cursor", &seads_embodiment::EnvConfig::default())
            .unwrap();
    let board_side = |obs: Vec<f32>| obs[2..].to_vec();
    for seed in [1, 2, 3, 40] {
        robot.seed(seed);
        cursor.seed(seed);
        robot.reset().unwrap();
        cursor.reset().unwrap();
        assert_eq!(robot.board(), cursor.board(), "seed {seed}");
        assert_eq!(
            board_side(robot.observation()),
            board_side(cursor.observation()),
            "seed {seed}"
        );
    }
    let board = LightsOut::new(5)
        .unwrap()
        .apply_all(Default::default(), &[0, 7, 24]);
    for limit in [Some(10), Some(1), None] {
        robot.set_step_limit(limit);
        cursor.set_step_limit(limit);
        robot.set_board(board).unwrap();
        cursor.set_board(board).unwrap();
        robot.reset_step_counter();
        cursor.reset_step_counter();
        for step in 0..=limit.unwrap_or(3) {
            let (r, c) = (robot.observation(), cursor.observation());
            assert_eq!(board_side(r), board_side(c), "limit {limit:?}, step {step}");
            if Some(step) == limit {
                break;
            }
            robot.step(&[0.0, 0.0, -1.0]).unwrap();
            cursor.step(&[0.0, 0.0, -1.0]).unwrap();
        }
    }
}

/// The centre field's press, `n` times on a twin with `noise`, each on a new board: what the
/// robot sees of them.
fn centre_presses(noise: TwinNoise, n: usize) -> Vec<Push> {
    let twin = Twin::with_noise(11, noise).unwrap();
    let mut env = env_with(&twin, ActionSpace::Absolute, true);
    env.seed(1);
    (0..n)
        .map(|_| {
            env.reset().unwrap();
            env.step(&[0.5, 0.5]).unwrap().push
        })
        .collect()
}

#[test]
fn taps_scatter_as_the_noise_says_and_repeat_with_the_seed() {
    let noise = TwinNoise {
        tap_sd_mm: 10.0,
        late_report_p: 0.0,
    };
    let n = 3000;
    let pushes = centre_presses(noise, n);
    assert_eq!(
        pushes,
        centre_presses(noise, n),
        "the same seed, the same taps"
    );
    let share = |f: &dyn Fn(usize) -> bool| {
        let hits = pushes
            .iter()
            .filter(|p| matches!(p, Push::Move(m) if f(*m)))
            .count();
        hits as f64 / n as f64
    };
    // The centre field is 217/5 = 43.4 mm wide and 136.18/5 = 27.24 mm high on the twin's screen
    // (its corners), so a tap with 10 mm deviation per axis stays in it with probability
    // erf(21.7 / (10 √2)) · erf(13.62 / (10 √2)) = 0.9700 · 0.8264 = 0.8016, in its column
    // (same x) with 0.9700 and in its row (same y) with 0.8264 (Python's math.erf).
    let centre = share(&|m| m == 12);
    assert!((centre - 0.8016).abs() < 0.03, "{centre}");
    let column = share(&|m| m % 5 == 2);
    assert!((column - 0.9700).abs() < 0.015, "{column}");
    let row = share(&|m| m / 5 == 2);
    assert!((row - 0.8264).abs() < 0.03, "{row}");
    // Without noise, every tap is the centre's.
    let exact = centre_presses(TwinNoise::default(), 50);
    assert!(exact.iter().all(|p| *p == Push::Move(12)), "{exact:?}");
}

#[test]
fn late_reports_reach_the_next_press() {
    let late = |p: f64| TwinNoise {
        tap_sd_mm: 0.0,
        late_report_p: p,
    };
    // Always late: the press sees nothing, the tablet has the move, the robot's board lags.
    let twin = Twin::with_noise(3, late(1.0)).unwrap();
    let mut env = env_with(&twin, ActionSpace::Absolute, false);
    env.reset().unwrap();
    let before = env.board();
    assert_eq!(env.step(&[0.5, 0.5]).unwrap().push, Push::Miss);
    assert_eq!(env.board(), before);
    assert_ne!(twin.board(), before);
    // A press off the board (no tap) then receives the late report: the centre's move.
    let twin = Twin::with_noise(3, late(1.0)).unwrap();
    let mut env = env_with(&twin, ActionSpace::Displacement, false);
    env.reset().unwrap();
    let before = env.board();
    assert_eq!(env.step(&[0.0, 0.0, 1.0]).unwrap().push, Push::Miss);
    env.reset().unwrap();
    assert_eq!(env.step(&[0.0, 0.0, -1.0]).unwrap().push, Push::None);
    let game = LightsOut::new(5).unwrap();
    assert_eq!(env.board(), before, "not yet");
    // The next press, on the field to the right, receives the late report with its own tap's:
    // the robot sees both moves, the last one as the press's.
    let out = env.step(&[0.2, 0.0, 1.0]).unwrap();
    assert_eq!(out.push, Push::Move(13));
    assert_eq!(env.board(), game.apply_all(before, &[12, 13]));
    assert_eq!(twin.board(), env.board());
    // Sometimes late: a share p of the presses on new boards miss (a new board makes a late
    // report of the one before obsolete). Within 0.035: over 3 binomial σ for 2000 presses.
    let misses = centre_presses(late(0.3), 2000)
        .iter()
        .filter(|p| **p == Push::Miss)
        .count() as f64
        / 2000.0;
    assert!((misses - 0.3).abs() < 0.035, "{misses}");
}

#[test]
fn noise_out_of_range_is_refused() {
    for (tap_sd_mm, late_report_p) in [(-1.0, 0.0), (f64::NAN, 0.0), (101.0, 0.0), (0.0, 1.5)] {
        let noise = TwinNoise {
            tap_sd_mm,
            late_report_p,
        };
        assert!(
            matches!(Twin::with_noise(1, noise), Err(UarmError::Config(_))),
            "{noise:?}"
        );
    }
    assert!(
        Twin::with_noise(
            1,
            TwinNoise {
                tap_sd_mm: 0.0,
                late_report_p: f64::NAN
            }
        )
        .is_err()
    );
}

#[test]
fn what_the_skills_do_not_see_reads_zero() {
    let twin = Twin::new(12);
    let calibration = calibrate(&twin);
    let observed = |observe: Observation| {
        let config = UarmConfig {
            observe,
            tap_timeout_s: 0.0,
            ..UarmConfig::default()
        };
        let mut env =
            UarmEnv::new(driver(&twin), twin.tablet(), calibration.clone(), config).unwrap();
        let board = LightsOut::new(5)
            .unwrap()
            .apply_all(Default::default(), &[3]);
        env.set_board(board).unwrap();
        env.restore_manipulator(&[0.25, 0.75]).unwrap();
        env.observation()
    };
    let all = observed(Observation::BoardAndPen);
    assert_eq!(all[..2], [0.25, 0.75]);
    assert_eq!(
        all[2..27].iter().filter(|v| **v != 0.0).count(),
        4,
        "move 3 lights 4"
    );
    let zero_pen = [vec![0.0, 0.0], all[2..].to_vec()].concat();
    let mut zero_board = all.clone();
    zero_board[2..27].fill(0.0);
    let mut nothing = zero_pen.clone();
    nothing[2..27].fill(0.0);
    assert_eq!(observed(Observation::Board), zero_pen);
    assert_eq!(observed(Observation::Pen), zero_board);
    assert_eq!(observed(Observation::Nothing), nothing);
    assert_eq!(
        *nothing.last().unwrap(),
        *all.last().unwrap(),
        "the time is always seen"
    );
}

#[test]
fn robot_settings_from_before_the_observation_read_as_the_defaults() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join(RobotSettings::FILE),
        "action_space = \"absolute\"\nreset_board = false\n",
    )
    .unwrap();
    let old = RobotSettings::read(dir.path()).unwrap().unwrap();
    assert_eq!(old.observe, Observation::BoardAndPen);
    assert_eq!(old.twin_noise, TwinNoise::default());
    let new = RobotSettings {
        observe: Observation::Pen,
        twin_noise: TwinNoise {
            tap_sd_mm: 2.5,
            late_report_p: 0.1,
        },
        ..old
    };
    new.write(dir.path()).unwrap();
    assert_eq!(RobotSettings::read(dir.path()).unwrap(), Some(new));
    std::fs::write(dir.path().join(RobotSettings::FILE), "observe = \"eyes\"\n").unwrap();
    assert!(matches!(
        RobotSettings::read(dir.path()),
        Err(UarmError::Config(_))
    ));
}

/// Presses at `points` (absolute pushes under the paper's protocol: no resets of board or pen),
/// each what the robot saw of it and the observation after it.
fn presses(env: &mut UarmEnv, points: &[[f32; 2]]) -> Vec<(Push, Vec<f32>)> {
    points
        .iter()
        .map(|p| {
            env.reset().unwrap();
            let push = env.step(p).unwrap().push;
            (push, env.observation())
        })
        .collect()
}

/// A noisy twin under the paper's protocol, with its environment carrying its state.
fn carrying_env(seed: u64) -> (Twin, UarmEnv) {
    let noise = TwinNoise {
        tap_sd_mm: 12.0,
        late_report_p: 0.3,
    };
    let twin = Twin::with_noise(seed, noise).unwrap();
    let env = env_with(&twin, ActionSpace::Absolute, false).on_twin(twin.clone());
    (twin, env)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(12))]

    /// A run stopped after any press and resumed on a fresh twin from the carried state presses
    /// as the run that was never stopped: the same taps, reports, boards and observations (the
    /// paper's protocol resets nothing, so the twin's pen, board and noise carry history). A
    /// fresh twin that is not given the state goes elsewhere.
    #[test]
    fn a_twin_run_resumed_from_its_carried_state_is_the_run_never_stopped(
        seed in 0u64..1000,
        stop in 1usize..30,
    ) {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let points: Vec<[f32; 2]> = (0..40).map(|_| [rng.random(), rng.random()]).collect();
        let (whole_twin, mut whole) = carrying_env(seed);
        let all = presses(&mut whole, &points);
        let (twin, mut stopped) = carrying_env(seed);
        presses(&mut stopped, &points[..stop]);
        let state = stopped.carried_state().expect("an environment on the twin carries state");
        drop((twin, stopped));
        let (twin, mut resumed) = carrying_env(seed);
        resumed.restore_carried_state(&state).unwrap();
        proptest::prop_assert_eq!(&presses(&mut resumed, &points[stop..]), &all[stop..]);
        let (_, mut fresh) = carrying_env(seed);
        proptest::prop_assert_ne!(&presses(&mut fresh, &points[stop..]), &all[stop..]);
        proptest::prop_assert_eq!(twin.state(), whole_twin.state());
    }
}

/// The real arm carries nothing (it stays where it is); a state that does not read, or one no
/// twin can be in, is refused and changes nothing.
#[test]
fn carried_states_that_cannot_be_are_refused() {
    let twin = Twin::new(4);
    let mut plain = env_with(&twin, ActionSpace::Absolute, false);
    assert_eq!(
        plain.carried_state(),
        None,
        "without on_twin nothing is carried"
    );
    let (twin, mut env) = carrying_env(4);
    presses(&mut env, &[[0.3, 0.7], [0.9, 0.1]]);
    let good = env.carried_state().unwrap();
    assert!(matches!(
        plain.restore_carried_state(&good),
        Err(EnvError::Unsupported { .. })
    ));
    let v: serde_json::Value = serde_json::from_str(&good).unwrap();
    let with = |pointer: &str, value: serde_json::Value| {
        let mut v = v.clone();
        *v.pointer_mut(pointer).unwrap() = value;
        v.to_string()
    };
    let (before, pen, board) = (env.observation(), twin.pen(), twin.board());
    for bad in [
        "{".to_string(),
        "null".to_string(),
        with("/cursor/0", serde_json::json!(1.5)),
        with("/board/words/0", serde_json::json!(u64::MAX)),
        with("/twin/pen/2", serde_json::json!(null)),
        with("/twin/noise_rng/word_pos", serde_json::json!(-1)),
        with("/twin/board/words/0", serde_json::json!(u64::MAX)),
        with("/twin/last_move", serde_json::json!(25)),
        with("/twin/timed", serde_json::json!(u64::MAX)),
        // Issue 82: a pen far beyond the arm's reach, and an environment board other than the
        // twin's although the environment received the twin's newest report.
        with("/twin/pen", serde_json::json!([1e308, -1e308, 1e308])),
        with(
            "/board",
            serde_json::to_value(seads_games::BoardGame::apply(&seads_uarm::game(), board, 0))
                .unwrap(),
        ),
    ] {
        let err = env.restore_carried_state(&bad).unwrap_err();
        assert!(matches!(err, EnvError::InvalidState { .. }), "{bad}: {err}");
        assert_eq!(env.observation(), before, "{bad}");
        assert_eq!((twin.pen(), twin.board()), (pen, board), "{bad}");
    }
    env.restore_carried_state(&good).unwrap();
    assert_eq!(env.carried_state().unwrap(), good);
}
