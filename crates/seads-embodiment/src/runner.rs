//! `random_rollout`: an environment stepped with random actions, the throughput workload of
//! `seads env-bench` and the benches. (Batches of environments are stepped by `seads-rl`'s
//! `run_episodes`, on rayon's pool.)

use crate::{EnvError, Environment};

/// Steps `env` `steps` times with uniformly random actions from a stream seeded with `seed`,
/// resetting whenever a skill ends (the throughput workload of `seads env-bench` and the
/// benches). Returns the number of game moves made.
pub fn random_rollout(
    env: &mut dyn Environment,
    steps: usize,
    seed: u64,
) -> Result<usize, EnvError> {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (low, high) = (
        env.spec().action_low.clone(),
        env.spec().action_high.clone(),
    );
    // A pool of actions drawn up front, so that the loop measures the environment, not the RNG.
    let pool: Vec<f32> = (0..4096 * low.len())
        .map(|i| rng.random_range(low[i % low.len()]..=high[i % low.len()]))
        .collect();
    let mut obs = vec![0.0; env.spec().obs_dim];
    let mut moves = 0;
    for (_, action) in (0..steps).zip(pool.chunks(low.len()).cycle()) {
        let outcome = env.step(action)?;
        env.observe(&mut obs);
        moves += outcome.moved() as usize;
        if outcome.done() {
            env.reset()?;
        }
    }
    Ok(moves)
}
