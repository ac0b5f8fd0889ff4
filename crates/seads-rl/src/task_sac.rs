//! The flat SAC baseline with the task reward (SPEC §5.1): SAC on the environment's own
//! observation in task mode ([`TaskEnv`]), a replay buffer of the most recent transitions, and
//! task success on the SEADS protocol's test boards as its evaluation.
//!
//! One epoch steps each of `samples_per_epoch` environments once (an episode continues across
//! epochs), stores the transitions, and takes N gradient steps, N < 1 meaning one every 1/N
//! epochs. An episode ends when the board is solved or after T_lim steps; both end the return
//! (the observation carries the time left, so the limit is part of the state).
//!
//! Choices where the seed is silent (SPEC §9.7), and why:
//! - "8 new samples per epoch" are one step of each of 8 environments: the sample count per
//!   update is the seed's either way, and parallel episodes give less correlated samples.
//! - N < 1 updates per epoch: ⌊(e+1)·N⌋ − ⌊e·N⌋ steps after epoch e (N = 0.5: one every other
//!   epoch); updates start once the replay buffer holds a batch.
//! - Evaluation: the deterministic policy (tanh of the mean) on the protocol's tasks, each
//!   episode until solved or T_lim; results in the planner's `DepthResult` form, so that reports
//!   treat SEADS and the baselines alike. [`Sac`] is reused as it is (3 × 512 layers and batch
//!   256 are config values).
//!
//! Resuming is exact: a checkpoint holds the networks, the optimisers, the replay buffer, the
//! random streams, and for each environment the seed and actions of its open episode, which
//! resuming replays (the simulations are deterministic given a seed).

use seads_nn::Resolve as _;
use std::path::Path;
use std::time::Instant;

use seads_planner::{DepthResult, TaskSet};

use crate::BaselineConfig;
use crate::learner::Learner;
use crate::replay::Replay;
use crate::task_episodes::{
    LossMean, Progress, TaskEpisodes, TaskEpochStats, read_progress, updates_due, write_progress,
};
use crate::{Moment, Purpose, RlError, Sac, TrainConfig, derived_seed, task_success};
use crate::{TaskMetrics, TaskTimings};

/// The replay buffer of a run's checkpoint.
pub const REPLAY_FILE: &str = "replay.safetensors";
/// Epoch, steps, random streams and open episodes of a run's checkpoint.
pub const TASK_PROGRESS_FILE: &str = "task-progress.json";

/// The line after the epoch that `progress` has reached, for the per-depth `results` of an
/// evaluation.
pub(crate) fn task_metrics(
    results: &[DepthResult],
    progress: &Progress,
    wall_s: f64,
    stats: &TaskEpochStats,
) -> TaskMetrics {
    let (epoch, env_steps) = (progress.epoch, progress.env_steps);
    let success: Vec<f64> = results.iter().map(DepthResult::success_rate).collect();
    TaskMetrics {
        epoch,
        env_steps,
        wall_s,
        mean_success: success.iter().sum::<f64>() / success.len().max(1) as f64,
        success,
        train_solved: progress.train_solved(),
        critic_loss: stats.sac.critic,
        actor_loss: stats.sac.actor,
        steps_per_s: env_steps as f64 / wall_s.max(1e-9),
        timings: progress.timings,
        subgoals_reached: None,
    }
}

/// A flat SAC agent in training on the task reward.
pub struct TaskSac {
    config: TrainConfig,
    /// How it collects and learns (the configuration's `[sac_baseline]`).
    training: BaselineConfig,
    episodes: TaskEpisodes,
    /// The current observation of each environment.
    obs: Vec<Vec<f32>>,
    /// Where the next observation is written before it becomes the current one (no allocation
    /// per environment step).
    next_obs: Vec<f32>,
    sac: Sac,
    replay: Replay,
    progress: Progress,
}

impl TaskSac {
    /// A fresh agent for `config` (validated; `config.algorithm()` is not checked here).
    pub fn new(config: TrainConfig) -> Result<Self, RlError> {
        let training = config.baseline_training()?;
        let (episodes, progress) = TaskEpisodes::new(&config)?;
        let spec = episodes.spec();
        let sac = Sac::new(
            spec.obs_dim,
            &spec.action_low,
            &spec.action_high,
            &config.sac,
            config.device.resolve()?,
            derived_seed(config.seed, Purpose::SacInit, 0),
        );
        let replay = Replay::new(training.replay_capacity, spec.obs_dim, spec.action_dim);
        let mut agent = Self {
            obs: vec![Vec::new(); episodes.len()],
            next_obs: vec![0.0; spec.obs_dim],
            config,
            training,
            episodes,
            sac,
            replay,
            progress,
        };
        for slot in 0..agent.episodes.len() {
            agent
                .episodes
                .start(slot, &mut agent.progress, &mut agent.obs[slot])?;
        }
        Ok(agent)
    }

    /// The configuration.
    pub fn config(&self) -> &TrainConfig {
        &self.config
    }

    /// The policy.
    pub fn policy(&self) -> &Sac {
        &self.sac
    }

    /// Epochs run so far.
    pub fn epoch(&self) -> u64 {
        self.progress.epoch
    }

