//! Configuration of an environment: board variant and reset distribution (SPEC §1.5, §1.6).

use seads_games::Split;
use serde::{Deserialize, Serialize};

use crate::EnvError;

/// Options shared by every environment. `Default` gives the paper's training environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EnvConfig {
    /// Board side length; only `lightsout-cursor` accepts sizes other than the game's default
    /// (odd, 5 to 13, as spaced boards).
    pub board_size: Option<usize>,
    /// Relative spacing s ∈ [0, 1] between the fields of a spaced LightsOut board (fields keep
    /// side 1/13). Unset: 5×5 fields tile the board; larger boards use s = 0.
    pub spacing: Option<f64>,
    /// The split boards are drawn from at reset ("train" for training, "test" for evaluation).
    pub reset_split: Split,
    /// Largest solution depth of a reset board.
    pub max_solution_depth: usize,
    /// Draw the depth uniformly from 1..=max (training); otherwise use exactly the maximum.
    pub random_solution_depth: bool,
    /// Steps per skill, overriding the environment's default T_max.
    pub step_limit: Option<usize>,
    /// Jaco only: physics steps per 0.1 s environment step (reference: 50 steps of 2 ms). Fewer
    /// steps run proportionally faster with coarser contact and servo dynamics.
    pub physics_substeps: Option<usize>,
}

impl Default for EnvConfig {
    fn default() -> Self {
        Self {
            board_size: None,
            spacing: None,
            reset_split: Split::Train,
            max_solution_depth: 5,
            random_solution_depth: true,
            step_limit: None,
            physics_substeps: None,
        }
    }
}

impl EnvConfig {
    /// Checks the values that do not depend on the environment.
    pub fn validate(&self) -> Result<(), EnvError> {
        let bad = |m: String| Err(EnvError::InvalidConfig(m));
        if self.max_solution_depth == 0 {
            return bad("max_solution_depth must be at least 1".into());
        }
        if let Some(s) = self.spacing
            && !(0.0..=1.0).contains(&s)
        {
            return bad(format!("spacing must lie in [0, 1], got {s}"));
        }
        if self.physics_substeps == Some(0) {
            return bad("physics_substeps must be at least 1".into());
        }
        if self.step_limit == Some(0) {
            return bad("step_limit must be at least 1".into());
        }
        Ok(())
    }
}
