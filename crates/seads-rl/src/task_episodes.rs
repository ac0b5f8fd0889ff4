//! What the two task-reward baselines (flat SAC and HAC) share: their environments stepped in
//! lockstep, one step of each per epoch; every episode seeded by its number from the run's seed;
//! the open episodes' actions, from which a checkpoint rebuilds the environments by replaying;
//! the counts, timings and random streams of the run; and the gradient steps due per epoch with
//! their mean losses.

use std::path::Path;
use std::time::Instant;

use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, EnvSpec, TaskEnv, TaskStep, make_env};
use seads_games::Split;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::TaskTimings;
use crate::seeds::{Purpose, derived_seed, stream};
use crate::{RlError, SacLosses, TrainConfig};

/// The open episode of one environment: enough to rebuild its state by replaying.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct OpenEpisode {
    /// The environment seed it was reset with.
    pub(crate) seed: u64,
    /// Its actions so far, row-major.
    pub(crate) actions: Vec<f32>,
}

/// Random streams of a baseline run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct Streams {
    pub(crate) collect: ChaCha8Rng,
    pub(crate) sample: ChaCha8Rng,
    pub(crate) sac: ChaCha8Rng,
}

/// What one epoch of a baseline did.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct TaskEpochStats {
    /// Epochs completed.
    pub epoch: u64,
    /// Environment steps so far.
    pub env_steps: u64,
    /// Gradient steps taken this epoch.
    pub updates: usize,
    /// Mean SAC losses of this epoch's steps (zero without steps).
    pub sac: SacLosses,
}

/// Gradient steps due after epoch `epoch` (0-based) at N per epoch: ⌊(e+1)·N⌋ − ⌊e·N⌋, so that
/// N = 0.25 steps once every 4 epochs and N = 2 twice per epoch.
pub fn updates_due(epoch: u64, per_epoch: f64) -> usize {
    let at = |e: u64| (e as f64 * per_epoch).floor();
    (at(epoch + 1) - at(epoch)).max(0.0) as usize
}

/// The shared part of a baseline's progress file: stored flat beside the baseline's own fields.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct Progress {
    pub(crate) epoch: u64,
    pub(crate) env_steps: u64,
    /// Episodes started, over all environments (numbers their seeds).
    pub(crate) episodes: u64,
    /// Episodes ended, and how many of them solved their board.
    pub(crate) ended: u64,
    pub(crate) solved: u64,
    pub(crate) timings: TaskTimings,
    pub(crate) streams: Streams,
    pub(crate) open: Vec<OpenEpisode>,
}

impl Progress {
    /// Nothing done yet, the streams drawn from `seed`.
    fn new(seed: u64) -> Self {
        Self {
            epoch: 0,
            env_steps: 0,
            episodes: 0,
            ended: 0,
            solved: 0,
            timings: TaskTimings::default(),
            streams: Streams {
                collect: stream(seed, Purpose::Collect),
                sample: stream(seed, Purpose::Sample),
                sac: stream(seed, Purpose::Sac),
            },
            open: Vec::new(),
        }
    }

    /// Share of the ended training episodes that solved their board.
    pub(crate) fn train_solved(&self) -> f64 {
        self.solved as f64 / self.ended.max(1) as f64
    }

    /// Ends the epoch's collection, begun at `start`: one step of each of `envs` environments.
    pub(crate) fn collected(&mut self, envs: usize, start: Instant) {
        self.env_steps += envs as u64;
        self.timings.collect += start.elapsed().as_secs_f64();
    }

    /// Ends the epoch with the gradient steps begun at `start`.
    pub(crate) fn end_epoch(&mut self, start: Instant, losses: LossMean) -> TaskEpochStats {
        self.timings.sac += start.elapsed().as_secs_f64();
        self.epoch += 1;
        let n = losses.updates.max(1) as f32;
        TaskEpochStats {
            epoch: self.epoch,
            env_steps: self.env_steps,
            updates: losses.updates,
            sac: SacLosses {
                critic: losses.sum.critic / n,
                actor: losses.sum.actor / n,
                q: losses.sum.q / n,
            },
        }
    }
}

/// The losses of an epoch's gradient steps, summed, for their mean.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LossMean {
    sum: SacLosses,
    updates: usize,
}

impl LossMean {
    /// Adds one step's losses.
    pub(crate) fn add(&mut self, l: SacLosses) {
        self.sum.critic += l.critic;
        self.sum.actor += l.actor;
        self.sum.q += l.q;
        self.updates += 1;
    }
}

