//! The symbolic skill model of SEADS (SPEC §3.4–3.6, §3.9): the forward model q(z_T | z_0, k)
//! and the VIC discriminator behind [`SkillModel`], the intrinsic reward with its clip,
//! second-best normalisation and novelty bonus, and relabelling by a minimum-cost assignment.
//! It also holds the small tch building blocks ([`nn::Mlp`], [`nn::Adam`]) that `seads-rl` reuses.
//!
//! Architecture invariant: with `seads-rl`, the only crate that links libtorch. Rewards and
//! relabelling are plain functions on slices, testable without a network.

mod groundtruth;
mod model;
pub mod nn;
mod relabel;
mod reward;

pub use groundtruth::{agreement_with_game, fit_to_game};
pub use model::{
    ForwardModel, OPTIMISER_FILES, SkillDiscriminator, SkillModel, SkillModelConfig,
    SkillModelKind, SkillTransition,
};
pub use relabel::{RelabelKind, relabel, relabel_assignment, relabel_max};
pub use reward::{
    Normalisation, RewardConfig, clipped_log_posterior, episode_rewards, minimum_reward,
    novelty_bonus, second_best_normalisation, skill_log_posterior,
};

/// Errors of the skill models.
#[derive(Debug, thiserror::Error)]
pub enum SkillModelError {
    /// Writing a checkpoint failed.
    #[error("writing skill-model checkpoint {path}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        #[source]
        source: tch::TchError,
    },
    /// A configuration value that cannot be used.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// A checkpoint is missing, corrupt or of another shape.
    #[error("cannot load skill-model checkpoint {path}: {reason}")]
    Checkpoint {
        /// The file.
        path: String,
        /// What went wrong.
        reason: String,
    },
}
