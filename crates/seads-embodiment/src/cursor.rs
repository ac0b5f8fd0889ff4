//! Cursor (SPEC §2.2): a point on the board moved by bounded displacements, pushing on demand.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::{Manipulator, Push, Shape, Touch};

/// Largest displacement per step along each axis.
const MAX_STEP: f32 = 0.2;
/// A push happens when the third action entry exceeds −1 + 0.8·2.
pub(crate) const PUSH_THRESHOLD: f32 = 0.6;

/// The cursor: position (x, y) ∈ [0, 1]², origin at the top-left corner of the board.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Cursor {
    /// Column direction.
    pub x: f64,
    /// Row direction.
    pub y: f64,
}

impl Manipulator for Cursor {
    fn state_dim(&self) -> usize {
        2
    }

    fn action_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        (
            vec![-MAX_STEP, -MAX_STEP, -1.0],
            vec![MAX_STEP, MAX_STEP, 1.0],
        )
    }

    /// The cursor stays on the board: its position lies in [0, 1]².
    fn state_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        (vec![0.0, 0.0], vec![1.0, 1.0])
    }

    fn default_step_limit(&self) -> usize {
        10
    }

    fn reset(&mut self, rng: &mut ChaCha8Rng) {
        self.x = rng.random::<f64>();
        self.y = rng.random::<f64>();
    }

    fn step(
        &mut self,
        action: &[f32],
        _rng: &mut ChaCha8Rng,
        touch: &mut dyn FnMut(Touch) -> Push,
    ) -> bool {
        let dx = action[0].clamp(-MAX_STEP, MAX_STEP) as f64;
        let dy = action[1].clamp(-MAX_STEP, MAX_STEP) as f64;
        self.x = (self.x + dx).clamp(0.0, 1.0);
        self.y = (self.y + dy).clamp(0.0, 1.0);
        if action[2] > PUSH_THRESHOLD {
            // The push is evaluated at the new position.
            touch(Touch::At {
                u: self.x,
                v: self.y,
            });
        }
        true
    }

    fn observe(&self, out: &mut [f32]) {
        out[0] = self.x as f32;
        out[1] = self.y as f32;
    }

    fn restore(&mut self, state: &[f32]) -> Result<(), String> {
        if state.iter().any(|v| !(0.0..=1.0).contains(v)) {
            return Err(format!("cursor position {state:?} lies outside [0, 1]²"));
        }
        (self.x, self.y) = (state[0] as f64, state[1] as f64);
        Ok(())
    }

    fn end_effector(&self) -> [f64; 2] {
        [self.x, self.y]
    }

    fn draw(&self, shapes: &mut Vec<Shape>, _extent: &mut [f64; 4]) {
        shapes.push(Shape::Marker {
            at: [self.x, self.y],
        });
    }
}
