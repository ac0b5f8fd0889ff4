//! Reinforcement learning for SEADS: soft actor-critic on tch (SPEC §3.2) and the SEADS training
//! loop of Algorithm 3 (SPEC §3.3, §3.7) — episode collection in lockstep with batched policy
//! calls, long- and short-term episode buffers, relabelling with the skill model, skill-model and
//! SAC updates, skill coverage, checkpoints and run directories. Beside SEADS, the two baselines
//! trained with the task reward (SPEC §5): flat SAC ([`TaskSac`]) and two-level HAC ([`Hac`]),
//! driven by the same [`Run`] and evaluated on the same protocol ([`task_success`]).
//!
//! Architecture invariant: with `seads-skillmodel`, the only crate that links libtorch. No
//! printing; the binary shows progress from the values [`Run::step`] returns. Every random
//! choice comes from streams seeded by the run's seed (network initialisation included), never
//! from libtorch's global generator.
//!
//! # Example: a few training epochs from code
//!
//! ```
//! use seads_rl::{TrainConfig, Trainer};
//!
//! // The paper's LightsOutCursor settings, shrunk so that the example runs in seconds.
//! let mut config = TrainConfig::preset("lightsout-cursor")?;
//! config.sac.hidden = vec![32, 32];
//! config.edit(|seads: &mut seads_rl::SeadsConfig| {
//!     seads.skill_model.hidden = vec![32, 32];
//!     (seads.sampled_episodes, seads.recent_episodes) = (32, 16);
//!     seads.eval_seeds = 2;
//! })?;
//! let mut trainer = Trainer::new(config)?;
//! for _ in 0..3 {
//!     let stats = trainer.run_epoch()?; // collect 32 episodes, relabel, update the model and SAC
//!     assert!(stats.mean_reward.is_finite());
//! }
//! assert_eq!(trainer.epoch(), 3);
//! let coverage = trainer.skill_coverage()?; // distinct moves of the K skills, 0..=25
//! assert!((0.0..=25.0).contains(&coverage));
//! # Ok::<(), seads_rl::RlError>(())
//! ```
//!
//! [`Run`] does the same into a run directory (metrics, checkpoints, exact resume); see
//! `cargo run --release -p seads-rl --example train`.

mod agent;
mod buffers;
mod checkpoint;
mod episode;
mod fit_model;
mod hac;
mod in_words;
mod learner;
pub mod learners;
mod metrics;
mod numerics;
mod population;
mod relaxed;
mod replay;
mod run;
mod sac;
mod seeds;
mod stacked;
mod stacked_population;
mod task_episodes;
mod task_policy;
mod task_sac;
mod trainer;

use std::path::Path;

pub use agent::{Agent, AgentPolicy, find_checkpoint, load_policy};
pub use buffers::{RelabelBatch, Relabelling};
pub use episode::{Episode, run_episodes, skill_coverage};
pub use fit_model::{FitProgress, collect_transitions, fit_model, fit_settings_of, train_model};
pub use hac::{Hac, HacPolicy};
pub use in_words::{BaselineInWords, InWords};
pub use learner::{Hook, Learner, Moment};
pub use learners::{WithLearner, with_learner};
pub use numerics::{PORTABLE_KERNELS, kernel_environment, portable_kernels_active};
pub use population::{Members, Population};
pub use relaxed::RelaxedBernoulli;
pub use run::{Run, RunEvent};
pub use sac::{Sac, SacLosses, TransitionBatch, checkpoint_files};
pub use seeds::{Purpose, derived_seed, stream};
pub use stacked_population::StackedPopulation;
pub use task_episodes::{TaskEpochStats, updates_due};
pub use task_policy::{TaskPolicy, task_success};
pub use task_sac::TaskSac;
pub use trainer::{COVERAGE_SEED, EpochStats, Trainer};
// A run's data (configuration, directory, metrics lines) is `seads-run`'s, re-exported here for
// the learners and their users.
pub use seads_run::{
    BaselineConfig, ComputeDevice, DeviceError, HacConfig, LearnerConfig, Metrics, PopulationKey,
    RelabelConfig, RunError, SacConfig, SeadsConfig, Section, TaskMetrics, TaskTimings, Timings,
    TrainConfig, check_population, learner_names, load_config, machine_memory_bytes, merge_toml,
    raise_budget, read_metrics, section_name, store,
};

/// Sets the number of libtorch intra-op threads of the process.
pub fn set_threads(n: usize) {
    tch::set_num_threads(n as i32);
}

