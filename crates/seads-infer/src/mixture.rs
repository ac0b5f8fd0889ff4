//! The mixture skill model (`seads_skillmodel::MixtureModel`, `skill_model.kind = "mixture"`)
//! from a checkpoint: an MLP on `[z_0, onehot(k)]` giving M mixture logits and M sets of D flip
//! logits; q(z_T | z_0, k) = Σ_m softmax(w)_m Π_d P(bit d as observed), each bit's probability
//! clamped to [ε, 1 − ε] as the libtorch model does; the successor is the most likely of the
//! components' modes (the first among equally likely ones).

use ndarray::ArrayView1;
use seads_games::{Successor, SymbolicState};

use crate::InferError;
use crate::mlp::Mlp;
use crate::model::{ForwardModel, log_sigmoid};

/// float32's machine epsilon, the clamp of every bit's probability.
const EPS: f32 = f32::EPSILON;

/// The mixture model of a checkpoint.
#[derive(Debug, Clone)]
pub struct MixtureModel {
    net: ForwardModel,
    board: usize,
    skills: usize,
    components: usize,
}

/// log Σ exp(x), stably.
fn log_sum_exp(x: impl Iterator<Item = f32> + Clone) -> f32 {
    let top = x.clone().fold(f32::NEG_INFINITY, f32::max);
    if !top.is_finite() {
        return top;
    }
    top + x.map(|v| (v - top).exp()).sum::<f32>().ln()
}

impl MixtureModel {
    /// The model of `mlp` for boards of `board` fields: it maps `board + K` inputs to
    /// `M · (board + 1)` outputs.
    pub fn new(mlp: Mlp, board: usize) -> Result<Self, InferError> {
        let outputs = mlp.outputs();
        if outputs == 0 || !outputs.is_multiple_of(board + 1) {
            return Err(InferError::Shape(format!(
                "a mixture model of boards of {board} fields gives M · {} values; this one gives \
                 {outputs}",
                board + 1
            )));
        }
        let net = ForwardModel::with_board(mlp, board)?;
        Ok(Self {
            skills: Successor::num_skills(&net),
            board,
            components: outputs / (board + 1),
            net,
        })
    }

    /// Number of components M.
    pub fn components(&self) -> usize {
        self.components
    }

    /// log q(z_T | z_0, k) of a row of heads, for the flips `flipped` = z_0 XOR z_T.
    fn log_likelihood(&self, heads: ArrayView1<'_, f32>, flipped: SymbolicState) -> f32 {
        let (m, d) = (self.components, self.board);
        let weights = heads.slice(ndarray::s![..m]);
        let norm = log_sum_exp(weights.iter().copied());
        let per = (0..m).map(|c| {
            let flips = heads.slice(ndarray::s![m + c * d..m + (c + 1) * d]);
            let bits: f32 = flips
                .iter()
                .enumerate()
                .map(|(bit, &l)| {
                    log_sigmoid(if flipped.get(bit) { l } else { -l })
                        .clamp(EPS.ln(), (1.0 - EPS).ln())
                })
                .sum();
            weights[c] - norm + bits
        });
        log_sum_exp(per.collect::<Vec<_>>().into_iter())
    }

    /// The most likely of the components' modes from `z` under a row of heads.
    fn most_likely(&self, heads: ArrayView1<'_, f32>, z: SymbolicState) -> SymbolicState {
        let (m, d) = (self.components, self.board);
        let mut best: Option<(f32, SymbolicState)> = None;
        for c in 0..m {
            let flips = heads.slice(ndarray::s![m + c * d..m + (c + 1) * d]);
            let mut next = z;
            for (bit, &l) in flips.iter().enumerate() {
                let flips = if z.get(bit) { l >= 0.0 } else { l > 0.0 };
                if flips {
                    next.flip(bit);
                }
            }
            let score = self.log_likelihood(heads, z ^ next);
            if best.is_none_or(|(b, _)| score > b) {
                best = Some((score, next));
            }
        }
        best.map_or(z, |(_, next)| next)
    }
}

impl Successor for MixtureModel {
    fn num_skills(&self) -> usize {
        self.skills
    }

    fn symbolic_len(&self) -> usize {
        self.board
    }

    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        let heads = self.net.flip_logits(states);
        for (row, heads) in heads.rows().into_iter().enumerate() {
            out.push(self.most_likely(heads, states[row / self.skills]));
        }
    }

    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        if steps.iter().any(|&(_, k, _)| k >= self.skills) {
            return None;
        }
        let pairs: Vec<(SymbolicState, usize)> = steps.iter().map(|&(z, k, _)| (z, k)).collect();
        let heads = self.net.pair_logits(&pairs);
        Some(
            steps
                .iter()
                .zip(heads.rows())
                .map(|(&(z0, _, zt), row)| self.log_likelihood(row, z0 ^ zt))
                .collect(),
        )
    }
}
