//! `VecEnv`: many environments stepped together, in parallel with rayon when it pays off.

use rayon::prelude::*;

use crate::{EnvConfig, EnvError, Environment, StepOutcome, make_env};

/// A batch of environments of the same kind, stepped with one call.
#[derive(Clone)]
pub struct VecEnv {
    envs: Vec<Box<dyn Environment>>,
    parallel: bool,
}

impl VecEnv {
    /// `n` copies of environment `name`, seeded `base_seed + 1 … base_seed + n` and reset.
    pub fn new(name: &str, config: &EnvConfig, n: usize, base_seed: u64) -> Result<Self, EnvError> {
        let template = make_env(name, config)?;
        let envs = (0..n)
            .map(|i| {
                let mut env = template.clone();
                env.seed(base_seed + i as u64 + 1);
                env.reset()?;
                Ok(env)
            })
            .collect::<Result<_, EnvError>>()?;
        Ok(Self {
            envs,
            parallel: false,
        })
    }

    /// Steps environments on rayon's pool (worth it for expensive physics, not for the Cursor).
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }

    /// Number of environments.
    pub fn len(&self) -> usize {
        self.envs.len()
    }

    /// Whether there are no environments.
    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }

    /// Environment `i`.
    pub fn env(&self, i: usize) -> &dyn Environment {
        self.envs[i].as_ref()
    }

    /// Environment `i`, mutably (to reset or re-seed it).
    pub fn env_mut(&mut self, i: usize) -> &mut dyn Environment {
        self.envs[i].as_mut()
    }

    /// Observation length.
    pub fn obs_dim(&self) -> usize {
        self.envs[0].spec().obs_dim
    }

    /// Action length.
    pub fn action_dim(&self) -> usize {
        self.envs[0].spec().action_dim
    }

    /// Writes every observation into `obs` (`len() × obs_dim()` values).
    pub fn observe_all(&self, obs: &mut [f32]) {
        for (env, o) in self.envs.iter().zip(obs.chunks_mut(self.obs_dim())) {
            env.observe(o);
        }
    }

    /// Steps the environments whose `active` flag is set with their rows of `actions`
    /// (`len() × action_dim()`), writing their new observations into `obs` and their outcomes
    /// into `outcomes`. Rows of inactive environments are left untouched.
    pub fn step(
        &mut self,
        active: &[bool],
        actions: &[f32],
        obs: &mut [f32],
        outcomes: &mut [StepOutcome],
    ) -> Result<(), EnvError> {
        let (a, o) = (self.action_dim(), self.obs_dim());
        if self.parallel {
            self.envs
                .par_iter_mut()
                .zip(actions.par_chunks(a))
                .zip(obs.par_chunks_mut(o))
                .zip(outcomes.par_iter_mut().zip(active.par_iter()))
                .try_for_each(|(((env, act), ob), (out, &on))| {
                    step_active(env.as_mut(), on, act, ob, out)
                })
        } else {
            self.envs
                .iter_mut()
                .zip(actions.chunks(a))
                .zip(obs.chunks_mut(o))
                .zip(outcomes.iter_mut().zip(active.iter()))
                .try_for_each(|(((env, act), ob), (out, &on))| {
                    step_active(env.as_mut(), on, act, ob, out)
                })
        }
    }
}

/// Steps one environment of a batch if it is active.
fn step_active(
    env: &mut dyn Environment,
    active: bool,
    action: &[f32],
    obs: &mut [f32],
    outcome: &mut StepOutcome,
) -> Result<(), EnvError> {
    if active {
        *outcome = env.step(action)?;
        env.observe(obs);
    }
    Ok(())
}

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
