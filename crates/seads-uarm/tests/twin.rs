//! The driver, the calibration and the environment end to end on the simulated twin, faults
//! included: every failure is a clear error, and the pen is left at hover height.

use seads_embodiment::{EnvError, Environment, Push, record_episode, replay_episode};
use seads_games::{BoardGame, LightsOut};
use seads_uarm::{
    ActionSpace, Calibration, CalibrationFile, DriverConfig, Faults, Swift, Twin, UarmConfig,
    UarmEnv, UarmError, twin_screen_corners,
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