/// A boxed error kept as the source of another.
pub type BoxError = Box<dyn std::error::Error + Send + Sync>;

/// Errors of training and checkpoints. What concerns a run's data (its configuration and
/// files) is [`RlError::Run`], with `seads-run`'s kinds: a bad configuration is
/// `RlError::Run(RunError::Config(_))`, a busy run `RlError::Run(RunError::Busy { .. })`.
#[derive(Debug, thiserror::Error)]
pub enum RlError {
    /// A run's configuration or files: a bad value, a file that cannot be read or written, a
    /// damaged checkpoint or run directory, another writer.
    #[error(transparent)]
    Run(#[from] RunError),
    /// The device asked for is not there.
    #[error(transparent)]
    Device(#[from] seads_nn::DeviceError),
    /// The skill model failed.
    #[error(transparent)]
    SkillModel(#[from] seads_skillmodel::SkillModelError),
    /// A run with evaluation lines has no checkpoints folder: its checkpoints were removed (a
    /// run copied without them, as `seads report --copy-runs` does). Training it again from
    /// scratch would replace the metrics it holds, so resuming refuses.
    #[error(
        "{dir} holds {lines} evaluation line(s) but no checkpoints folder (copied without its \
         checkpoints?): it cannot be resumed, and training it again would overwrite its metrics"
    )]
    CheckpointsMissing {
        /// The run directory.
        dir: String,
        /// Lines in its metrics file.
        lines: usize,
    },
    /// A member of a population failed.
    #[error("{dir}")]
    Member {
        /// The member's run directory.
        dir: String,
        /// What went wrong.
        #[source]
        source: Box<RlError>,
    },
    /// A run that has written checkpoints has none that can be loaded.
    #[error("{dir}: none of its {tried} checkpoint(s) can be loaded; the newest")]
    NoCheckpoint {
        /// The checkpoints folder.
        dir: String,
        /// How many checkpoints were tried.
        tried: usize,
        /// Why the newest could not be loaded.
        #[source]
        source: Box<RlError>,
    },
}

/// The environment failed: a run's environment, as `seads-run` reports it.
impl From<seads_embodiment::EnvError> for RlError {
    fn from(e: seads_embodiment::EnvError) -> Self {
        RlError::Run(RunError::Env(e))
    }
}

impl RlError {
    /// A configuration value that cannot be used ([`RunError::Config`]).
    pub fn config(message: impl Into<String>) -> Self {
        RlError::Run(RunError::Config(message.into()))
    }

    /// A checkpoint that is missing, corrupt or from another configuration
    /// ([`RunError::Checkpoint`]).
    pub fn checkpoint(path: impl Into<String>, reason: impl Into<String>) -> Self {
        RlError::Run(RunError::Checkpoint {
            path: path.into(),
            reason: reason.into(),
        })
    }

    fn io(path: &Path, e: impl Into<BoxError>) -> Self {
        RlError::Run(RunError::io(path, e))
    }

    fn unreadable(path: &Path, e: impl Into<BoxError>) -> Self {
        RlError::Run(RunError::unreadable(path, e))
    }
}

#[cfg(test)]
mod tests {
    use tch::nn::{self, Module, OptimizerConfig};
    use tch::{Device, Kind, Tensor};

    /// libtorch is installed and linked: one Adam step of a small MLP lowers its loss.
    #[test]
    fn tch_smoke_adam_step_lowers_loss() {
        let vs = nn::VarStore::new(Device::Cpu);
        let net = nn::seq()
            .add(nn::linear(vs.root() / "l1", 4, 16, Default::default()))
            .add_fn(|x| x.relu())
            .add(nn::linear(vs.root() / "l2", 16, 1, Default::default()));
        let mut opt = nn::Adam::default().build(&vs, 1e-2).expect("optimizer");
        let x = Tensor::from_slice(
            &(0..256)
                .map(|i| ((i * 37 % 101) as f32 - 50.0) / 25.0)
                .collect::<Vec<_>>(),
        )
        .view([64, 4]);
        let y = x.sum_dim_intlist(1, true, Kind::Float);
        let loss = |net: &nn::Sequential| (net.forward(&x) - &y).square().mean(Kind::Float);
        let before = f64::try_from(loss(&net)).unwrap();
        opt.backward_step(&loss(&net));
        let after = f64::try_from(loss(&net)).unwrap();
        assert!(after < before, "loss {before} -> {after}");
    }
}
