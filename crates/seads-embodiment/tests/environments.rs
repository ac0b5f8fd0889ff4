//! Behaviour shared by every environment: dimensions, bad input, determinism, termination.

use seads_embodiment::{EnvConfig, EnvError, Push, StepOutcome, env_names, list_envs, make_env};
use seads_games::{BoardGame, LightsOut, Split, split_of};

#[test]
fn dimensions_match_the_paper() {
    let expected = [
        ("lightsout-cursor", 28, 3, 25, 10),
        ("tileswap-cursor", 84, 3, 12, 10),
        ("lightsout-reacher", 30, 3, 25, 50),
        ("tileswap-reacher", 86, 3, 12, 50),
        ("lightsout-jaco", 68, 9, 25, 50),
        ("tileswap-jaco", 124, 9, 12, 50),
        ("lightsout3d-jaco", 68, 9, 25, 50),
    ];
    let listed = list_envs();
    for (name, obs, act, k, limit) in expected {
        let info = listed
            .iter()
            .find(|i| i.name == name)
            .unwrap_or_else(|| panic!("{name} is registered"));
        assert_eq!(
            (
                info.obs_dim,
                info.action_dim,
                info.num_skills,
                info.step_limit
            ),
            (obs, act, k, limit),
            "{name}"
        );
    }
}

#[test]
fn unknown_environment_lists_the_valid_ones() {
    let err = make_env("lightsout-robot", &EnvConfig::default())
        .err()
        .unwrap();
    let text = err.to_string();
    assert!(matches!(err, EnvError::UnknownEnv { .. }));
    for name in env_names() {
        assert!(text.contains(name), "{text}");
    }
}

#[test]
fn bad_actions_are_errors_not_physics() {
    for name in env_names() {
        let mut env = make_env(name, &EnvConfig::default()).unwrap();
        let a = env.spec().action_dim;
        assert!(
            matches!(
                env.step(&[0.0, 0.0]),
                Err(EnvError::ActionLength { found: 2, .. })
            ),
            "{name}"
        );
        let mut bad = vec![0.0; a];
        bad[1] = f32::NAN;
        assert!(
            matches!(
                env.step(&bad),
                Err(EnvError::NonFiniteAction { index: 1, .. })
            ),
            "{name}"
        );
        bad[1] = 0.0;
        bad[0] = f32::INFINITY;
        assert!(matches!(
            env.step(&bad),
            Err(EnvError::NonFiniteAction { index: 0, .. })
        ));
        // The environment is unharmed.
        assert!(env.observation().iter().all(|v| v.is_finite()));
        env.step(&vec![0.0; a]).unwrap();
    }
}

#[test]
fn bad_configs_are_rejected() {
    let with = |f: fn(&mut EnvConfig)| {
        let mut c = EnvConfig::default();
        f(&mut c);
        c
    };
    let cases = [
        ("lightsout-cursor", with(|c| c.max_solution_depth = 0)),
        ("lightsout-cursor", with(|c| c.board_size = Some(6))),
        ("lightsout-cursor", with(|c| c.board_size = Some(15))),
        ("lightsout-cursor", with(|c| c.spacing = Some(1.5))),
        ("tileswap-cursor", with(|c| c.board_size = Some(5))),
        ("lightsout-reacher", with(|c| c.spacing = Some(0.5))),
        ("tileswap-cursor", with(|c| c.step_limit = Some(0))),
        // TileSwap has no test board of depth 16.
        (
            "tileswap-cursor",
            with(|c| {
                c.max_solution_depth = 16;
                c.random_solution_depth = false;
                c.reset_split = Split::Test;
            }),
        ),
    ];
    for (name, config) in cases {
        assert!(
            matches!(make_env(name, &config), Err(EnvError::InvalidConfig(_))),
            "{name} {config:?}"
        );
    }
}

#[test]
fn config_toml_round_trips_and_rejects_unknown_fields() {
    let config = EnvConfig {
        board_size: Some(9),
        spacing: Some(0.5),
        ..EnvConfig::default()
    };
    let text = toml::to_string(&config).unwrap();
    assert_eq!(toml::from_str::<EnvConfig>(&text).unwrap(), config);
    assert!(toml::from_str::<EnvConfig>("max_depth = 3").is_err());
}

/// The same seed gives the same boards, manipulator states and episodes.
#[test]
fn same_seed_same_episode() {
    for name in env_names() {
        let run = |seed| {
            let mut env = make_env(name, &EnvConfig::default()).unwrap();
            env.seed(seed);
            let dim = env.spec().action_dim;
            let mut trace = Vec::new();
            for _ in 0..3 {
                env.reset().unwrap();
                for t in 0..10 {
                    let mut a = vec![0.15 * (t as f32).sin(); dim];
                    a[1] = -0.1;
                    a[dim - 1] = if t % 3 == 2 { 1.0 } else { -1.0 };
                    let out = env.step(&a).unwrap();
                    trace.push((env.observation(), out));
                    if out.done() {
                        break;
                    }
                }
            }
            trace
        };
        assert_eq!(run(5), run(5), "{name}");
        assert_ne!(run(5), run(6), "{name}");
    }
}

