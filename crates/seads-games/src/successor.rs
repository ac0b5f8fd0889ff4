//! `Successor`: what a planner needs to know about skills — the symbolic state each skill leads
//! to. The ground-truth game implements it (skill k = move k); so does the learned forward model.

use crate::{BoardGame, SymbolicState};

/// A (possibly learned) deterministic model of the symbolic effect of each skill.
pub trait Successor {
    /// Number of skills K.
    fn num_skills(&self) -> usize;
    /// Length D of the symbolic states.
    fn symbolic_len(&self) -> usize;
    /// Appends the successor of every state under every skill to `out`, state-major:
    /// entry `i · K + k` is the state after skill k from `states[i]`.
    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>);
    /// How many states one call should take to run efficiently (0: no preference). A GPU
    /// wants tens of thousands; the planner then computes several of its chunks per call.
    fn preferred_batch(&self) -> usize {
        0
    }
    /// The model's log-probability log q(z_T | z_0, k) of each step `(z_0, k, z_T)`, for
    /// choosing among plans the one the model is surest of; `None` for a model without
    /// probabilities (the true rules: every successor is certain).
    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        let _ = steps;
        None
    }
}

/// The ground-truth game as a successor function: skill k performs move k.
pub struct GameSuccessor<'a> {
    game: &'a dyn BoardGame,
}

impl<'a> GameSuccessor<'a> {
    /// The successor function of `game`.
    pub fn new(game: &'a dyn BoardGame) -> Self {
        Self { game }
    }
}

impl Successor for GameSuccessor<'_> {
    fn num_skills(&self) -> usize {
        self.game.num_moves()
    }

    fn symbolic_len(&self) -> usize {
        self.game.symbolic_len()
    }

    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        for &z in states {
            out.extend((0..self.game.num_moves()).map(|m| self.game.apply(z, m)));
        }
    }
}
