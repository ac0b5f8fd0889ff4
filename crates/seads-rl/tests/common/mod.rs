//! Helpers shared by the tests and the benches of seads-rl (benches include this file by path).
#![allow(dead_code)] // each test crate or bench uses some of them

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_rl::{TrainConfig, TransitionBatch};

/// `rows` transitions with values uniform in [−1, 1), policy inputs of `input` values, 2-D
/// actions, no episode ends, drawn from `seed`.
pub fn random_transitions(rows: usize, input: usize, seed: u64) -> TransitionBatch {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut random =
        |n: usize| -> Vec<f32> { (0..n).map(|_| rng.random_range(-1.0..1.0)).collect() };
    TransitionBatch {
        obs: random(rows * input),
        actions: random(rows * 2),
        rewards: random(rows),
        next_obs: random(rows * input),
        dones: vec![0.0; rows],
    }
}

/// A small, fast configuration of LightsOutCursor.
pub fn small(seed: u64, steps: u64) -> TrainConfig {
    let mut config = TrainConfig::preset("lightsout-cursor").unwrap();
    config.seed = seed;
    config.env_steps = steps;
    config.sac.hidden = vec![64, 64];
    config
        .edit(|s: &mut seads_rl::SeadsConfig| {
            s.skill_model.hidden = vec![64, 64];
            (s.sampled_episodes, s.recent_episodes) = (64, 32);
        })
        .unwrap();
    config.eval_every = 10;
    config.checkpoint_every = 10;
    config
        .edit(|s: &mut seads_rl::SeadsConfig| s.eval_seeds = 2)
        .unwrap();
    // Tests run side by side: SAC taking a second thread would oversubscribe the cores.
    config.sac_threads_alone = 0;
    // Portable kernels, as the demo uses (cargo sets them: .cargo/config.toml).
    config.portable_numerics = true;
    config
}
