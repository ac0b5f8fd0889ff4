//! The soft actor-critic's settings (`[sac]`): every learner trains SAC (the baselines' with the
//! task reward, SEADS's with its intrinsic one). The agent itself is `seads-rl`'s.

use serde::{Deserialize, Serialize};

use crate::RunError;

/// SAC hyper-parameters. `Default` = the reference's SEADS settings (Cursor α).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SacConfig {
    /// Hidden layer sizes of actor and critics (reference code: [256, 256]; the paper's table
    /// says 512).
    pub hidden: Vec<i64>,
    /// Adam learning rate of actor and critics.
    pub lr: f64,
    /// Discount γ.
    pub gamma: f64,
    /// Polyak coefficient τ of the target critics.
    pub tau: f64,
    /// Fixed entropy temperature α.
    pub alpha: f64,
    /// Transitions per gradient step (how many steps an epoch takes is the learner's: its
    /// section's `updates_per_epoch`).
    pub batch_size: usize,
}

impl Default for SacConfig {
    fn default() -> Self {
        Self {
            hidden: vec![256, 256],
            lr: 3e-4,
            gamma: 0.99,
            tau: 0.005,
            alpha: 0.1,
            batch_size: 128,
        }
    }
}

impl SacConfig {
    /// Checks the values.
    pub fn validate(&self) -> Result<(), RunError> {
        let bad = |m: String| Err(RunError::Config(m));
        if self.hidden.is_empty() || self.hidden.iter().any(|&h| h <= 0) {
            return bad(format!(
                "sac.hidden must be positive layer sizes, got {:?}",
                self.hidden
            ));
        }
        let positive = |name: &str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                bad(format!("sac.{name} must be positive, got {v}"))
            }
        };
        positive("lr", self.lr)?;
        positive("alpha", self.alpha)?;
        if !(0.0..=1.0).contains(&self.gamma) {
            return bad(format!("sac.gamma must lie in [0, 1], got {}", self.gamma));
        }
        if !(self.tau > 0.0 && self.tau <= 1.0) {
            return bad(format!("sac.tau must lie in (0, 1], got {}", self.tau));
        }
        if self.batch_size == 0 {
            return bad("sac.batch_size must be at least 1".into());
        }
        Ok(())
    }
}
