//! Recording and replaying episodes: exact round trips, and clear errors.

use rand::{RngExt, SeedableRng};
use seads_embodiment::{
    EnvConfig, EpisodeRecord, ReplayError, compare, make_env, record_episode, replay_episode,
};

fn random_episode(name: &str, config: &EnvConfig, seed: u64, steps: usize) -> EpisodeRecord {
    let mut env = make_env(name, config).unwrap();
    env.seed(seed);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (low, high) = (
        env.spec().action_low.clone(),
        env.spec().action_high.clone(),
    );
    record_episode(env.as_mut(), steps, |_, a| {
        for (x, (l, h)) in a.iter_mut().zip(low.iter().zip(&high)) {
            *x = rng.random_range(*l..=*h);
        }
    })
    .unwrap()
}

#[test]
fn record_then_replay_is_identical_for_every_replayable_environment() {
    let spaced = EnvConfig {
        board_size: Some(7),
        spacing: Some(0.5),
        ..EnvConfig::default()
    };
    // Every registered environment whose manipulator restores from an observation (the Jaco's
    // physics state does not), unnamed, and a spaced board.
    let replayable = |name: &str| {
        let mut env = make_env(name, &EnvConfig::default()).unwrap();
        env.seed(0);
        env.reset().unwrap();
        let state = env.observation()[..env.spec().manipulator_dim].to_vec();
        env.restore_manipulator(&state).is_ok()
    };
    let mut cases: Vec<(&str, EnvConfig)> = seads_embodiment::env_names()
        .into_iter()
        .filter(|n| replayable(n))
        .map(|n| (n, EnvConfig::default()))
        .collect();
    assert!(cases.len() >= 9, "{}", cases.len());
    cases.push(("lightsout-cursor", spaced));
    for (name, config) in cases {
        // Random pushes make moves in every episode of most games; on the sliding puzzle only
        // the few fields next to the gap move, so longer episodes make sure some are replayed.
        let mut moves = 0;
        for seed in 0..3 {
            let recorded = random_episode(name, &config, seed, 1000);
            moves += recorded
                .steps
                .iter()
                .filter(|s| s.game_move.is_some())
                .count();
            let mut env = make_env(name, &config).unwrap();
            env.seed(seed + 100); // a different state before the replay must not matter
            env.reset().unwrap();
            let replayed = replay_episode(env.as_mut(), &recorded).unwrap();
            assert_eq!(replayed, recorded, "{name}, seed {seed}");
            let c = compare(&recorded, &replayed, env.spec().manipulator_dim);
            assert_eq!(
                (
                    c.board_mismatches,
                    c.move_mismatches,
                    c.max_manipulator_deviation
                ),
                (0, 0, 0.0)
            );
        }
        assert!(moves > 0, "{name}: random actions make moves");
    }
}

#[test]
fn jaco_records_but_cannot_replay() {
    let recorded = random_episode("tileswap-jaco", &EnvConfig::default(), 1, 2);
    assert_eq!(recorded.initial_obs.len(), 42 + 81);
    let mut env = make_env("tileswap-jaco", &EnvConfig::default()).unwrap();
    assert!(matches!(
        replay_episode(env.as_mut(), &recorded),
        Err(ReplayError::Env(_))
    ));
}

#[test]
fn inconsistent_records_are_rejected_with_a_reason() {
    let recorded = random_episode("tileswap-cursor", &EnvConfig::default(), 2, 5);
    let mut env = make_env("tileswap-cursor", &EnvConfig::default()).unwrap();
    let check = |edit: &dyn Fn(&mut EpisodeRecord),
                 needle: &str,
                 env: &mut dyn seads_embodiment::Environment| {
        let mut bad = recorded.clone();
        edit(&mut bad);
        let err = replay_episode(env, &bad).unwrap_err().to_string();
        assert!(err.contains(needle), "{needle}: {err}");
    };
    check(
        &|r| r.initial_obs.pop().map(|_| ()).unwrap(),
        "initial_obs has 82 values",
        env.as_mut(),
    );
    check(&|r| r.initial_obs[5] = 0.5, "not 0 or 1", env.as_mut());
    check(
        &|r| r.initial_obs[2..].fill(0.0),
        "not a valid tileswap board",
        env.as_mut(),
    );
    check(&|r| r.steps[1].action.push(0.0), "step 1", env.as_mut());
    check(
        &|r| r.env = "lightsout-cursor".into(),
        "environment",
        env.as_mut(),
    );
    check(&|r| r.initial_obs[0] = 2.0, "outside [0, 1]", env.as_mut());
    check(
        &|r| r.steps[0].action[0] = f32::NAN,
        "not a finite number",
        env.as_mut(),
    );
}
