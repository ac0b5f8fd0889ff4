//! What a [`Run`](crate::Run) drives: a learner whose whole state a checkpoint folder holds,
//! and the moments inside its epochs at which a crash leaves a different state on disk.

use std::path::Path;

use seads_embodiment::EnvSpec;

use crate::store::MetricsLine;
use crate::task_policy::TaskPolicy;
use crate::{RlError, TrainConfig};

/// What a [`Run`](crate::Run) drives: an agent in training whose whole state a checkpoint folder holds.
/// [`Trainer`](crate::Trainer) (SEADS) and [`TaskSac`](crate::TaskSac) (the task-reward baseline) are learners.
pub trait Learner: Sized {
    /// Its section of the configuration, whose [`Section::ALGORITHM`](seads_run::Section) is the
    /// learner's name in the registry ([`learners`](crate::learners)).
    type Section: seads_run::Section;
    /// What one epoch reports.
    type Stats: Clone + Send;
    /// One line of `metrics.jsonl`.
    type Metrics: MetricsLine + Clone + Send;
    /// A fresh learner for `config` (validated).
    fn build(config: TrainConfig) -> Result<Self, RlError>;
    /// The configuration.
    fn config(&self) -> &TrainConfig;
    /// Epochs completed.
    fn epoch(&self) -> u64;
    /// Whether the step budget is spent.
    fn finished(&self) -> bool;
    /// One epoch, calling `hook` at the [`Moment`]s inside it.
    fn run_epoch_observed(&mut self, hook: &mut dyn FnMut(Moment)) -> Result<Self::Stats, RlError>;
    /// The evaluation after an epoch, as a metrics line (`wall_s`: the run's seconds so far).
    fn metrics(&mut self, stats: &Self::Stats, wall_s: f64) -> Result<Self::Metrics, RlError>;
    /// Writes the complete state into the folder `dir`.
    fn save(&self, dir: &Path) -> Result<(), RlError>;
    /// Restores what [`Learner::save`] wrote.
    fn load(&mut self, dir: &Path) -> Result<(), RlError>;
    /// The checkpoint files only resuming needs, dropped from all but the two newest.
    fn resume_only_files() -> Vec<&'static str>;
    /// The task policy in a checkpoint folder of a run with `config` on an environment of
    /// `spec`, for a learner trained with the task reward; an error for one that learns skills
    /// (they plan instead).
    fn load_task_policy(
        config: &TrainConfig,
        spec: &EnvSpec,
        checkpoint: &Path,
    ) -> Result<Box<dyn TaskPolicy>, RlError>;
}

/// Moments of a run at which a crash leaves a different state on disk. A hook set with
/// [`Run::set_hook`](crate::Run::set_hook) is called at each (the crash-point tests stop the process there).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Moment {
    /// An epoch's episodes are collected; its updates have not started.
    Collected,
    /// The next epoch's updates are prepared while this epoch's SAC steps may still run.
    Prepared,
    /// An epoch is complete in memory; nothing of it is on disk yet.
    EpochDone,
    /// An evaluation line was appended to `metrics.jsonl`.
    MetricsAppended,
    /// A checkpoint's files are written in its temporary folder, not yet renamed.
    CheckpointWritten,
    /// A checkpoint folder is in place; `latest` still names the previous one.
    CheckpointRenamed,
    /// `latest` names the new checkpoint; older ones still hold their resume files.
    LatestWritten,
}

impl Moment {
    /// A short name (`collected`, `metrics-appended`, …).
    pub fn name(self) -> &'static str {
        match self {
            Moment::Collected => "collected",
            Moment::Prepared => "prepared",
            Moment::EpochDone => "epoch-done",
            Moment::MetricsAppended => "metrics-appended",
            Moment::CheckpointWritten => "checkpoint-written",
            Moment::CheckpointRenamed => "checkpoint-renamed",
            Moment::LatestWritten => "latest-written",
        }
    }
}

/// A hook called at every [`Moment`].
pub type Hook = Box<dyn FnMut(Moment) + Send>;
