//! The SEADS trainer as a [`Learner`]: its line of `metrics.jsonl` and its epochs.

use std::path::Path;

use crate::learner::{Learner, Moment};
use crate::{EpochStats, Metrics, RlError, TrainConfig, Trainer};

impl Learner for Trainer {
    type Section = crate::SeadsConfig;
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
        Err(RlError::config(
            "a SEADS run has skills and a forward model, not a task policy; plan with it",
        ))
    }
}
