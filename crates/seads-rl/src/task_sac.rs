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

use std::path::Path;
use std::time::Instant;

use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, EnvSpec, TaskEnv, make_env};
use seads_games::Split;
use seads_planner::{DepthResult, TaskSet};
use serde::{Deserialize, Serialize};
use tch::Device;

use crate::learner::Learner;
use crate::replay::Replay;
use crate::store::MetricsLine;
use crate::{Moment, Purpose, RlError, Sac, SacLosses, TrainConfig};
use crate::{derived_seed, stream, task_success};

/// The replay buffer of a run's checkpoint.
pub const REPLAY_FILE: &str = "replay.safetensors";
/// Epoch, steps, random streams and open episodes of a run's checkpoint.
pub const TASK_PROGRESS_FILE: &str = "task-progress.json";

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

impl Streams {
    pub(crate) fn new(seed: u64) -> Self {
        Self {
            collect: stream(seed, Purpose::Collect),
            sample: stream(seed, Purpose::Sample),
            sac: stream(seed, Purpose::Sac),
        }
    }
}

/// The environments of a baseline in training: task mode on the train split.
pub(crate) fn training_envs(config: &TrainConfig) -> Result<Vec<TaskEnv>, RlError> {
    let train = EnvConfig {
        reset_split: Split::Train,
        ..config.env_config.clone()
    };
    let max_depth = train.max_solution_depth;
    (0..config.baseline.samples_per_epoch)
        .map(|_| Ok(TaskEnv::new(make_env(&config.env, &train)?, max_depth)?))
        .collect()
}

/// Seconds per phase since the start of the run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TaskTimings {
    /// Environment steps and policy calls.
    pub collect: f64,
    /// SAC gradient steps.
    pub sac: f64,
    /// Task-success evaluations.
    pub evaluate: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct Progress {
    epoch: u64,
    env_steps: u64,
    /// Episodes started, over all environments (numbers their seeds).
    episodes: u64,
    /// Episodes ended, and how many of them solved their board.
    ended: u64,
    solved: u64,
    timings: TaskTimings,
    streams: Streams,
    open: Vec<OpenEpisode>,
}

/// What one epoch of the baseline did.
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

/// One line of a baseline run's `metrics.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskMetrics {
    /// Epochs completed.
    pub epoch: u64,
    /// Environment steps so far.
    pub env_steps: u64,
    /// Wall-clock seconds since the run started (across resumes).
    pub wall_s: f64,
    /// Share of the test boards solved per depth 1–5, deterministic policy.
    pub success: Vec<f64>,
    /// Mean of `success`.
    pub mean_success: f64,
    /// Share of the training episodes ended so far that solved their board.
    pub train_solved: f64,
    /// Last critic loss.
    pub critic_loss: f32,
    /// Last actor loss.
    pub actor_loss: f32,
    /// Environment steps per wall-clock second since the start of the run.
    pub steps_per_s: f64,
    /// Seconds per phase since the start of the run.
    pub timings: TaskTimings,
    /// HAC: share of the subgoal attempts ended since the previous line that reached their
    /// subgoal (absent for SAC).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subgoals_reached: Option<f64>,
}

impl TaskMetrics {
    /// The line after `(epoch, env_steps)` for the per-depth `results` of an evaluation.
    pub(crate) fn new(
        results: &[DepthResult],
        (epoch, env_steps): (u64, u64),
        wall_s: f64,
        train_solved: f64,
        stats: &TaskEpochStats,
        timings: TaskTimings,
    ) -> Self {
        let success: Vec<f64> = results
            .iter()
            .map(|r| r.solved as f64 / r.tasks.max(1) as f64)
            .collect();
        Self {
            epoch,
            env_steps,
            wall_s,
            mean_success: success.iter().sum::<f64>() / success.len().max(1) as f64,
            success,
            train_solved,
            critic_loss: stats.sac.critic,
            actor_loss: stats.sac.actor,
            steps_per_s: env_steps as f64 / wall_s.max(1e-9),
            timings,
            subgoals_reached: None,
        }
    }
}

impl MetricsLine for TaskMetrics {
    fn epoch(&self) -> u64 {
        self.epoch
    }
    fn wall_s(&self) -> f64 {
        self.wall_s
    }
}

/// A flat SAC agent in training on the task reward.
pub struct TaskSac {
    config: TrainConfig,
    spec: EnvSpec,
    envs: Vec<TaskEnv>,
    /// The current observation of each environment.
    obs: Vec<Vec<f32>>,
    /// Where the next observation is written before it becomes the current one (no allocation
    /// per environment step).
    next_obs: Vec<f32>,
    sac: Sac,
    replay: Replay,
    progress: Progress,
}

/// Gradient steps due after epoch `epoch` (0-based) at N per epoch: ⌊(e+1)·N⌋ − ⌊e·N⌋, so that
/// N = 0.25 steps once every 4 epochs and N = 2 twice per epoch.
pub fn updates_due(epoch: u64, per_epoch: f64) -> usize {
    let at = |e: u64| (e as f64 * per_epoch).floor();
    (at(epoch + 1) - at(epoch)).max(0.0) as usize
}

