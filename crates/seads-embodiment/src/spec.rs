//! What an environment looks like from outside: dimensions, bounds, step results.

use seads_games::{GameKind, MoveId, SymbolicState};
use serde::Serialize;

/// Dimensions and bounds of an environment (SPEC §2.5).
///
/// An observation is `[manipulator state (M), z as 0.0/1.0 (D), remaining time ρ (1)]`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EnvSpec {
    /// Registered name, e.g. `lightsout-cursor`.
    pub name: String,
    /// The board game.
    pub game: GameKind,
    /// Board side length N.
    pub board_size: usize,
    /// Length M of the manipulator part of the observation.
    pub manipulator_dim: usize,
    /// Lower bounds of the manipulator part of the observation (−∞ where unbounded).
    pub state_low: Vec<f32>,
    /// Upper bounds of the manipulator part of the observation (+∞ where unbounded).
    pub state_high: Vec<f32>,
    /// Length D of the symbolic state.
    pub symbolic_len: usize,
    /// Length of the observation, M + D + 1.
    pub obs_dim: usize,
    /// Length of an action.
    pub action_dim: usize,
    /// Lower action bounds.
    pub action_low: Vec<f32>,
    /// Upper action bounds.
    pub action_high: Vec<f32>,
    /// Number of skills K to learn (= number of game moves).
    pub num_skills: usize,
    /// Steps per skill execution T_max (`None`: unlimited).
    pub step_limit: Option<usize>,
    /// The environment drives shared physical hardware: its clones are the same robot, so
    /// episodes must run one at a time.
    pub exclusive: bool,
}

impl EnvSpec {
    /// The observation's remaining time ρ = (T_max − t)/T_max after `steps` steps of the current
    /// skill; 1 without a step limit. Every environment observes it through this one rule.
    pub fn remaining_time(&self, steps: usize) -> f32 {
        match self.step_limit {
            Some(limit) => limit.saturating_sub(steps) as f32 / limit.max(1) as f32,
            None => 1.0,
        }
    }

    /// Writes the board side of an observation after the manipulator's `manipulator_dim`
    /// entries: the board's bits, then the remaining time after `steps` steps. Every environment
    /// observes its board through this one rule.
    pub fn observe_board(&self, board: SymbolicState, steps: usize, out: &mut [f32]) {
        let (m, d) = (self.manipulator_dim, self.symbolic_len);
        board.write_f32(&mut out[m..m + d]);
        out[m + d] = self.remaining_time(steps);
    }

    /// Checks an action's length and that every entry is finite.
    pub fn check_action(&self, action: &[f32]) -> Result<(), crate::EnvError> {
        if action.len() != self.action_dim {
            return Err(crate::EnvError::ActionLength {
                env: self.name.clone(),
                expected: self.action_dim,
                found: action.len(),
            });
        }
        if let Some(index) = action.iter().position(|a| !a.is_finite()) {
            return Err(crate::EnvError::NonFiniteAction {
                env: self.name.clone(),
                index,
                value: action[index],
            });
        }
        Ok(())
    }

    /// The ground-truth symbolic mapping Φ(s): the D entries before ρ, non-zero → 1.
    pub fn phi(&self, obs: &[f32]) -> SymbolicState {
        SymbolicState::from_observation(
            &obs[self.manipulator_dim..self.manipulator_dim + self.symbolic_len],
        )
    }
}

/// What a push did to the board in one step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum Push {
    /// No push (or a push off the board).
    #[default]
    None,
    /// A push on the board that made no move (TileSwap outside every pivot, a gap between
    /// fields, a sliding tile away from the gap).
    Miss,
    /// A game move with its ground-truth id (SPEC §1 numbering).
    Move(MoveId),
}

/// The result of one environment step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct StepOutcome {
    /// What the push of this step did (at most one move per step).
    pub push: Push,
    /// The step counter reached the skill's step limit.
    pub truncated: bool,
}

impl StepOutcome {
    /// A game move happened, i.e. z changed.
    pub fn moved(&self) -> bool {
        matches!(self.push, Push::Move(_))
    }

    /// The skill ends: a move happened or the time ran out (the agent does not distinguish them).
    pub fn done(&self) -> bool {
        self.moved() || self.truncated
    }

    /// The ground-truth move id, if a move happened.
    pub fn game_move(&self) -> Option<MoveId> {
        match self.push {
            Push::Move(m) => Some(m),
            _ => None,
        }
    }
}
