//! The skill model's settings (`[seads.skill_model]`, `[seads.reward]`, `[seads.relabel]`'s
//! kind): which model, its network and optimiser, the reward's switches and how episodes are
//! relabelled. The model itself is `seads-skillmodel`'s.

use serde::{Deserialize, Serialize};

use crate::RunError;

/// Which skill model, and its network and optimiser. `Default` = the paper's forward model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SkillModelConfig {
    /// `forward` (SEADS) or `vic` (skill discriminator, no planning).
    pub kind: SkillModelKind,
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
        Ok(())
    }
}

/// The kind of skill model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SkillModelKind {
    /// SEADS: the forward model q(z_T | z_0, k).
    Forward,
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
