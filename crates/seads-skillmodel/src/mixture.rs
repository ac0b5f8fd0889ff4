//! A mixture of forward models, for skills whose effect depends on the board (issue 80).
//!
//! The paper's forward model predicts each bit of the successor on its own. Where a move changes
//! several bits together (the sliding puzzle: a slide changes the tile's field and the gap's), a
//! skill that is still stochastic during training has several outcomes from one board (its
//! slide, nothing, another slide), and a per-bit model averages them: its most likely successor
//! is often no board at all (`docs/results/sliding/forward-model-seed-N.json`: 30 % of its
//! predictions are boards, a fifth of them change a single field).
//!
//! This model keeps each outcome whole: an MLP on `[z_0, onehot(k)]` gives M mixture logits w
//! and M sets of D flip logits ℓ_m, and
//!
//! q(z_T | z_0, k) = Σ_m softmax(w)_m · Π_d Bern(f_d; σ(ℓ_md)),   f = z_0 XOR z_T,
//!
//! each bit's probability clamped to [ε, 1 − ε] as the paper's model does. With M = 1 it is the
//! paper's model. Its likelihood drives everything the paper's does (the intrinsic reward and
//! the relabelling through [`SkillModel::scores`], the plan choice through
//! [`Successor::log_likelihoods`]); its successor is the most likely of the components' modes
//! (the exact mode where the components are apart, as a near-deterministic outcome's is).
//! Training minimises the negative log-likelihood per bit (divided by D, so that the step sizes
//! are the paper's model's).
//!
//! Why this form. The analyses show a skill's outcomes from one board are few (its move where
//! the move exists, nothing, or another move: `relative_to_the_gap` there), each a coherent
//! change of a few bits; a mixture gives each of them a component and leaves the rest of the
//! paper's model as it is (one network, the same inputs, the per-bit form within a component,
//! M = 1 the paper's). A categorical over the effects seen in training would be coherent too,
//! but its outputs grow with the effects seen and do not generalise a slide from one tile or
//! field to another; an autoregressive model over the D bits is exact but needs D network passes
//! per successor, where breadth-first search asks for millions.

use std::path::Path;

use seads_games::{Successor, SymbolicState};
use tch::nn::Module;
use tch::{Device, Kind, Tensor};

use crate::SkillModelError;
use crate::model::{
    EPS, SkillModel, SkillModelConfig, SkillTransition, Trainable, skill_inputs, states_tensor,
};
use seads_nn::mean_f32;

/// The mixture forward model.
#[derive(Debug)]
pub struct MixtureModel {
    d: usize,
    k: usize,
    m: usize,
    device: Device,
    network: Trainable,
}

impl MixtureModel {
    /// A fresh model for `d`-bit states, `k` skills and the settings' number of components,
    /// initialised from `seed`.
    pub fn new(d: usize, k: usize, config: &SkillModelConfig, device: Device, seed: u64) -> Self {
        let m = config.mixture_components().max(1);
        Self {
            d,
            k,
            m,
            device,
            network: Trainable::new("mixture_model", d + k, m * (d + 1), config, device, seed),
        }
    }

    /// Number of components M.
    pub fn components(&self) -> usize {
        self.m
    }

    /// The network's output for each `(z_0, k)`, split: mixture log-weights (n × M, log-softmax)
    /// and flip logits (n × M × D).
    fn heads(&self, z0: &[SymbolicState], skills: &[usize]) -> (Tensor, Tensor) {
        let inputs = skill_inputs(z0, skills, self.d, self.k, self.device);
        let out = self.network.net.forward(&inputs);
        let (n, m, d) = (z0.len() as i64, self.m as i64, self.d as i64);
        let log_weights = out.narrow(1, 0, m).log_softmax(1, Kind::Float);
        let flips = out.narrow(1, m, m * d).view([n, m, d]);
        (log_weights, flips)
    }

    /// log q(z_T | z_0, k) for each row, from its heads and `flipped` (n × D, z_0 XOR z_T as
    /// 0/1): log Σ_m π_m Π_d P(bit d as observed), each bit's probability clamped to [ε, 1 − ε].
    fn log_likelihood(log_weights: &Tensor, flips: &Tensor, flipped: &Tensor) -> Tensor {
        let sign = flipped.unsqueeze(1) * 2.0 - 1.0; // n × 1 × D
        let per_component = (flips * sign)
            .log_sigmoid()
            .clamp(EPS.ln(), (1.0 - EPS).ln())
            .sum_dim_intlist(2, false, Kind::Float); // n × M
        (log_weights + per_component).logsumexp(1, false)
    }

