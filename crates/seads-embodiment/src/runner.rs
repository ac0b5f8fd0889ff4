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

/// Environment steps per second of `threads` copies of `env`, each seeded `1..=threads` and
/// stepped `steps / threads` (rounded up) times by [`random_rollout`] on its own thread.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Throughput {
    /// The environment's name.
    pub env: String,
    /// Steps taken in all.
    pub steps: usize,
    /// Threads.
    pub threads: usize,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// `steps / seconds`.
    pub steps_per_sec: f64,
}

impl Throughput {
    /// Measures it; `threads` and `steps` must be at least 1.
    pub fn measure(env: &dyn Environment, steps: usize, threads: usize) -> Result<Self, EnvError> {
        let (steps, threads) = (steps.max(1), threads.max(1));
        let per_thread = steps.div_ceil(threads);
        let envs: Vec<Box<dyn Environment>> = (0..threads)
            .map(|i| {
                let mut env = env.box_clone();
                env.seed(i as u64 + 1);
                env.reset()?;
                Ok(env)
            })
            .collect::<Result<_, EnvError>>()?;
        let start = std::time::Instant::now();
        std::thread::scope(|scope| {
            let handles: Vec<_> = envs
                .into_iter()
                .enumerate()
                .map(|(i, mut env)| {
                    scope.spawn(move || random_rollout(env.as_mut(), per_thread, i as u64))
                })
                .collect();
            handles
                .into_iter()
                .try_for_each(|h| h.join().expect("a rollout thread panicked").map(|_| ()))
        })?;
        let seconds = start.elapsed().as_secs_f64();
        Ok(Self {
            env: env.spec().name.clone(),
            steps: per_thread * threads,
            threads,
            seconds,
            steps_per_sec: (per_thread * threads) as f64 / seconds,
        })
    }
}
