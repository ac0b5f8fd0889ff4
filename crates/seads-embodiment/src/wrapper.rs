//! An environment wrapped in a layer that changes how it is seeded, stepped or copied (action
//! noise, filming), while every other call goes to the wrapped environment, here and only here:
//! a method added to [`Environment`] is forwarded once for every layer, defaults included (the
//! tidy test `the_wrapper_forwards_every_method_of_the_environment` keeps it so), so that no
//! layer can quietly drop what its environment does, such as the state it carries between
//! episodes.

use seads_games::SymbolicState;

use crate::{EnvError, EnvSpec, Environment, Scene, StepOutcome};

/// What a [`Wrapped`] environment adds to the one it wraps.
pub trait Layer: Send + Sync + Sized + 'static {
    /// After the wrapped environment is seeded with `seed` (a layer with a random stream of
    /// its own re-seeds it here).
    fn seed(&mut self, seed: u64) {
        let _ = seed;
    }

    /// One step of `inner` under `action`: by default the action as it is.
    fn step(
        &mut self,
        inner: &mut dyn Environment,
        action: &[f32],
    ) -> Result<StepOutcome, EnvError> {
        inner.step(action)
    }

    /// The layer of a copy of the environment ([`Environment::box_clone`]), or `None` for a copy
    /// without this layer.
    fn for_copy(&self) -> Option<Self>;
}

/// An environment `inner` with the layer `L` around it.
pub struct Wrapped<L: Layer> {
    inner: Box<dyn Environment>,
    layer: L,
}

impl<L: Layer> Wrapped<L> {
    /// `inner` with `layer` around it.
    pub fn wrap(inner: Box<dyn Environment>, layer: L) -> Self {
        Self { inner, layer }
    }

    /// The layer.
    pub fn layer(&self) -> &L {
        &self.layer
    }

    /// The layer, to change.
    pub fn layer_mut(&mut self) -> &mut L {
        &mut self.layer
    }

    /// The wrapped environment, without the layer, in the state the wrapped steps left it.
    pub fn into_inner(self) -> Box<dyn Environment> {
        self.inner
    }
}

impl<L: Layer> Environment for Wrapped<L> {
    fn spec(&self) -> &EnvSpec {
        self.inner.spec()
    }
    fn seed(&mut self, seed: u64) {
        self.inner.seed(seed);
        self.layer.seed(seed);
    }
    fn reset(&mut self) -> Result<(), EnvError> {
        self.inner.reset()
    }
    fn step(&mut self, action: &[f32]) -> Result<StepOutcome, EnvError> {
        self.layer.step(self.inner.as_mut(), action)
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
    fn box_clone(&self) -> Box<dyn Environment> {
        match self.layer.for_copy() {
            Some(layer) => Box::new(Self::wrap(self.inner.box_clone(), layer)),
            None => self.inner.box_clone(),
        }
    }
    fn carried_state(&self) -> Option<String> {
        self.inner.carried_state()
    }
    fn restore_carried_state(&mut self, state: &str) -> Result<(), EnvError> {
        self.inner.restore_carried_state(state)
    }
    fn observation(&self) -> Vec<f32> {
        self.inner.observation()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EnvConfig, make_env};

    /// A layer that adds nothing, and counts the steps and seeds it saw.
    #[derive(Clone, Default)]
    struct Count {
        steps: usize,
        seeds: Vec<u64>,
    }

    impl Layer for Count {
        fn seed(&mut self, seed: u64) {
            self.seeds.push(seed);
        }
        fn step(
            &mut self,
            inner: &mut dyn Environment,
            action: &[f32],
        ) -> Result<StepOutcome, EnvError> {
            self.steps += 1;
            inner.step(action)
        }
        fn for_copy(&self) -> Option<Self> {
            Some(self.clone())
        }
    }

    #[test]
    fn a_layer_that_adds_nothing_is_the_environment_itself_and_its_copies_keep_it() {
        let env = || make_env("tileswap-reacher", &EnvConfig::default()).unwrap();
        let (mut plain, mut wrapped) = (env(), Wrapped::wrap(env(), Count::default()));
        let action = [0.3, -0.2, -1.0];
        for e in [plain.as_mut(), &mut wrapped as &mut dyn Environment] {
            e.seed(5);
            e.reset().unwrap();
            e.set_step_limit(Some(7));
            for _ in 0..7 {
                e.step(&action).unwrap();
            }
            assert!(
                e.step(&action).is_err(),
                "the step limit reaches the wrapped"
            );
        }
        assert_eq!(plain.observation(), wrapped.observation());
        assert_eq!(plain.board(), wrapped.board());
        assert_eq!(plain.scene(), wrapped.scene());
        assert_eq!(plain.end_effector(), wrapped.end_effector());
        assert_eq!(plain.carried_state(), wrapped.carried_state());
        assert_eq!(
            (wrapped.layer().steps, &wrapped.layer().seeds[..]),
            (8, &[5][..])
        );

        let mut copy = wrapped.box_clone();
        assert_eq!(copy.observation(), wrapped.observation());
        copy.reset_step_counter();
        copy.step(&action).unwrap();
        assert_eq!(wrapped.layer().steps, 8, "a copy steps its own layer");
        let inner = wrapped.into_inner();
        assert_eq!(inner.observation(), plain.observation());
    }
}
