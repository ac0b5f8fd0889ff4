//! The symbolic skill model of SEADS (SPEC §3.4–3.6, §3.9): the forward model q(z_T | z_0, k)
//! and the VIC discriminator behind [`SkillModel`], the intrinsic reward with its clip,
//! second-best normalisation and novelty bonus, and relabelling by a minimum-cost assignment.
//! Its networks are built from `seads-nn`'s blocks, as SAC's are.
//!
//! Architecture invariant: rewards and relabelling are plain functions on slices, testable
//! without a network.
//!
//! # Example: the reward of an episode, and relabelling
//!
//! ```
//! use seads_skillmodel::{RewardConfig, episode_rewards, relabel_assignment};
//!
//! // log q(z_T | z_0, k) for K = 3 skills: the effect is best explained by skill 1.
//! let scores = [-9.0, -0.1, -4.0];
//! let (clipped, rewards) = episode_rewards(&scores, true, &RewardConfig::default());
//! // The label that explains the effect earns most, and at least its margin over the runner-up.
//! assert!(rewards[1] > rewards[0] && rewards[1] > rewards[2]);
//! assert!(rewards[1] >= clipped[1] - clipped[2]);
//!
//! // Two episodes labelled 0 and 1, each better explained by the other's label: relabelling
//! // swaps them and keeps the multiset of labels.
//! let clipped = [-5.0, -0.1, /* episode 2: */ -0.2, -6.0];
//! assert_eq!(relabel_assignment(&clipped, 2, &[0, 1]), vec![1, 0]);
//! ```
//!
//! `cargo run -p seads-skillmodel --example fit` fits a forward model to the LightsOut move table
//! and measures how often its mode is the true successor.

mod build;
mod groundtruth;
mod mixture;
mod model;
mod relabel;
mod reward;
mod screen;

pub use build::BuildSkillModel;
pub use groundtruth::{agreement_with_game, fit_to_game, move_transitions};
pub use mixture::MixtureModel;

/// A skill model an agent plans with: its likelihoods ([`SkillModel`]) and its successors
/// ([`seads_games::Successor`]); the paper's [`ForwardModel`] and the [`MixtureModel`].
pub trait PlanningModel: SkillModel + seads_games::Successor {}

impl<T: SkillModel + seads_games::Successor> PlanningModel for T {}
pub use model::{
    ForwardModel, OPTIMISER_FILES, SkillDiscriminator, SkillModel, SkillModelConfig,
    SkillModelKind, SkillTransition, fast_int8_products,
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
