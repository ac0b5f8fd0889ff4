//! The task-reward SAC baseline (SPEC §5.1): its update schedule by hand, determinism, exact
//! resume through a run directory, and task success on the SEADS protocol's boards.

use seads_rl::{
    Algorithm, Run, TaskMetrics, TaskSac, TrainConfig, read_metrics_as, task_success, updates_due,
};

/// A small baseline run on LightsOutCursor: 8 environments, one update per epoch once 32
/// transitions are stored.
fn small(seed: u64, steps: u64) -> TrainConfig {
    let mut config = TrainConfig::preset("lightsout-cursor").unwrap();
    config.algorithm = Algorithm::Sac;
    config.seed = seed;
    config.env_steps = steps;
    config.sac.hidden = vec![32, 32];
    config.sac.batch_size = 32;
    config.baseline.eval_boards = 2;
    config.eval_every = 20;
    config.checkpoint_every = 20;
    config.portable_numerics = true;
    config
}

/// The metrics without the wall-clock fields.
fn numbers(metrics: &[TaskMetrics]) -> Vec<(u64, u64, Vec<f64>, u64, u32, u32)> {
    metrics
        .iter()
        .map(|m| {
            (
                m.epoch,
                m.env_steps,
                m.success.clone(),
                m.train_solved.to_bits(),
                m.critic_loss.to_bits(),
                m.actor_loss.to_bits(),
            )
        })
        .collect()
}

#[test]
fn the_update_schedule_follows_n_per_epoch() {
    let over =
        |n: f64, epochs: u64| -> Vec<usize> { (0..epochs).map(|e| updates_due(e, n)).collect() };
    assert_eq!(over(1.0, 4), [1, 1, 1, 1]);
    assert_eq!(over(2.0, 3), [2, 2, 2]);
    // N < 1: one update every 1/N epochs (SPEC §5.1: 16 samples per update for N = 0.5, 32 for
    // N = 0.25 with 8 samples per epoch).
    assert_eq!(over(0.5, 6), [0, 1, 0, 1, 0, 1]);
    assert_eq!(over(0.25, 8), [0, 0, 0, 1, 0, 0, 0, 1]);
}

/// Two runs of one seed are the same run, bit for bit; another seed is another run.
#[test]
fn a_seed_gives_the_same_run() {
    let run = |seed| {
        let dir = tempfile::tempdir().unwrap();
        let mut run = Run::<TaskSac>::create(dir.path(), small(seed, 480)).unwrap();
        while !run.finished() {
            run.step().unwrap();
        }
        numbers(&read_metrics_as::<TaskMetrics>(dir.path()).unwrap())
    };
    let a = run(4);
    assert_eq!(
        a.len(),
        4,
        "evaluations at epochs 1, 20, 40 and 60 (the last)"
    );
    assert_eq!(a, run(4));
    assert_ne!(a, run(5));
}

/// A run stopped after its epoch-40 checkpoint and resumed in a new process state (a fresh
/// `Run`) ends exactly as the uninterrupted run: the replay buffer, the streams and the open
/// episodes (replayed from their seeds and actions) are all restored.
#[test]
fn a_resumed_run_is_the_uninterrupted_run() {
    let whole = tempfile::tempdir().unwrap();
    let mut run = Run::<TaskSac>::create(whole.path(), small(6, 800)).unwrap();
    while !run.finished() {
        run.step().unwrap();
    }
    let parted = tempfile::tempdir().unwrap();
    let mut run = Run::<TaskSac>::create(parted.path(), small(6, 800)).unwrap();
    // Past the checkpoint at epoch 40: epochs 41–52 are lost and redone.
    for _ in 0..52 {
        run.step().unwrap();
    }
    drop(run);
    let mut run = Run::<TaskSac>::resume(parted.path()).unwrap();
    assert_eq!(run.trainer().epoch(), 40);
    while !run.finished() {
        run.step().unwrap();
    }
    assert_eq!(
        numbers(&read_metrics_as::<TaskMetrics>(parted.path()).unwrap()),
        numbers(&read_metrics_as::<TaskMetrics>(whole.path()).unwrap())
    );
}

/// Task success runs the SEADS protocol's test boards: every depth 1–5, the requested number of
/// boards each, and a solved task took at most T_lim = 10·S steps.
#[test]
fn task_success_covers_every_depth() {
    let config = small(1, 800);
    let agent = TaskSac::new(config.clone()).unwrap();
    let results = task_success(&config, agent.policy(), &[1, 2, 3, 4, 5], 3).unwrap();
    assert_eq!(
        results.iter().map(|r| r.depth).collect::<Vec<_>>(),
        [1, 2, 3, 4, 5]
    );
    for r in &results {
        assert_eq!(r.tasks, 3);
        assert!(r.solved <= 3);
        assert!(r.solution_steps.iter().all(|&s| s <= 10 * r.depth));
    }
}

/// The shipped presets carry SPEC §5.1's settings: 3 × 512 units, batch 256, a replay buffer of
/// 10⁶, 8 samples per epoch, and the seed's best (N, α) per environment.
#[test]
fn presets_carry_the_seeds_best_settings() {
    let best = [
        ("lightsout-cursor", 1.0, 0.1),
        ("tileswap-cursor", 1.0, 0.1),
        ("lightsout-reacher", 0.5, 0.001),
        ("tileswap-reacher", 0.25, 0.001),
        ("lightsout-jaco", 0.5, 0.0001),
        ("tileswap-jaco", 0.5, 0.0001),
    ];
    assert_eq!(TrainConfig::sac_presets().len(), 7, "and LightsOut3DJaco");
    for (env, n, alpha) in best {
        let c = TrainConfig::preset_for(env, Algorithm::Sac).unwrap();
        c.validate().unwrap();
        assert_eq!(c.algorithm, Algorithm::Sac);
        assert_eq!(c.env, env);
        assert_eq!(c.sac.hidden, [512, 512, 512]);
        assert_eq!(
            (c.sac.batch_size, c.sac.lr, c.sac.gamma, c.sac.tau),
            (256, 3e-4, 0.99, 0.005)
        );
        assert_eq!(
            (c.baseline.updates_per_epoch, c.sac.alpha),
            (n, alpha),
            "{env}"
        );
        assert_eq!(
            (c.baseline.replay_capacity, c.baseline.samples_per_epoch),
            (1_000_000, 8)
        );
        let budget = if env.ends_with("cursor") {
            500_000
        } else {
            10_000_000
        };
        assert_eq!(c.env_steps, budget);
    }
}

/// A baseline's config.toml names all its settings, defaults included, and reads back equal; a
/// SEADS config has no baselines' section.
#[test]
fn configs_round_trip_through_toml() {
    let sac = TrainConfig::preset_for("tileswap-cursor", Algorithm::Sac).unwrap();
    let text = sac.to_toml();
    assert!(
        text.contains("[baseline]") && text.contains("updates_per_epoch = 1.0"),
        "{text}"
    );
    assert_eq!(TrainConfig::from_toml(&text).unwrap(), sac);
    let seads = TrainConfig::preset("tileswap-cursor").unwrap();
    let text = seads.to_toml();
    assert!(
        !text.contains("baseline") && !text.contains("algorithm"),
        "{text}"
    );
    assert_eq!(TrainConfig::from_toml(&text).unwrap(), seads);
}
