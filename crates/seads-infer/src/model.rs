//! The symbolic forward model q(z_T | z_0, k) (SPEC §3.4) from a checkpoint: an MLP on
//! `[z_0, onehot(k)]` giving per-bit flip logits, as the planner's [`Successor`].

use ndarray::{Array2, Axis, s};
use seads_games::{Successor, SymbolicState};

use crate::InferError;
use crate::mlp::Mlp;

/// The forward model of a checkpoint.
#[derive(Debug, Clone)]
pub struct ForwardModel {
    mlp: Mlp,
    board: usize,
    skills: usize,
}

impl ForwardModel {
    /// The model of `mlp`, which maps `board + K` inputs to `board` flip logits.
    pub fn new(mlp: Mlp) -> Result<Self, InferError> {
        let board = mlp.outputs();
        if mlp.inputs() <= board || board > SymbolicState::MAX_BITS {
            return Err(InferError::Shape(format!(
                "a forward model takes the board and a skill; this one takes {} values and gives {}",
                mlp.inputs(),
                board
            )));
        }
        Ok(Self {
            skills: mlp.inputs() - board,
            board,
            mlp,
        })
    }

    /// Flip logits of every state under every skill, state-major (row `i · K + k`), `D` each.
    /// The first layer is computed once per state and once per skill (its input is a board
    /// and a one-hot skill), the rest on every (state, skill) row.
    pub fn flip_logits(&self, states: &[SymbolicState]) -> Array2<f32> {
        let (d, k) = (self.board, self.skills);
        let first = &self.mlp.layers()[0];
        let mut z = Array2::<f32>::zeros((states.len(), d));
        for (mut row, state) in z.rows_mut().into_iter().zip(states) {
            for (i, v) in row.iter_mut().enumerate() {
                *v = f32::from(u8::from(state.get(i)));
            }
        }
        let from_board = z.dot(&first.weight.slice(s![.., ..d]).t());
        let width = first.outputs();
        let mut h = Array2::<f32>::zeros((states.len() * k, width));
        for (i, board_part) in from_board.rows().into_iter().enumerate() {
            for skill in 0..k {
                let mut row = h.row_mut(i * k + skill);
                row.assign(&board_part);
                row += &first.weight.column(d + skill);
                row += &first.bias;
            }
        }
        let layers = self.mlp.layers();
        if layers.len() == 1 {
            return h; // the first layer is the head: no ReLU
        }
        h.mapv_inplace(|v| v.max(0.0));
        for layer in &layers[1..layers.len() - 1] {
            h = layer.forward(h.view());
            h.mapv_inplace(|v| v.max(0.0));
        }
        layers[layers.len() - 1].forward(h.view())
    }
}

/// log σ(x), stably.
fn log_sigmoid(x: f32) -> f32 {
    x.min(0.0) - (-x.abs()).exp().ln_1p()
}

impl Successor for ForwardModel {
    fn num_skills(&self) -> usize {
        self.skills
    }

    fn symbolic_len(&self) -> usize {
        self.board
    }

    /// The mode of q: a 0 flips iff its logit is > 0, a 1 iff it is ≥ 0 (SPEC §4.1).
    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        let logits = self.flip_logits(states);
        for (row, logits) in logits.axis_iter(Axis(0)).enumerate() {
            let z = states[row / self.skills];
            let mut next = z;
            for (bit, &logit) in logits.iter().enumerate() {
                let flips = if z.get(bit) {
                    logit >= 0.0
                } else {
                    logit > 0.0
                };
                if flips {
                    next.flip(bit);
                }
            }
            out.push(next);
        }
    }

    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        if steps.iter().any(|&(_, k, _)| k >= self.skills) {
            return None;
        }
        // Each step's row of its start's logits under every skill.
        let from: Vec<SymbolicState> = steps.iter().map(|&(z, _, _)| z).collect();
        let logits = self.flip_logits(&from);
        Some(
            steps
                .iter()
                .enumerate()
                .map(|(i, &(z0, k, zt))| {
                    let flipped = z0 ^ zt;
                    logits
                        .row(i * self.skills + k)
                        .iter()
                        .enumerate()
                        .map(|(bit, &l)| log_sigmoid(if flipped.get(bit) { l } else { -l }))
                        .sum()
                })
                .collect(),
        )
    }
}
