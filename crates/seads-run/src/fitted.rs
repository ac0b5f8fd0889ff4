//! A forward model fitted afterwards to a run's frozen skills (`seads fit-model`): where it lives
//! in the run directory and the record of how it was fitted, readable without libtorch.
//!
//! Any skill learner's skills can be planned with once a forward model q(z_T | z_0, k) is fitted
//! to them, so learners that learn no model of their own (DIAYN, VIC) compare with SEADS by
//! their skills alone. The model's weights sit in [`FITTED_MODEL`] beside the checkpoints and,
//! like them, are never committed; [`FIT_RECORD`] is.

use std::path::{Path, PathBuf};

use seads_planner::{CheckpointId, Evaluator};
use serde::{Deserialize, Serialize};

use crate::{RunError, SkillModelConfig};

/// The folder of a run's fitted model: its weights and [`FIT_RECORD`].
pub const FITTED_MODEL: &str = "fitted-model";

/// The record of the fit, in [`FITTED_MODEL`].
pub const FIT_RECORD: &str = "fit.json";

/// How a model is fitted: how many skill executions it learns from, how many gradient steps it
/// takes, and the seed every random choice of the fit flows from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitSettings {
    /// Skill executions collected, each from a fresh reset of a training board with a skill
    /// drawn uniformly, executed deterministically (as evaluations execute skills).
    pub episodes: usize,
    /// Gradient steps, each on a batch of the skill model's `batch_size` executions.
    pub updates: usize,
    /// The seed of the boards, the skills drawn, the initial weights and the batches.
    pub seed: u64,
}

impl FitSettings {
    /// One in this many executions is held out of training to measure the fit.
    pub const HELD_OUT_EVERY: usize = 10;

    /// The defaults: about as many executions and steps as SEADS's own model sees while
    /// training on a Cursor board for 5·10⁵ steps.
    pub fn standard(seed: u64) -> Self {
        Self {
            episodes: 20_000,
            updates: 20_000,
            seed,
        }
    }

    /// Checks the values: enough executions that some are held out, and at least one step.
    pub fn validate(&self) -> Result<(), RunError> {
        if self.episodes < Self::HELD_OUT_EVERY {
            return Err(RunError::Config(format!(
                "a fit needs at least {} skill executions (one in {} is held out), not {}",
                Self::HELD_OUT_EVERY,
                Self::HELD_OUT_EVERY,
                self.episodes
            )));
        }
        if self.updates == 0 {
            return Err(RunError::Config(
                "a fit needs at least one gradient step".into(),
            ));
        }
        Ok(())
    }
}

/// How well the fitted model explains the executions held out of its training.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitQuality {
    /// Executions held out.
    pub held_out: usize,
    /// Mean log q(z_T | z_0, k) of the held-out executions, in nats.
    pub log_likelihood: f64,
    /// Share of held-out executions whose board the model's most likely successor is exactly:
    /// how often the planner's prediction of a skill comes true.
    pub mode_accuracy: f64,
    /// Share of all executions that changed the board.
    pub changed: f64,
}

/// `fit.json`: which checkpoint's skills the model was fitted to, how, by which binary, and how
/// well it fits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitRecord {
    /// The checkpoint whose skills were executed.
    pub checkpoint: CheckpointId,
    /// Skills K (the width of the skill policy's one-hot input).
    pub num_skills: usize,
    /// The fit's settings.
    pub settings: FitSettings,
    /// The forward model's network and optimiser (the environment's SEADS preset).
    pub skill_model: SkillModelConfig,
    /// How well it fits.
    pub quality: FitQuality,
    /// The binary that fitted it.
    pub fitted_by: Vec<Evaluator>,
}

/// The folder of the fitted model of the run in `run`.
pub fn fitted_model_dir(run: &Path) -> PathBuf {
    run.join(FITTED_MODEL)
}

/// The record of the run's fitted model; `None` if it has none.
pub fn read_fit_record(run: &Path) -> Result<Option<FitRecord>, RunError> {
    let path = fitted_model_dir(run).join(FIT_RECORD);
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(RunError::unreadable(&path, e)),
    };
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| RunError::unreadable(&path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_reads_back_and_a_damaged_one_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        assert!(read_fit_record(dir.path()).unwrap().is_none());
        let record = FitRecord {
            checkpoint: CheckpointId {
                epoch: 7,
                env_steps: Some(700),
            },
            num_skills: 3,
            settings: FitSettings::standard(1),
            skill_model: SkillModelConfig::default(),
            quality: FitQuality {
                held_out: 2,
                log_likelihood: -0.5,
                mode_accuracy: 1.0,
                changed: 0.5,
            },
            fitted_by: Vec::new(),
        };
        std::fs::create_dir(fitted_model_dir(dir.path())).unwrap();
        let path = fitted_model_dir(dir.path()).join(FIT_RECORD);
        std::fs::write(&path, serde_json::to_string(&record).unwrap()).unwrap();
        assert_eq!(read_fit_record(dir.path()).unwrap(), Some(record));
        std::fs::write(&path, "{").unwrap();
        assert!(matches!(
            read_fit_record(dir.path()),
            Err(RunError::Unreadable { .. })
        ));
    }

    #[test]
    fn settings_refuse_a_fit_with_nothing_held_out_or_no_step() {
        assert!(FitSettings::standard(1).validate().is_ok());
        let few = FitSettings {
            episodes: FitSettings::HELD_OUT_EVERY - 1,
            ..FitSettings::standard(1)
        };
        assert!(few.validate().is_err());
        let idle = FitSettings {
            updates: 0,
            ..FitSettings::standard(1)
        };
        assert!(idle.validate().is_err());
    }
}
