//! The lines of a run's `metrics.jsonl`: SEADS's ([`Metrics`], skill coverage) and the
//! task-reward baselines' ([`TaskMetrics`], task success), each with its wall time and phases.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::RunError;
use crate::store::{MetricsLine, read_metrics_as};

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
pub fn read_metrics(dir: &Path) -> Result<Vec<Metrics>, RunError> {
    read_metrics_as(dir)
}

/// Seconds spent per phase since the start of the run (the epoch profile). Relabelling and the
/// skill-model steps run beside SAC (see `seads-rl`'s `Trainer::run_epoch`), so the phases add up to more
/// than the wall time.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
pub struct Timings {
    /// Episode collection (environment steps and policy calls).
    pub collect: f64,
    /// Skill-model scores, rewards and assignments for both batches, and SAC minibatch assembly.
    pub relabel: f64,
    /// Skill-model gradient steps.
    pub skill_model: f64,
    /// SAC gradient steps.
    pub sac: f64,
    /// Skill-coverage evaluations.
    pub evaluate: f64,
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

impl MetricsLine for TaskMetrics {
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
