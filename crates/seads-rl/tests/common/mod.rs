//! Helpers shared by the tests and the benches of seads-rl (benches include this file by path).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_rl::TransitionBatch;

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
