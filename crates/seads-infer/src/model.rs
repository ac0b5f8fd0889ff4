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
        Self::with_board(mlp, board)
    }

    /// A network on `[z_0, onehot(k)]` for boards of `board` fields, whatever it outputs per
    /// row (the mixture's heads).
    pub(crate) fn with_board(mlp: Mlp, board: usize) -> Result<Self, InferError> {
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
        let k = self.skills;
        let first = &self.mlp.layers()[0];
        let from_board = self.board_parts(states.iter().copied());
        let mut h = Array2::<f32>::zeros((states.len() * k, first.outputs()));
        for (i, board_part) in from_board.rows().into_iter().enumerate() {
            for skill in 0..k {
                let mut row = h.row_mut(i * k + skill);
                row.assign(&board_part);
                self.add_skill(row, skill);
            }
        }
        self.after_first_layer(h)
    }

    /// Flip logits of each `(state, skill)` pair, one row of `D` each, in order: what
    /// [`flip_logits`](Self::flip_logits) gives in the pair's row, computed for that row alone.
    pub fn pair_logits(&self, pairs: &[(SymbolicState, usize)]) -> Array2<f32> {
        let mut h = self.board_parts(pairs.iter().map(|&(z, _)| z));
        for (row, &(_, skill)) in h.rows_mut().into_iter().zip(pairs) {
            self.add_skill(row, skill);
        }
        self.after_first_layer(h)
    }

    /// The first layer's board part of each state (no bias), one row each.
    fn board_parts(&self, states: impl ExactSizeIterator<Item = SymbolicState>) -> Array2<f32> {
        let d = self.board;
        let mut z = Array2::<f32>::zeros((states.len(), d));
        for (mut row, state) in z.rows_mut().into_iter().zip(states) {
            for (i, v) in row.iter_mut().enumerate() {
                *v = f32::from(u8::from(state.get(i)));
            }
        }
        z.dot(&self.mlp.layers()[0].weight.slice(s![.., ..d]).t())
    }

    /// Adds the first layer's column of `skill` (its one-hot input) and its bias to `row`.
    fn add_skill(&self, mut row: ndarray::ArrayViewMut1<'_, f32>, skill: usize) {
        let first = &self.mlp.layers()[0];
        row += &first.weight.column(self.board + skill);
        row += &first.bias;
    }

    /// The layers after the first on the first layer's outputs (ReLU between layers).
    fn after_first_layer(&self, mut h: Array2<f32>) -> Array2<f32> {
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
pub(crate) fn log_sigmoid(x: f32) -> f32 {
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
        // Each step's logits under its own skill.
        let pairs: Vec<(SymbolicState, usize)> = steps.iter().map(|&(z, k, _)| (z, k)).collect();
        let logits = self.pair_logits(&pairs);
        Some(
            steps
                .iter()
                .enumerate()
                .map(|(i, &(z0, _, zt))| {
                    let flipped = z0 ^ zt;
                    logits
                        .row(i)
                        .iter()
                        .enumerate()
                        .map(|(bit, &l)| log_sigmoid(if flipped.get(bit) { l } else { -l }))
                        .sum()
                })
                .collect(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mlp::Dense;

    /// A model of 9 bits and 4 skills with fixed, uneven weights.
    fn model() -> ForwardModel {
        let dense = |outputs: usize, inputs: usize, salt: f32| {
            let weight = Array2::from_shape_fn((outputs, inputs), |(i, j)| {
                ((i * 31 + j * 17) as f32 * 0.37 + salt).sin()
            });
            let bias =
                ndarray::Array1::from_shape_fn(outputs, |i| (i as f32 * 0.71 + salt).cos() * 0.3);
            Dense::new(weight, bias, "test").unwrap()
        };
        let mlp = Mlp::new(
            vec![dense(16, 13, 0.1), dense(16, 16, 0.2), dense(9, 16, 0.3)],
            "test",
        )
        .unwrap();
        ForwardModel::new(mlp).unwrap()
    }

    /// Each step's log-likelihood is the one its row of every skill's logits gives, computed
    /// for that step's skill alone.
    #[test]
    fn a_steps_log_likelihood_is_its_skills_row_of_the_logits() {
        let mut model = model();
        let states: Vec<SymbolicState> = [0u64, 0b1_0110_1001, 0b1_1111_1111, 0b0_0010_0100]
            .map(SymbolicState::from_u64)
            .to_vec();
        let all = model.flip_logits(&states);
        let steps: Vec<(SymbolicState, usize, SymbolicState)> = (0..12)
            .map(|i| {
                let z = states[i % 4];
                (
                    z,
                    (i * 3) % 4,
                    z ^ SymbolicState::from_u64((i as u64 * 0x5b) % 512),
                )
            })
            .collect();
        let pairs: Vec<(SymbolicState, usize)> = steps.iter().map(|&(z, k, _)| (z, k)).collect();
        let rows = model.pair_logits(&pairs);
        let got = model.log_likelihoods(&steps).unwrap();
        for (i, &(z0, k, zt)) in steps.iter().enumerate() {
            let s = states.iter().position(|&z| z == z0).unwrap();
            let expected_row = all.row(s * 4 + k);
            for (a, b) in rows.row(i).iter().zip(expected_row) {
                assert!(
                    (a - b).abs() <= 1e-5 * (1.0 + b.abs()),
                    "step {i}: {a} against {b}"
                );
            }
            let expected: f32 = expected_row
                .iter()
                .enumerate()
                .map(|(bit, &l)| log_sigmoid(if (z0 ^ zt).get(bit) { l } else { -l }))
                .sum();
            assert!(
                (got[i] - expected).abs() <= 1e-5 * (1.0 + expected.abs()),
                "step {i}"
            );
        }
        assert!(
            model
                .log_likelihoods(&[(states[0], 4, states[0])])
                .is_none()
        );
    }
}