impl TaskSac {
    /// A fresh agent for `config` (validated; `config.algorithm` is not checked here).
    pub fn new(config: TrainConfig) -> Result<Self, RlError> {
        config.validate()?;
        crate::numerics::check(config.portable_numerics)?;
        if config.threads > 0 {
            tch::set_num_threads(config.threads as i32);
        }
        let envs = training_envs(&config)?;
        let spec = envs[0].spec().clone();
        let sac = Sac::new(
            spec.obs_dim,
            &spec.action_low,
            &spec.action_high,
            &config.sac,
            Device::Cpu,
            derived_seed(config.seed, Purpose::SacInit, 0),
        );
        let replay = Replay::new(
            config.baseline.replay_capacity,
            spec.obs_dim,
            spec.action_dim,
        );
        let progress = Progress {
            epoch: 0,
            env_steps: 0,
            episodes: 0,
            ended: 0,
            solved: 0,
            timings: TaskTimings::default(),
            streams: Streams::new(config.seed),
            open: Vec::new(),
        };
        let mut agent = Self {
            obs: vec![Vec::new(); envs.len()],
            next_obs: vec![0.0; spec.obs_dim],
            config,
            spec,
            envs,
            sac,
            replay,
            progress,
        };
        for slot in 0..agent.envs.len() {
            agent.start_episode(slot)?;
        }
        Ok(agent)
    }

    /// Resets environment `slot` for the next episode, seeded by the episode's number.
    fn start_episode(&mut self, slot: usize) -> Result<(), RlError> {
        let seed = derived_seed(self.config.seed, Purpose::TrainEnvs, self.progress.episodes);
        self.progress.episodes += 1;
        let env = &mut self.envs[slot];
        env.seed(seed);
        env.reset()?;
        self.obs[slot].resize(self.spec.obs_dim, 0.0);
        env.observe(&mut self.obs[slot]);
        let open = OpenEpisode {
            seed,
            actions: Vec::new(),
        };
        match self.progress.open.get_mut(slot) {
            Some(o) => *o = open,
            None => self.progress.open.push(open),
        }
        Ok(())
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
        let a = self.spec.action_dim;
        for slot in 0..self.envs.len() {
            let action = &actions[slot * a..(slot + 1) * a];
            let step = self.envs[slot].step(action)?;
            self.envs[slot].observe(&mut self.next_obs);
            self.replay.push(
                &self.obs[slot],
                action,
                step.reward,
                &self.next_obs,
                step.done,
            );
            self.progress.open[slot].actions.extend_from_slice(action);
            std::mem::swap(&mut self.obs[slot], &mut self.next_obs);
            if step.done {
                self.progress.ended += 1;
                self.progress.solved += u64::from(step.solved);
                self.start_episode(slot)?;
            }
        }
        self.progress.env_steps += self.envs.len() as u64;
        self.progress.timings.collect += start.elapsed().as_secs_f64();

        let start = Instant::now();
        let mut updates = 0;
        let mut total = SacLosses::default();
        if self.replay.len() >= self.config.sac.batch_size {
            for _ in 0..updates_due(self.progress.epoch, self.config.baseline.updates_per_epoch) {
                let batch = self.replay.sample(
                    self.config.sac.batch_size,
                    &mut self.progress.streams.sample,
                );
                let l = self.sac.update(&batch, &mut self.progress.streams.sac);
                total.critic += l.critic;
                total.actor += l.actor;
                total.q += l.q;
                updates += 1;
            }
        }
        self.progress.timings.sac += start.elapsed().as_secs_f64();
        self.progress.epoch += 1;
        let n = updates.max(1) as f32;
        Ok(TaskEpochStats {
            epoch: self.progress.epoch,
            env_steps: self.progress.env_steps,
            updates,
            sac: SacLosses {
                critic: total.critic / n,
                actor: total.actor / n,
                q: total.q / n,
            },
        })
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
        let path = dir.join(TASK_PROGRESS_FILE);
        let text = serde_json::to_string(&self.progress).map_err(|e| RlError::io(&path, e))?;
        std::fs::write(&path, text).map_err(|e| RlError::io(&path, e))
    }

    /// Restores what [`TaskSac::save`] wrote, replaying each environment's open episode.
    pub fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        self.sac.load(dir, false)?;
        self.replay.load(&dir.join(REPLAY_FILE))?;
        let path = dir.join(TASK_PROGRESS_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| RlError::io(&path, e))?;
        let progress: Progress =
            serde_json::from_str(&text).map_err(|e| RlError::unreadable(&path, e))?;
        if progress.open.len() != self.envs.len() {
            return Err(RlError::Checkpoint {
                path: path.display().to_string(),
                reason: format!(
                    "{} open episodes for {} environments",
                    progress.open.len(),
                    self.envs.len()
                ),
            });
        }
        let a = self.spec.action_dim;
        for (slot, open) in progress.open.iter().enumerate() {
            let env = &mut self.envs[slot];
            env.seed(open.seed);
            env.reset()?;
            for action in open.actions.chunks(a) {
                env.step(action)?;
            }
            let mut obs = vec![0.0; self.spec.obs_dim];
            env.observe(&mut obs);
            self.obs[slot] = obs;
        }
        self.progress = progress;
        Ok(())
    }
}

impl Learner for TaskSac {
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
        let results = self.task_success(self.config.baseline.eval_boards)?;
        let p = &self.progress;
        Ok(TaskMetrics::new(
            &results,
            (p.epoch, p.env_steps),
            wall_s,
            p.solved as f64 / p.ended.max(1) as f64,
            stats,
            p.timings,
        ))
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
}