    /// log q for each `(z_0, k, z_T)` as a tensor (n).
    fn step_log_likelihoods(&self, steps: &[(SymbolicState, usize, SymbolicState)]) -> Tensor {
        let z0: Vec<SymbolicState> = steps.iter().map(|&(z, _, _)| z).collect();
        let skills: Vec<usize> = steps.iter().map(|&(_, k, _)| k).collect();
        let (log_weights, flips) = self.heads(&z0, &skills);
        let flipped = states_tensor(steps.iter().map(|&(z, _, zt)| z ^ zt), self.d, self.device);
        Self::log_likelihood(&log_weights, &flips, &flipped)
    }

    /// The successor of each `(z_0, k)`: of the M components' modes (bit d flips iff ℓ_md > 0,
    /// or ≥ 0 for a bit that is 1, as the paper's model decides), the one the whole mixture
    /// finds most likely; among equally likely ones the first component's.
    fn most_likely(&self, z0: &[SymbolicState], skills: &[usize]) -> Vec<SymbolicState> {
        let (m, d) = (self.m, self.d);
        let (log_weights, flips) = self.heads(z0, skills);
        let ones = states_tensor(z0.iter().copied(), d, self.device)
            .unsqueeze(1)
            .gt(0.5); // n × 1 × D
        let modes = flips
            .gt(0.0)
            .logical_or(&ones.logical_and(&flips.eq(0.0)))
            .to_kind(Kind::Float); // n × M (candidates) × D
        // Every candidate scored under every component: n × M(cand) × M(comp).
        let sign = modes.unsqueeze(2) * 2.0 - 1.0; // n × M × 1 × D
        let per_component = (flips.unsqueeze(1) * sign)
            .log_sigmoid()
            .clamp(EPS.ln(), (1.0 - EPS).ln())
            .sum_dim_intlist(3, false, Kind::Float);
        let scores = (log_weights.unsqueeze(1) + per_component).logsumexp(2, false); // n × M
        let scores =
            Vec::<f32>::try_from(scores.to_device(Device::Cpu).view([-1])).expect("float scores");
        let modes =
            Vec::<f32>::try_from(modes.to_device(Device::Cpu).view([-1])).expect("float modes");
        z0.iter()
            .enumerate()
            .map(|(i, &z)| {
                let row = &scores[i * m..(i + 1) * m];
                let best = (0..m).fold(0, |b, c| if row[c] > row[b] { c } else { b });
                let mut next = z;
                let flips = &modes[(i * m + best) * d..(i * m + best + 1) * d];
                for (bit, &f) in flips.iter().enumerate() {
                    if f != 0.0 {
                        next.flip(bit);
                    }
                }
                next
            })
            .collect()
    }
}

impl SkillModel for MixtureModel {
    fn num_skills(&self) -> usize {
        self.k
    }

    fn scores(&self, pairs: &[(SymbolicState, SymbolicState)]) -> Vec<f32> {
        if pairs.is_empty() {
            return Vec::new();
        }
        let steps: Vec<(SymbolicState, usize, SymbolicState)> = pairs
            .iter()
            .flat_map(|&(z0, zt)| (0..self.k).map(move |k| (z0, k, zt)))
            .collect();
        tch::no_grad(|| {
            let ll = self.step_log_likelihoods(&steps);
            Vec::<f32>::try_from(ll.to_device(Device::Cpu)).expect("float scores")
        })
    }

    fn scores_are_likelihoods(&self) -> bool {
        true
    }

    fn train_step(&mut self, batch: &[SkillTransition]) -> f32 {
        let steps: Vec<_> = batch.iter().map(|t| (t.z0, t.skill, t.zt)).collect();
        let loss = -self.step_log_likelihoods(&steps).mean(Kind::Float) / self.d as f64;
        self.network.opt.backward_step(&loss);
        mean_f32(&loss)
    }

    fn save(&self, dir: &Path) -> Result<(), SkillModelError> {
        self.network.save(dir)
    }

    fn load(&mut self, dir: &Path, optimiser: bool) -> Result<(), SkillModelError> {
        self.network.load(dir, optimiser)
    }
}

impl Successor for MixtureModel {
    fn num_skills(&self) -> usize {
        self.k
    }

    fn symbolic_len(&self) -> usize {
        self.d
    }

    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        if states.is_empty() {
            return;
        }
        let z0: Vec<SymbolicState> = states
            .iter()
            .flat_map(|&z| std::iter::repeat_n(z, self.k))
            .collect();
        let skills: Vec<usize> = (0..states.len()).flat_map(|_| 0..self.k).collect();
        out.extend(tch::no_grad(|| self.most_likely(&z0, &skills)));
    }

    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        if steps.iter().any(|&(_, k, _)| k >= self.k) {
            return None;
        }
        if steps.is_empty() {
            return Some(Vec::new());
        }
        tch::no_grad(|| {
            Vec::<f32>::try_from(self.step_log_likelihoods(steps).to_device(Device::Cpu)).ok()
        })
    }

    /// Each state takes K rows and each row M × M × D scores, so calls stay small.
    fn preferred_batch(&self) -> usize {
        1024
    }
}
