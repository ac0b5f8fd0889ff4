//! The SEADS trainer as a [`Learner`]: its line of `metrics.jsonl` and its epochs.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::learner::{Learner, Moment};
use crate::store::{MetricsLine, read_metrics_as};
use crate::{EpochStats, RlError, Timings, TrainConfig, Trainer};

/// One line of `metrics.jsonl`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Metrics {
    /// Epochs completed.
    pub epoch: u64,
    /// Environment steps so far.
    pub env_steps: u64,
    /// Mean number of distinct game moves made by the skills (SPEC §4.5).
    pub skill_coverage: f64,
    /// Wall-clock seconds since the run started (across resumes).
    pub wall_s: f64,
    /// Mean final reward of the last SAC batch.
    pub mean_reward: f32,
    /// Fraction of the last epoch's new episodes that changed the board.
    pub changed: f32,
    /// Last skill-model loss.
    pub skill_model_loss: f32,
    /// Last critic loss.
    pub critic_loss: f32,
    /// Last actor loss.
    pub actor_loss: f32,
    /// Environment steps per wall-clock second since the start of the run.
    pub steps_per_s: f64,
    /// Seconds per phase since the start of the run.
    pub timings: Timings,
}

impl MetricsLine for Metrics {
    fn epoch(&self) -> u64 {
        self.epoch
    }
    fn wall_s(&self) -> f64 {
        self.wall_s
    }
    fn env_steps(&self) -> u64 {
        self.env_steps
    }
    fn steps_per_s(&self) -> f64 {
        self.steps_per_s
    }
}

/// The lines of `dir/metrics.jsonl`. A last line without its newline is the trace of a crash
/// during the append and is left out; any other line that does not parse is an error.
pub fn read_metrics(dir: &Path) -> Result<Vec<Metrics>, RlError> {
    read_metrics_as(dir)
}

impl Learner for Trainer {
    type Stats = EpochStats;
    type Metrics = Metrics;

    fn build(config: TrainConfig) -> Result<Self, RlError> {
        Trainer::new(config)
    }
    fn config(&self) -> &TrainConfig {
        Trainer::config(self)
    }
    fn epoch(&self) -> u64 {
        Trainer::epoch(self)
    }
    fn finished(&self) -> bool {
        Trainer::finished(self)
    }
    fn run_epoch_observed(&mut self, hook: &mut dyn FnMut(Moment)) -> Result<EpochStats, RlError> {
        Trainer::run_epoch_observed(self, hook)
    }
    fn metrics(&mut self, stats: &EpochStats, wall_s: f64) -> Result<Metrics, RlError> {
        let skill_coverage = self.skill_coverage()?;
        Ok(Metrics {
            epoch: self.epoch(),
            env_steps: self.env_steps(),
            skill_coverage,
            wall_s,
            mean_reward: stats.mean_reward,
            changed: stats.changed,
            skill_model_loss: stats.skill_model_loss,
            critic_loss: stats.sac.critic,
            actor_loss: stats.sac.actor,
            steps_per_s: self.env_steps() as f64 / wall_s.max(1e-9),
            timings: self.timings(),
        })
    }
    fn save(&self, dir: &Path) -> Result<(), RlError> {
        Trainer::save(self, dir)
    }
    fn load(&mut self, dir: &Path) -> Result<(), RlError> {
        Trainer::load(self, dir)
    }
    fn resume_only_files() -> Vec<&'static str> {
        crate::checkpoint::resume_only_files()
    }
    fn load_task_policy(
        _: &TrainConfig,
        _: &seads_embodiment::EnvSpec,
        _: &std::path::Path,
    ) -> Result<Box<dyn crate::TaskPolicy>, RlError> {
        Err(RlError::Config(
            "a SEADS run has skills and a forward model, not a task policy; plan with it".into(),
        ))
    }
}
