//! The skill policy π(a | s, k) from a checkpoint: SAC's tanh-squashed Gaussian actor, an MLP
//! trunk on `[observation, onehot(k)]` with a mean head and a log σ head.

use ndarray::{Array2, ArrayView2};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use seads_embodiment::SkillPolicy;

use crate::InferError;
use crate::mlp::{Dense, Mlp};

/// log σ's bounds (SAC's clamp).
const LOG_STD_MIN: f32 = -20.0;
const LOG_STD_MAX: f32 = 2.0;

/// The actor of a checkpoint, with the action box it squashes into.
#[derive(Debug, Clone)]
pub struct Policy {
    mean: Mlp,
    log_std: Dense,
    obs_dim: usize,
    skills: usize,
    scale: Vec<f32>,
    bias: Vec<f32>,
}

impl Policy {
    /// The actor of trunk-and-mean `mean` and head `log_std` for observations of `obs_dim`
    /// values and actions in `[low, high]`.
    pub fn new(
        mean: Mlp,
        log_std: Dense,
        obs_dim: usize,
        low: &[f32],
        high: &[f32],
    ) -> Result<Self, InferError> {
        let action_dim = mean.outputs();
        let width = mean.layers()[mean.layers().len() - 1].inputs();
        if mean.inputs() <= obs_dim
            || log_std.outputs() != action_dim
            || log_std.inputs() != width
            || low.len() != action_dim
            || high.len() != action_dim
        {
            return Err(InferError::Shape(format!(
                "an actor taking {} values and giving {action_dim} actions does not fit \
                 observations of {obs_dim} values and an action box of {} (log σ head {:?})",
                mean.inputs(),
                low.len(),
                log_std.weight.shape()
            )));
        }
        Ok(Self {
            skills: mean.inputs() - obs_dim,
            obs_dim,
            scale: low.iter().zip(high).map(|(l, h)| (h - l) / 2.0).collect(),
            bias: low.iter().zip(high).map(|(l, h)| (h + l) / 2.0).collect(),
            mean,
            log_std,
        })
    }

    /// Values per observation.
    pub fn obs_dim(&self) -> usize {
        self.obs_dim
    }

    /// Values per action.
    pub fn action_dim(&self) -> usize {
        self.scale.len()
    }

    /// `[observation, onehot(skill)]` rows, after checking the sizes.
    fn inputs(&self, observations: &[f32], skills: &[usize]) -> Result<Array2<f32>, InferError> {
        let n = skills.len();
        if observations.len() != n * self.obs_dim {
            return Err(InferError::Input(format!(
                "{} observation values for {n} skills of {} each",
                observations.len(),
                self.obs_dim
            )));
        }
        if let Some(&bad) = skills.iter().find(|&&k| k >= self.skills) {
            return Err(InferError::Input(format!(
                "skill {bad}: the agent has {} skills",
                self.skills
            )));
        }
        let width = self.obs_dim + self.skills;
        let mut x = Array2::<f32>::zeros((n, width));
        for (i, mut row) in x.rows_mut().into_iter().enumerate() {
            let obs = &observations[i * self.obs_dim..(i + 1) * self.obs_dim];
            for (v, &o) in row.iter_mut().zip(obs) {
                *v = o;
            }
            row[self.obs_dim + skills[i]] = 1.0;
        }
        Ok(x)
    }

    /// Mean and clamped log σ of the pre-squash Gaussian.
    fn gaussian(&self, x: ArrayView2<f32>) -> (Array2<f32>, Array2<f32>) {
        let h = self.mean.features(x);
        let mut log_std = self.log_std.forward(h.view());
        log_std.mapv_inplace(|v| v.clamp(LOG_STD_MIN, LOG_STD_MAX));
        (self.mean.head().forward(h.view()), log_std)
    }

    fn squash(&self, u: f32, j: usize) -> f32 {
        u.tanh() * self.scale[j] + self.bias[j]
    }

    /// Actions for rows of observations, row i executing skill `skills[i]`: the deterministic
    /// action tanh(mean)·scale + bias when `rng` is `None`, else a sample
    /// tanh(mean + σ·ε)·scale + bias with ε standard normal from `rng` (row by row, as the
    /// trainer draws it).
    pub fn actions<R: Rng + ?Sized>(
        &self,
        observations: &[f32],
        skills: &[usize],
        rng: Option<&mut R>,
    ) -> Result<Vec<f32>, InferError> {
        if let Some(bad) = observations.iter().find(|v| !v.is_finite()) {
            return Err(InferError::Input(format!("an observation holds {bad}")));
        }
        let x = self.inputs(observations, skills)?;
        let (mean, log_std) = self.gaussian(x.view());
        let a = self.action_dim();
        let mut out = Vec::with_capacity(skills.len() * a);
        match rng {
            None => out.extend(mean.iter().enumerate().map(|(i, &m)| self.squash(m, i % a))),
            Some(rng) => {
                let noise: Vec<f32> = (0..skills.len() * a)
                    .map(|_| StandardNormal.sample(rng))
                    .collect();
                out.extend(
                    mean.iter()
                        .zip(log_std.iter())
                        .zip(noise)
                        .enumerate()
                        .map(|(i, ((&m, &ls), e))| self.squash(m + ls.exp() * e, i % a)),
                );
            }
        }
        // Finite observations can still carry a layer past float32's range (±3e38): an action
        // that is not a number is never handed out as one.
        if out.iter().any(|v| !v.is_finite()) {
            return Err(InferError::Input(
                "these observations drive the policy's layers beyond float32's range: no finite \
                 action"
                    .into(),
            ));
        }
        Ok(out)
    }
}

impl SkillPolicy for Policy {
    fn num_skills(&self) -> usize {
        self.skills
    }

    /// Deterministic actions. The executor's batches always fit the agent's sizes; a batch that
    /// does not (a caller's error) gets zero actions.
    fn act(&self, observations: &[f32], skills: &[usize], actions: &mut [f32]) {
        match self.actions::<rand_chacha::ChaCha8Rng>(observations, skills, None) {
            Ok(a) if a.len() == actions.len() => actions.copy_from_slice(&a),
            _ => actions.fill(0.0),
        }
    }
}
