//! Gaussian noise on the low-level actions: the authors' planner evaluation can execute skills
//! with N(0, σ²) added to every action of the manipulator (σ = 0.05 for the cursor). The wrapper
//! works for every environment; the noisy action is clipped to the action bounds. Its noise comes
//! from the task's seed: [`Environment::seed`] re-seeds it on the stream [`ACTION_NOISE_STREAM`],
//! apart from the board's and the manipulator's streams, so a task sees the same noise on every
//! machine and the board it plays is the board it plays without noise.

use crate::wrapper::{Layer, Wrapped};
use crate::{EnvError, Environment, StepOutcome};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// The ChaCha8 stream of the action noise (the ASCII of "noise").
pub const ACTION_NOISE_STREAM: u64 = 0x6e_6f_69_73_65;

/// An environment whose actions get Gaussian noise of standard deviation `std` before they act.
pub type ActionNoise = Wrapped<Noise>;

/// The layer of an [`ActionNoise`] environment: the noise's standard deviation and stream.
#[derive(Clone)]
pub struct Noise {
    std: f32,
    rng: ChaCha8Rng,
    noisy: Vec<f32>,
}

impl ActionNoise {
    /// Wraps `inner`; `std` must be finite and not negative (0 leaves the actions as they are).
    pub fn new(inner: Box<dyn Environment>, std: f64) -> Result<Self, EnvError> {
        if !(std.is_finite() && std >= 0.0) {
            return Err(EnvError::InvalidConfig(format!(
                "the action noise must be a finite standard deviation of at least 0, got {std}"
            )));
        }
        let noisy = vec![0.0; inner.spec().action_dim];
        let noise = Noise {
            std: std as f32,
            rng: noise_rng(0),
            noisy,
        };
        Ok(Self::wrap(inner, noise))
    }
}

/// The noise generator of a task seeded with `seed`.
fn noise_rng(seed: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(ACTION_NOISE_STREAM);
    rng
}

impl Layer for Noise {
    fn seed(&mut self, seed: u64) {
        self.rng = noise_rng(seed);
    }
    fn step(
        &mut self,
        inner: &mut dyn Environment,
        action: &[f32],
    ) -> Result<StepOutcome, EnvError> {
        if action.len() != self.noisy.len() {
            return inner.step(action); // the environment names the error
        }
        let spec = inner.spec();
        for (i, (out, &a)) in self.noisy.iter_mut().zip(action).enumerate() {
            let e: f32 = StandardNormal.sample(&mut self.rng);
            *out = (a + self.std * e).clamp(spec.action_low[i], spec.action_high[i]);
            if !a.is_finite() {
                *out = a; // a non-finite action stays one, and the environment refuses it
            }
        }
        inner.step(&self.noisy)
    }
    fn for_copy(&self) -> Option<Self> {
        Some(self.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EnvConfig, make_env};

    fn cursor() -> Box<dyn Environment> {
        make_env("lightsout-cursor", &EnvConfig::default()).unwrap()
    }

    /// Runs `steps` steps of a fixed small action from the task seeded with `seed`; returns the
    /// observations.
    fn rollout(env: &mut dyn Environment, seed: u64, steps: usize) -> Vec<Vec<f32>> {
        env.seed(seed);
        env.reset().unwrap();
        env.set_step_limit(None);
        (0..steps)
            .map(|_| {
                env.step(&[0.01, -0.01, -1.0]).unwrap();
                env.observation()
            })
            .collect()
    }

    #[test]
    fn no_noise_is_the_environment_itself_and_a_seed_repeats_its_noise() {
        let mut plain = cursor();
        let mut quiet = ActionNoise::new(cursor(), 0.0).unwrap();
        assert_eq!(rollout(plain.as_mut(), 3, 20), rollout(&mut quiet, 3, 20));
        let mut noisy = ActionNoise::new(cursor(), 0.05).unwrap();
        let a = rollout(&mut noisy, 3, 20);
        assert_eq!(
            a,
            rollout(&mut noisy, 3, 20),
            "the same task, the same noise"
        );
        assert_ne!(a, rollout(plain.as_mut(), 3, 20));
        assert_ne!(a, rollout(&mut noisy, 4, 20), "another task, other noise");
        // The board a task plays does not depend on the noise.
        noisy.seed(9);
        noisy.reset().unwrap();
        plain.seed(9);
        plain.reset().unwrap();
        assert_eq!(noisy.board(), plain.board());
    }

    #[test]
    fn the_noise_has_the_standard_deviation_asked_for_and_bad_values_are_refused() {
        // The cursor moves by the action's first two entries (bounds ±1): with a zero action
        // and no push, each step's displacement is the noise itself.
        let mut noisy = ActionNoise::new(cursor(), 0.05).unwrap();
        noisy.seed(1);
        noisy.reset().unwrap();
        noisy.set_step_limit(None);
        let mut moves = Vec::new();
        for _ in 0..4000 {
            noisy
                .restore_manipulator(&[0.5, 0.5])
                .expect("the cursor can be placed");
            let from = noisy.observation();
            noisy.step(&[0.0, 0.0, -1.0]).unwrap();
            let after = noisy.observation();
            moves.push(f64::from(after[0] - from[0]));
        }
        let n = moves.len() as f64;
        let mean = moves.iter().sum::<f64>() / n;
        let std = (moves.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        assert!(mean.abs() < 0.005, "mean {mean}");
        assert!((std - 0.05).abs() < 0.004, "std {std}");
        for bad in [-0.1, f64::NAN, f64::INFINITY] {
            assert!(ActionNoise::new(cursor(), bad).is_err(), "{bad}");
        }
        assert!(noisy.step(&[f32::NAN, 0.0, -1.0]).is_err());
    }
}
