//! Does a stacked batched product (one `baddbmm` per layer over K members) give the same bits as
//! each member's own `linear` on the CPU? The question behind the design of populations
//! (`seads_rl::Population`, docs/ARCHITECTURE.md "A study"): on the CPU the members keep their own
//! kernels, because it does not for every shape. For the layer shapes of LightsOutCursor's SAC and
//! forward model, and the 32-wide networks of the tests, it prints per shape whether the forward
//! pass and the weight gradient of K = 8 stacked members equal the members computed one by one,
//! and the largest difference (JSON; one libtorch thread, float32, the kernels cargo sets).
//!
//! ```sh
//! cargo run --release -p seads-rl --example stacked_vs_solo > docs/results/population/stacked-vs-solo.json
//! ```
#![allow(clippy::print_stdout)] // an example prints

use common::values;
use tch::{Kind, Tensor};

mod common;

/// The largest absolute difference of two tensors, and whether they are equal bit for bit.
fn compare(a: &Tensor, b: &Tensor) -> (f64, bool) {
    let diff = (a - b).abs().max().double_value(&[]);
    (diff, a.equal(b))
}

fn main() {
    tch::set_num_threads(1);
    let members = 8i64;
    // (batch, inputs, outputs): the actor's and a critic's first layers (LightsOutCursor: 53
    // observations + 25 skills, + 2 actions), the hidden layer, the actor's head, the forward
    // model's first layer, and a 32-wide layer of the tests' small networks.
    let shapes = [
        (128i64, 78i64, 256i64),
        (128, 80, 256),
        (128, 256, 256),
        (128, 256, 4),
        (256, 50, 256),
        (32, 32, 32),
    ];
    let mut rows = Vec::new();
    for (i, &(batch, fan_in, fan_out)) in shapes.iter().enumerate() {
        let seed = 10 * i as u64;
        let x = values(&[members, batch, fan_in], seed);
        let w = (values(&[members, fan_out, fan_in], seed + 1) / (fan_in as f64).sqrt())
            .set_requires_grad(true);
        let b = values(&[members, fan_out], seed + 2).set_requires_grad(true);
        let upstream = values(&[members, batch, fan_out], seed + 3);

        let stacked = b.unsqueeze(1).baddbmm(&x, &w.transpose(1, 2), 1, 1);
        let stacked_grad = Tensor::run_backward(
            &[(&stacked * &upstream).sum(Kind::Float)],
            &[&w],
            false,
            false,
        );
        let solo = Tensor::stack(
            &(0..members)
                .map(|k| x.get(k).linear(&w.get(k), Some(&b.get(k))))
                .collect::<Vec<_>>(),
            0,
        );
        let solo_grad =
            Tensor::run_backward(&[(&solo * &upstream).sum(Kind::Float)], &[&w], false, false);
        let (forward_diff, forward_equal) = compare(&stacked, &solo);
        let (grad_diff, grad_equal) = compare(&stacked_grad[0], &solo_grad[0]);
        rows.push(format!(
            "    {{\"batch\": {batch}, \"in\": {fan_in}, \"out\": {fan_out}, \"members\": {members}, \
             \"forward_bit_identical\": {forward_equal}, \"forward_max_abs_diff\": {forward_diff:e}, \
             \"weight_grad_bit_identical\": {grad_equal}, \"weight_grad_max_abs_diff\": {grad_diff:e}}}"
        ));
    }
    common::print_report(&rows);
}
