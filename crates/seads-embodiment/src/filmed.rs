//! An environment that films itself: its scene after every step, for animations (`seads solve
//! --render`, `seads plot --animate`, Python's `Agent.solve(render=True)`).

use seads_games::SymbolicState;

use crate::{EnvError, EnvSpec, Environment, Scene, StepOutcome};

/// An environment that keeps its scene after every step (and at the start), for an animation.
pub struct Filmed {
    inner: Box<dyn Environment>,
    /// The scenes: the first when filming started, then one per step.
    pub frames: Vec<Scene>,
}

impl Filmed {
    /// Films `inner` from now on.
    pub fn new(inner: Box<dyn Environment>) -> Self {
        let frames = vec![inner.scene()];
        Self { inner, frames }
    }

    /// The environment, no longer filmed (in the state the filmed steps left it).
    pub fn into_inner(self) -> Box<dyn Environment> {
        self.inner
    }
}

impl Environment for Filmed {
    fn spec(&self) -> &EnvSpec {
        self.inner.spec()
    }
    fn seed(&mut self, seed: u64) {
        self.inner.seed(seed);
    }
    fn reset(&mut self) -> Result<(), EnvError> {
        self.inner.reset()
    }
    fn step(&mut self, action: &[f32]) -> Result<StepOutcome, EnvError> {
        let outcome = self.inner.step(action)?;
        self.frames.push(self.inner.scene());
        Ok(outcome)
    }
    fn observe(&self, out: &mut [f32]) {
        self.inner.observe(out);
    }
    fn board(&self) -> SymbolicState {
        self.inner.board()
    }
    fn set_board(&mut self, board: SymbolicState) -> Result<(), EnvError> {
        self.inner.set_board(board)
    }
    fn reset_step_counter(&mut self) {
        self.inner.reset_step_counter();
    }
    fn set_step_limit(&mut self, limit: Option<usize>) {
        self.inner.set_step_limit(limit);
    }
    fn restore_manipulator(&mut self, state: &[f32]) -> Result<(), EnvError> {
        self.inner.restore_manipulator(state)
    }
    fn scene(&self) -> Scene {
        self.inner.scene()
    }
    fn end_effector(&self) -> [f64; 2] {
        self.inner.end_effector()
    }
    fn move_point(&self) -> Option<[f64; 2]> {
        self.inner.move_point()
    }
    fn carried_state(&self) -> Option<String> {
        self.inner.carried_state()
    }
    fn restore_carried_state(&mut self, state: &str) -> Result<(), EnvError> {
        self.inner.restore_carried_state(state)
    }
    /// A clone films nothing: only this environment's steps are frames.
    fn box_clone(&self) -> Box<dyn Environment> {
        self.inner.box_clone()
    }
}