/// A baseline's environments in task mode on the train split, one per sample of an epoch.
pub(crate) struct TaskEpisodes {
    envs: Vec<TaskEnv>,
    spec: EnvSpec,
    seed: u64,
}

impl TaskEpisodes {
    /// Checks `config` and sets the run's libtorch threads, then builds the environments and the
    /// shared progress of a fresh run; each environment's first episode is not started yet.
    pub(crate) fn new(config: &TrainConfig) -> Result<(Self, Progress), RlError> {
        config.validate()?;
        crate::numerics::check(config.portable_numerics)?;
        if config.threads > 0 {
            tch::set_num_threads(config.threads as i32);
        }
        let train = EnvConfig {
            reset_split: Split::Train,
            ..config.env_config.clone()
        };
        let max_depth = train.max_solution_depth;
        let envs = (0..config.baseline_training()?.samples_per_epoch)
            .map(|_| Ok(TaskEnv::new(make_env(&config.env, &train)?, max_depth)?))
            .collect::<Result<Vec<_>, RlError>>()?;
        let spec = envs[0].spec().clone();
        let episodes = Self {
            envs,
            spec,
            seed: config.seed,
        };
        Ok((episodes, Progress::new(config.seed)))
    }

    /// The environments' spec.
    pub(crate) fn spec(&self) -> &EnvSpec {
        &self.spec
    }

    /// How many environments step each epoch.
    pub(crate) fn len(&self) -> usize {
        self.envs.len()
    }

    /// Resets environment `slot` for the next episode, seeded by the episode's number, and
    /// writes its first observation into `obs` (resized to the observation's length).
    pub(crate) fn start(
        &mut self,
        slot: usize,
        progress: &mut Progress,
        obs: &mut Vec<f32>,
    ) -> Result<(), RlError> {
        let seed = derived_seed(self.seed, Purpose::TrainEnvs, progress.episodes);
        progress.episodes += 1;
        let env = &mut self.envs[slot];
        env.seed(seed);
        env.reset()?;
        obs.resize(self.spec.obs_dim, 0.0);
        env.observe(obs);
        let open = OpenEpisode {
            seed,
            actions: Vec::new(),
        };
        match progress.open.get_mut(slot) {
            Some(o) => *o = open,
            None => progress.open.push(open),
        }
        Ok(())
    }

    /// Steps environment `slot` with `action`, writes the next observation into `obs` and keeps
    /// the action in the open episode; an episode that ends is counted (the caller starts the
    /// next).
    pub(crate) fn step(
        &mut self,
        slot: usize,
        action: &[f32],
        progress: &mut Progress,
        obs: &mut [f32],
    ) -> Result<TaskStep, RlError> {
        let step = self.envs[slot].step(action)?;
        self.envs[slot].observe(obs);
        progress.open[slot].actions.extend_from_slice(action);
        if step.done {
            progress.ended += 1;
            progress.solved += u64::from(step.solved);
        }
        Ok(step)
    }

    /// Rebuilds every environment's open episode of `progress` (read from `path`) by replaying
    /// its actions, calling `observed(slot, observation)` after the reset and after each step.
    pub(crate) fn replay(
        &mut self,
        progress: &Progress,
        path: &Path,
        mut observed: impl FnMut(usize, &[f32]),
    ) -> Result<(), RlError> {
        if progress.open.len() != self.envs.len() {
            return Err(RlError::from(seads_run::RunError::Checkpoint {
                path: path.display().to_string(),
                reason: format!(
                    "{} open episodes for {} environments",
                    progress.open.len(),
                    self.envs.len()
                ),
            }));
        }
        let mut obs = vec![0.0; self.spec.obs_dim];
        for (slot, open) in progress.open.iter().enumerate() {
            let env = &mut self.envs[slot];
            env.seed(open.seed);
            env.reset()?;
            env.observe(&mut obs);
            observed(slot, &obs);
            for action in open.actions.chunks(self.spec.action_dim) {
                env.step(action)?;
                env.observe(&mut obs);
                observed(slot, &obs);
            }
        }
        Ok(())
    }
}

/// Writes a baseline's progress file `path`.
pub(crate) fn write_progress<T: Serialize>(path: &Path, progress: &T) -> Result<(), RlError> {
    let text = serde_json::to_string(progress).map_err(|e| RlError::io(path, e))?;
    std::fs::write(path, text).map_err(|e| RlError::io(path, e))
}

/// Reads a baseline's progress file `path`.
pub(crate) fn read_progress<T: DeserializeOwned>(path: &Path) -> Result<T, RlError> {
    let text = std::fs::read_to_string(path).map_err(|e| RlError::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| RlError::unreadable(path, e))
}
