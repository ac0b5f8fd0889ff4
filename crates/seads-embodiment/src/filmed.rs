//! An environment that films itself: its scene after every step, for animations (`seads solve
//! --render`, `seads plot --animate`, Python's `Agent.solve(render=True)`).

use crate::wrapper::{Layer, Wrapped};
use crate::{EnvError, Environment, Scene, StepOutcome};

/// An environment that keeps its scene after every step (and at the start), for an animation.
pub type Filmed = Wrapped<Film>;

/// The layer of a [`Filmed`] environment: the scenes, the first when filming started, then one
/// per step.
pub struct Film {
    frames: Vec<Scene>,
}

impl Layer for Film {
    fn step(
        &mut self,
        inner: &mut dyn Environment,
        action: &[f32],
    ) -> Result<StepOutcome, EnvError> {
        let outcome = inner.step(action)?;
        self.frames.push(inner.scene());
        Ok(outcome)
    }
    /// A copy films nothing: only this environment's steps are frames.
    fn for_copy(&self) -> Option<Self> {
        None
    }
}

impl Filmed {
    /// Films `inner` from now on.
    pub fn new(inner: Box<dyn Environment>) -> Self {
        let frames = vec![inner.scene()];
        Self::wrap(inner, Film { frames })
    }

    /// The scenes filmed so far.
    pub fn frames(&self) -> &[Scene] {
        &self.layer().frames
    }

    /// The scenes filmed so far, taken; filming goes on from the current scene.
    pub fn take_frames(&mut self) -> Vec<Scene> {
        let now = vec![self.scene()];
        std::mem::replace(&mut self.layer_mut().frames, now)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EnvConfig, make_env};

    #[test]
    fn a_film_has_the_start_and_a_scene_per_step_and_its_copies_film_nothing() {
        let mut filmed = Filmed::new(make_env("lightsout-cursor", &EnvConfig::default()).unwrap());
        let start = filmed.scene();
        for _ in 0..3 {
            filmed.step(&[0.1, 0.0, -1.0]).unwrap();
        }
        assert_eq!(filmed.frames().len(), 4);
        assert_eq!(filmed.frames()[0], start);
        assert_eq!(filmed.frames()[3], filmed.scene());
        let mut copy = filmed.box_clone();
        copy.step(&[0.1, 0.0, -1.0]).unwrap();
        assert_eq!(filmed.frames().len(), 4, "the copy's steps are not filmed");
        let taken = filmed.take_frames();
        assert_eq!((taken.len(), filmed.frames()), (4, &[filmed.scene()][..]));
    }
}
