//! The RelaxedBernoulli (binary Concrete) distribution of the HAC high level (SPEC §5.2): a
//! factorised distribution over (0, 1)^D whose samples are differentiable in the logits, so a
//! discrete SAC can pick binary subgoals z ∈ {0,1}^D by thresholding them at 0.5.
//!
//! It computes what `torch.distributions.RelaxedBernoulli(temperature, logits=…)` computes,
//! clamps included (checked against stored PyTorch outputs in `tests/reference.rs`):
//! - a sample from uniforms u is σ(y) with y = (logit u + logit p) / τ, p = σ(logits), where u and
//!   p are clamped to [ε, 1 − ε] and the result to [ε, 1 − ε] (ε: float32's machine epsilon);
//! - the log-density of x is that of y = logit x under the logistic-relaxed distribution,
//!   log τ + d − 2 log(1 + e^d) with d = logits − τ y, plus the sigmoid's Jacobian term
//!   softplus(−y) + softplus(y); x is clamped to [tiny, 1 − ε] first.

use tch::{Kind, Tensor};

/// float32's machine epsilon, PyTorch's `clamp_probs` bound.
const EPS: f64 = f32::EPSILON as f64;
/// float32's smallest normal number, PyTorch's lower clamp in the sigmoid's inverse.
const TINY: f64 = f32::MIN_POSITIVE as f64;

/// A factorised RelaxedBernoulli distribution.
#[derive(Debug)]
pub struct RelaxedBernoulli {
    temperature: f64,
    logits: Tensor,
}

impl RelaxedBernoulli {
    /// The distribution with `temperature` τ > 0 and `logits` (any shape; the HAC policy clamps
    /// them to [−5, 5] before).
    pub fn new(temperature: f64, logits: Tensor) -> Self {
        Self {
            temperature,
            logits,
        }
    }

    /// The reparameterised sample for `uniforms` (uniform on [0, 1), the shape of the logits):
    /// differentiable in the logits. The caller draws the uniforms from the run's streams.
    pub fn rsample_with(&self, uniforms: &Tensor) -> Tensor {
        let u = uniforms.clamp(EPS, 1.0 - EPS);
        let p = self.logits.sigmoid().clamp(EPS, 1.0 - EPS);
        let y = (u.log() - u.neg().log1p() + p.log() - p.neg().log1p()) / self.temperature;
        y.sigmoid().clamp(EPS, 1.0 - EPS)
    }

    /// The log-density of every entry of `value` (in (0, 1)), elementwise.
    pub fn log_prob(&self, value: &Tensor) -> Tensor {
        let x = value.clamp(TINY, 1.0 - EPS);
        let y = x.log() - x.neg().log1p();
        let diff = &self.logits - &y * self.temperature;
        let base = diff.exp().log1p() * -2.0 + &diff + self.temperature.ln();
        base + y.neg().softplus() + y.softplus()
    }

    /// The deterministic action: 1 where the probability exceeds 0.5 (logits > 0), else 0.
    pub fn mode(&self) -> Tensor {
        self.logits.gt(0.0).to_kind(Kind::Float)
    }
}
