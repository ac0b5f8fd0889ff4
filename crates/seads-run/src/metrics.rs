//! The lines of a run's `metrics.jsonl`: SEADS's ([`Metrics`], skill coverage) and the
//! task-reward baselines' ([`TaskMetrics`], task success), each with its wall time and phases;
//! and any learner's line as a reader sees it ([`MetricsRecord`]).

use std::collections::BTreeMap;
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

/// A line of any learner's `metrics.jsonl` as reports read it: what every learner's line has
/// (epoch, steps, wall time, and its phases by name in `timings`), and what it measured, by the
/// field's name, where it measured it. A learner's line describes itself, so that reading runs
/// needs no list per algorithm: a new learner whose line has these fields is reported as it is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MetricsRecord {
    /// Epochs completed.
    pub epoch: u64,
    /// Environment steps so far.
    pub env_steps: u64,
    /// Wall-clock seconds since the run started (across resumes).
    pub wall_s: f64,
    /// Environment steps per wall-clock second since the start of the run.
    pub steps_per_s: f64,
    /// Seconds per phase since the start of the run, by the learner's names (`collect`, `sac`,
    /// `evaluate`, …).
    pub timings: BTreeMap<String, f64>,
    /// Skill coverage (SPEC §4.5), where the learner measures it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skill_coverage: Option<f64>,
    /// Share of the test boards solved per depth, where the learner measures task success.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub success: Option<Vec<f64>>,
    /// Mean of `success`, as the learner wrote it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_success: Option<f64>,
}

impl MetricsLine for MetricsRecord {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// SEADS's and a baseline's lines, as they write them, read as records with their own
    /// phases and measures; the fields a record does not know are skipped.
    #[test]
    fn every_learners_line_reads_as_a_record() {
        let seads = Metrics {
            epoch: 3,
            env_steps: 960,
            skill_coverage: 12.5,
            wall_s: 4.0,
            mean_reward: 0.5,
            changed: 0.25,
            skill_model_loss: 0.1,
            critic_loss: 0.2,
            actor_loss: 0.3,
            steps_per_s: 240.0,
            timings: Timings {
                collect: 1.0,
                relabel: 2.0,
                skill_model: 0.5,
                sac: 1.5,
                evaluate: 0.25,
            },
        };
        let record: MetricsRecord =
            serde_json::from_str(&serde_json::to_string(&seads).unwrap()).unwrap();
        assert_eq!((record.epoch, record.env_steps), (3, 960));
        assert_eq!(record.skill_coverage, Some(12.5));
        assert_eq!(record.success, None);
        let phases: Vec<(&str, f64)> = record
            .timings
            .iter()
            .map(|(k, v)| (k.as_str(), *v))
            .collect();
        assert_eq!(
            phases,
            [
                ("collect", 1.0),
                ("evaluate", 0.25),
                ("relabel", 2.0),
                ("sac", 1.5),
                ("skill_model", 0.5)
            ]
        );
        let task = TaskMetrics {
            epoch: 5,
            env_steps: 40,
            wall_s: 2.0,
            success: vec![0.5, 0.25],
            mean_success: 0.375,
            train_solved: 0.0,
            critic_loss: 0.1,
            actor_loss: 0.1,
            steps_per_s: 20.0,
            timings: TaskTimings {
                collect: 1.0,
                sac: 0.5,
                evaluate: 0.5,
            },
            subgoals_reached: None,
        };
        let record: MetricsRecord =
            serde_json::from_str(&serde_json::to_string(&task).unwrap()).unwrap();
        assert_eq!(record.skill_coverage, None);
        assert_eq!(record.success, Some(vec![0.5, 0.25]));
        assert_eq!(record.mean_success, Some(0.375));
        assert_eq!(record.timings.len(), 3);
    }
}
