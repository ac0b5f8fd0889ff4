//! The skill model's settings (`[seads.skill_model]`, `[seads.reward]`, `[seads.relabel]`'s
//! kind): which model, its network and optimiser, the reward's switches and how episodes are
//! relabelled. The model itself is `seads-skillmodel`'s.

use serde::{Deserialize, Serialize};

use crate::RunError;

/// Which skill model, and its network and optimiser. `Default` = the paper's forward model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SkillModelConfig {
    /// `forward` (SEADS), `mixture` (a mixture of forward models: effects that depend on the
    /// board stay coherent) or `vic` (skill discriminator, no planning).
    pub kind: SkillModelKind,
    /// Components of the `mixture` model (default [`DEFAULT_COMPONENTS`]); only with that kind.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub components: Option<usize>,
    /// Hidden layer sizes.
    pub hidden: Vec<i64>,
    /// Adam learning rate.
    pub lr: f64,
    /// Tuples per gradient step.
    pub batch_size: usize,
    /// Gradient steps per epoch.
    pub updates_per_epoch: usize,
}

impl Default for SkillModelConfig {
    fn default() -> Self {
        Self {
            kind: SkillModelKind::Forward,
            components: None,
            hidden: vec![256, 256],
            lr: 1e-3,
            batch_size: 32,
            updates_per_epoch: 4,
        }
    }
}

impl SkillModelConfig {
    /// Checks the values.
    pub fn validate(&self) -> Result<(), RunError> {
        let bad = |m: String| Err(RunError::Config(m));
        if self.hidden.is_empty() || self.hidden.iter().any(|&h| h <= 0) {
            return bad(format!(
                "skill_model.hidden must be positive layer sizes, got {:?}",
                self.hidden
            ));
        }
        if !(self.lr > 0.0 && self.lr.is_finite()) {
            return bad(format!("skill_model.lr must be positive, got {}", self.lr));
        }
        if self.batch_size == 0 {
            return bad("skill_model.batch_size must be at least 1".into());
        }
        match (self.kind, self.components) {
            (SkillModelKind::Mixture, Some(0)) => {
                return bad("skill_model.components must be at least 1".into());
            }
            (SkillModelKind::Mixture, _) | (_, None) => {}
            (kind, Some(_)) => {
                return bad(format!(
                    "skill_model.components belongs to kind = \"mixture\", not {kind:?}"
                ));
            }
        }
        Ok(())
    }

    /// The mixture model's number of components.
    pub fn mixture_components(&self) -> usize {
        self.components.unwrap_or(DEFAULT_COMPONENTS)
    }
}

/// Components of a mixture skill model unless its settings say otherwise: room for the few
/// outcomes a skill has from one board while it is still stochastic (its move, nothing, another
/// move), each kept whole in a component of its own.
pub const DEFAULT_COMPONENTS: usize = 4;

impl SkillModelKind {
    /// Whether the model predicts successors, so that an agent plans with it (not VIC's).
    pub fn plans(self) -> bool {
        matches!(self, Self::Forward | Self::Mixture)
    }
}

/// The kind of skill model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SkillModelKind {
    /// SEADS: the forward model q(z_T | z_0, k).
    Forward,
    /// A mixture of forward models q(z_T | z_0, k) = Σ_m π_m(z_0, k) Π_d Bern(flip_d; p_md):
    /// an effect that changes several bits together (a slide: the tile's and the gap's) stays
    /// one outcome of one component instead of being averaged bit by bit.
    Mixture,
    /// VIC: the discriminator q(k | z_0, z_T).
    Vic,
}

/// What replaces the second-best normalisation in the "no SBN" ablation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Normalisation {
    /// SEADS: subtract the second-largest clipped log-posterior.
    SecondBest,
    /// Add log K (the reference's alternative; plain VIC's choice).
    LogK,
    /// No normalisation.
    None,
}

/// Reward switches (the ablations of SPEC §3.10). `Default` = SEADS.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RewardConfig {
    /// Normalisation of the clipped log-posterior.
    pub normalisation: Normalisation,
    /// Add the novelty bonus (only defined for the forward model).
    pub novelty_bonus: bool,
}

impl Default for RewardConfig {
    fn default() -> Self {
        Self {
            normalisation: Normalisation::SecondBest,
            novelty_bonus: true,
        }
    }
}

/// How chosen episodes are relabelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RelabelKind {
    /// One linear assignment over all chosen episodes (SEADS).
    Assignment,
    /// Each episode independently gets `argmax_k C_e[k]` (not used in the paper).
    Max,
}