    /// Environment steps so far.
    pub fn env_steps(&self) -> u64 {
        self.progress.env_steps
    }

    /// Whether the step budget is spent.
    pub fn finished(&self) -> bool {
        self.progress.env_steps >= self.config.env_steps
    }

    /// Time spent per phase.
    pub fn timings(&self) -> TaskTimings {
        self.progress.timings
    }

    /// One epoch: a step of every environment, then the gradient steps due.
    pub fn run_epoch(&mut self) -> Result<TaskEpochStats, RlError> {
        let start = Instant::now();
        let inputs: Vec<f32> = self.obs.concat();
        let actions = self
            .sac
            .act(&inputs, Some(&mut self.progress.streams.collect));
        let a = self.episodes.spec().action_dim;
        for slot in 0..self.episodes.len() {
            let action = &actions[slot * a..(slot + 1) * a];
            let step = self
                .episodes
                .step(slot, action, &mut self.progress, &mut self.next_obs)?;
            self.replay.push(
                &self.obs[slot],
                action,
                step.reward,
                &self.next_obs,
                step.done,
            );
            std::mem::swap(&mut self.obs[slot], &mut self.next_obs);
            if step.done {
                self.episodes
                    .start(slot, &mut self.progress, &mut self.obs[slot])?;
            }
        }
        self.progress.collected(self.episodes.len(), start);

        let start = Instant::now();
        let mut losses = LossMean::default();
        if self.replay.len() >= self.config.sac.batch_size {
            for _ in 0..updates_due(self.progress.epoch, self.training.updates_per_epoch) {
                let streams = &mut self.progress.streams;
                let batch = self
                    .replay
                    .sample(self.config.sac.batch_size, &mut streams.sample);
                losses.add(self.sac.update(&batch, &mut streams.sac));
            }
        }
        Ok(self.progress.end_epoch(start, losses))
    }

    /// Task success of the deterministic policy on `boards` test boards of each depth 1–5
    /// (the authors' evaluation seeds first), as the SEADS evaluation's per-depth results.
    pub fn task_success(&mut self, boards: usize) -> Result<Vec<DepthResult>, RlError> {
        let start = Instant::now();
        let results = task_success(
            &self.config,
            &mut &self.sac,
            &TaskSet::standard(boards),
            |_, _, _, _| {},
        )?;
        self.progress.timings.evaluate += start.elapsed().as_secs_f64();
        Ok(results)
    }

    /// Writes the complete training state into `dir` (which must exist).
    pub fn save(&self, dir: &Path) -> Result<(), RlError> {
        self.sac.save(dir)?;
        self.replay.save(&dir.join(REPLAY_FILE))?;
        write_progress(&dir.join(TASK_PROGRESS_FILE), &self.progress)
    }

    /// Restores what [`TaskSac::save`] wrote, replaying each environment's open episode.
    pub fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        self.sac.load(dir, false)?;
        self.replay.load(&dir.join(REPLAY_FILE))?;
        let path = dir.join(TASK_PROGRESS_FILE);
        let progress: Progress = read_progress(&path)?;
        let current = &mut self.obs;
        self.episodes.replay(&progress, &path, |slot, obs| {
            current[slot].clear();
            current[slot].extend_from_slice(obs);
        })?;
        self.progress = progress;
        Ok(())
    }
}

impl Learner for TaskSac {
    type Section = crate::BaselineConfig;
    type Stats = TaskEpochStats;
    type Metrics = TaskMetrics;

    fn build(config: TrainConfig) -> Result<Self, RlError> {
        Self::new(config)
    }
    fn config(&self) -> &TrainConfig {
        &self.config
    }
    fn epoch(&self) -> u64 {
        self.progress.epoch
    }
    fn finished(&self) -> bool {
        TaskSac::finished(self)
    }
    fn run_epoch_observed(
        &mut self,
        hook: &mut dyn FnMut(Moment),
    ) -> Result<TaskEpochStats, RlError> {
        let stats = self.run_epoch()?;
        hook(Moment::Collected);
        Ok(stats)
    }
    fn metrics(&mut self, stats: &TaskEpochStats, wall_s: f64) -> Result<TaskMetrics, RlError> {
        let results = self.task_success(self.training.eval_boards)?;
        Ok(task_metrics(&results, &self.progress, wall_s, stats))
    }
    fn save(&self, dir: &Path) -> Result<(), RlError> {
        TaskSac::save(self, dir)
    }
    fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        TaskSac::load(self, dir)
    }
    fn resume_only_files() -> Vec<&'static str> {
        crate::sac::RESUME_FILES
            .iter()
            .chain(&[REPLAY_FILE, TASK_PROGRESS_FILE])
            .copied()
            .collect()
    }
    /// Only the actor is read: older checkpoints keep nothing else.
    fn load_task_policy(
        config: &TrainConfig,
        spec: &seads_embodiment::EnvSpec,
        checkpoint: &std::path::Path,
    ) -> Result<Box<dyn crate::TaskPolicy>, RlError> {
        let mut sac = Sac::new(
            spec.obs_dim,
            &spec.action_low,
            &spec.action_high,
            &config.sac,
            config.device.resolve()?,
            0,
        );
        sac.load(checkpoint, true)?;
        Ok(Box::new(sac))
    }
}