#[test]
fn step_limit_truncates_and_then_refuses() {
    let mut env = make_env(
        "lightsout-cursor",
        &EnvConfig {
            step_limit: Some(3),
            ..EnvConfig::default()
        },
    )
    .unwrap();
    env.reset().unwrap();
    let obs = env.observation();
    assert_eq!(obs[27], 1.0, "remaining time starts at 1");
    let mut last = StepOutcome::default();
    for _ in 0..3 {
        last = env.step(&[0.01, 0.0, -1.0]).unwrap();
    }
    assert!(last.truncated && last.done() && !last.moved());
    assert_eq!(env.observation()[27], 0.0);
    assert!(matches!(
        env.step(&[0.0, 0.0, -1.0]),
        Err(EnvError::StepLimitReached { limit: 3, .. })
    ));
    env.reset_step_counter();
    assert!(env.step(&[0.0, 0.0, -1.0]).is_ok());
}

#[test]
fn reset_boards_follow_the_split_and_depth() {
    let game = LightsOut::new(5).unwrap();
    let solver = seads_games::Gf2Solver::new(&game);
    for (split, random, max) in [(Split::Train, true, 5), (Split::Test, false, 4)] {
        let config = EnvConfig {
            reset_split: split,
            random_solution_depth: random,
            max_solution_depth: max,
            ..EnvConfig::default()
        };
        let mut env = make_env("lightsout-cursor", &config).unwrap();
        env.seed(11);
        let mut depths = [0usize; 6];
        for _ in 0..300 {
            env.reset().unwrap();
            let board = env.board();
            assert_eq!(split_of(&game.values(board)), split);
            depths[solver.depth(board).unwrap()] += 1;
        }
        if random {
            assert!(
                depths[1..=5].iter().all(|&c| c > 30),
                "depths 1..5 all drawn: {depths:?}"
            );
        } else {
            assert_eq!(depths[4], 300);
        }
    }
}

#[test]
fn moves_end_the_skill_and_change_phi() {
    let mut env = make_env("lightsout-cursor", &EnvConfig::default()).unwrap();
    env.reset().unwrap();
    let before = env.board();
    let out = env.step(&[0.0, 0.0, 1.0]).unwrap();
    assert!(out.moved() && out.done());
    let Push::Move(mv) = out.push else {
        unreachable!()
    };
    let game = LightsOut::new(5).unwrap();
    assert_eq!(env.board(), game.apply(before, mv));
    assert_eq!(env.spec().phi(&env.observation()), env.board());
}

#[test]
fn spaced_boards_of_every_size_build() {
    for n in [5, 7, 9, 13] {
        let config = EnvConfig {
            board_size: Some(n),
            spacing: Some(0.5),
            ..EnvConfig::default()
        };
        let mut env = make_env("lightsout-cursor", &config).unwrap();
        assert_eq!(env.spec().num_skills, n * n);
        assert_eq!(env.spec().obs_dim, 2 + n * n + 1);
        env.reset().unwrap();
        assert!(!env.board().is_zero());
    }
}

#[test]
fn jaco_clones_continue_identically_and_cannot_be_restored() {
    let mut env = make_env("tileswap-jaco", &EnvConfig::default()).unwrap();
    env.seed(4);
    env.reset().unwrap();
    let action = [0.3, -0.2, 0.1, 0.5, -0.5, 0.2, 1.0, 1.0, 1.0];
    env.step(&action).unwrap();
    let mut copy = env.clone();
    for _ in 0..3 {
        let (a, b) = (env.step(&action).unwrap(), copy.step(&action).unwrap());
        assert_eq!(a, b);
        let (oa, ob) = (env.observation(), copy.observation());
        assert!(
            oa.iter().zip(&ob).all(|(x, y)| (x - y).abs() < 1e-3),
            "{oa:?} vs {ob:?}"
        );
    }
    let m = env.spec().manipulator_dim;
    assert!(matches!(
        env.restore_manipulator(&vec![0.0; m]),
        Err(EnvError::Unsupported { .. })
    ));
}

#[test]
fn each_manipulator_reads_its_own_options_and_refuses_others() {
    let with = |key: &str, value: i64| {
        let mut config = EnvConfig::default();
        config.manipulator.insert(key.into(), value.into());
        config
    };
    for name in env_names() {
        let unknown = make_env(name, &with("no_such_option", 1)).err();
        assert!(
            matches!(unknown, Some(EnvError::ManipulatorOptions { .. })),
            "{name}: {unknown:?}"
        );
        // The Jaco's one option: only the Jaco environments take it, and never zero.
        let jaco = name.ends_with("-jaco");
        let substeps = make_env(name, &with("physics_substeps", 10));
        assert_eq!(substeps.is_ok(), jaco, "{name}");
        if jaco {
            assert!(
                make_env(name, &with("physics_substeps", 0)).is_err(),
                "{name}"
            );
        }
    }
}

#[test]
fn restoring_the_manipulator_validates_input() {
    let mut env = make_env("lightsout-cursor", &EnvConfig::default()).unwrap();
    env.restore_manipulator(&[0.25, 0.75]).unwrap();
    assert_eq!(env.observation()[..2], [0.25, 0.75]);
    assert!(matches!(
        env.restore_manipulator(&[1.5, 0.0]),
        Err(EnvError::InvalidState { .. })
    ));
    assert!(matches!(
        env.restore_manipulator(&[0.5]),
        Err(EnvError::InvalidState { .. })
    ));
}
