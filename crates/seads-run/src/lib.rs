//! A SEADS run's data, without libtorch: what a run is configured with and what its directory
//! holds, for the learners that write it (`seads-rl`) and for everything that only reads it
//! (reports, sweeps, the command line's status and plots).
//!
//! - [`TrainConfig`]: a run's configuration (`config.toml`): its settings, its environment and
//!   its learner ([`LearnerConfig`]: the algorithm and its section only, [`SeadsConfig`],
//!   [`BaselineConfig`] or [`HacConfig`]), with
//!   [`SacConfig`] and the skill model's settings ([`SkillModelConfig`]); the shipped presets of
//!   `configs/`; validated on load.
//! - [`store`]: the run directory: atomic writes, JSON Lines, `metrics.jsonl`, checkpoints'
//!   names, order and metadata, and the run's one writer ([`store::RunLock`]).
//! - [`Metrics`], [`TaskMetrics`]: the lines of `metrics.jsonl` of SEADS and of the baselines;
//!   [`tensorboard`]: the same lines as TensorBoard events beside them.
//! - [`PopulationKey`]: which runs can train in one population.
//! - [`fitted`]: a forward model fitted afterwards to a run's frozen skills, and its record.
//!
//! Architecture invariant: no libtorch in this crate's dependency tree (`tests/tidy.rs`).
//!
//! ```
//! use seads_run::TrainConfig;
//! let config = TrainConfig::from_user_toml("env = \"lightsout-cursor\"\nseed = 7", None, None)?;
//! assert_eq!((config.seed, config.sac.alpha), (7, TrainConfig::preset("lightsout-cursor")?.sac.alpha));
//! # Ok::<(), seads_run::RunError>(())
//! ```

mod config;
mod device;
pub mod fitted;
mod metrics;
mod population;
mod sac;
mod sections;
mod skill_model;
pub mod store;
pub mod tensorboard;

pub use config::{
    TrainConfig, config_difference, learner_names, machine_memory_bytes, merge_toml, preset_layers,
    section_name,
};
pub use device::{ComputeDevice, DeviceError};
pub use metrics::{Metrics, MetricsRecord, TaskMetrics, TaskTimings, Timings, read_metrics};
pub use population::{PopulationKey, check_population};
pub use sac::SacConfig;
pub use sections::{
    BaselineConfig, COVERAGE_SEED, HacConfig, LearnerConfig, MAX_PER_EPOCH, RelabelConfig,
    SeadsConfig, Section,
};
pub use skill_model::{
    DEFAULT_COMPONENTS, Normalisation, RelabelKind, RewardConfig, SkillModelConfig, SkillModelKind,
};
pub use store::{load_config, raise_budget};

use std::path::Path;

/// A boxed error kept as the source of another.
pub type BoxError = Box<dyn std::error::Error + Send + Sync>;

/// Errors of a run's configuration and of its directory's files.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A configuration value that cannot be used.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// The environment failed (a configuration's environment is built to check it).
    #[error(transparent)]
    Env(#[from] seads_embodiment::EnvError),
    /// Reading or writing a file failed.
    #[error("{path}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        #[source]
        source: BoxError,
    },
    /// A checkpoint is missing, corrupt or from another configuration.
    #[error("cannot load checkpoint {path}: {reason}")]
    Checkpoint {
        /// The checkpoint.
        path: String,
        /// What went wrong.
        reason: String,
    },
    /// A file of the run (a checkpoint's, a JSON Lines file's line) could not be read or parsed;
    /// `path` names it (`file:line` for a line).
    #[error("cannot read {path}")]
    Unreadable {
        /// The file.
        path: String,
        /// What went wrong.
        #[source]
        source: BoxError,
    },
    /// A run directory is damaged in a way resuming cannot repair without losing or inventing
    /// history (its metrics file or its checkpoints were removed).
    #[error("{dir}: {reason}; resuming refuses (restore it, or train a new run)")]
    Damaged {
        /// The run directory.
        dir: String,
        /// What is damaged.
        reason: String,
    },
    /// Another process writes into the run directory now.
    #[error("{dir} is in use by {holder}: one writer at a time")]
    Busy {
        /// The run directory.
        dir: String,
        /// Who holds it, as its lock file names it.
        holder: String,
    },
}

impl RunError {
    /// An [`RunError::Io`] on `path`.
    pub fn io(path: &Path, e: impl Into<BoxError>) -> Self {
        RunError::Io {
            path: path.display().to_string(),
            source: e.into(),
        }
    }

    /// An [`RunError::Unreadable`] on `path`.
    pub fn unreadable(path: &Path, e: impl Into<BoxError>) -> Self {
        RunError::Unreadable {
            path: path.display().to_string(),
            source: e.into(),
        }
    }
}
