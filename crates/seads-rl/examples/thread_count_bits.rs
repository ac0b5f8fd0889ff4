//! Why SAC's bits can depend on libtorch's thread count (docs/ARCHITECTURE.md, determinism): the
//! weight gradient of a linear layer, `δᵀ·X` for a batch of 128, computed on one thread and on
//! two. Where the layer is narrow, MKL splits the product's columns (the layer's inputs) between
//! the threads, and the columns at the seam are summed in another order: their gradients differ
//! in the last bits. Wide layers are split along their outputs and agree. Which products are
//! split where is MKL's choice, per kernel branch: the shapes below are LightsOutCursor's actor
//! (53 observations + 25 skills = 78 inputs) and critic (80) first layers, the forward model's
//! (50), and the critic of the thread-count test (96 + 2 = 98), at the widths the tests shrink
//! the networks to and at the presets' 256 units.
//!
//! Prints JSON: per shape whether the two agree, and the input columns that differ. Run it with
//! each kernel setting of `seads_nn::numerics`:
//!
//! ```sh
//! cargo run --release -p seads-rl --example thread_count_bits > docs/results/determinism/thread-count-bits-compatible.json
//! MKL_CBWR=AUTO cargo run --release -p seads-rl --example thread_count_bits > docs/results/determinism/thread-count-bits-auto.json
//! ```
#![allow(clippy::print_stdout)] // an example prints

use common::values;
use tch::{Kind, Tensor};

mod common;

/// The weight gradient of `linear` (`outputs × inputs`) for a batch of `batch`, on a fresh thread
/// with `threads` libtorch threads.
fn weight_gradient(batch: i64, inputs: i64, outputs: i64, threads: i32) -> Vec<f32> {
    std::thread::spawn(move || {
        tch::set_num_threads(threads);
        let x = values(&[batch, inputs], 1);
        let w = values(&[outputs, inputs], 2).set_requires_grad(true);
        let upstream = values(&[batch, outputs], 3);
        let y = x.linear(&w, None::<&Tensor>);
        let grad = Tensor::run_backward(&[(y * upstream).sum(Kind::Float)], &[&w], false, false);
        Vec::<f32>::try_from(grad[0].contiguous().view([-1])).expect("float gradient")
    })
    .join()
    .expect("the gradient thread")
}

fn main() {
    let batch = 128;
    let mut rows = Vec::new();
    for inputs in [78i64, 80, 50, 98] {
        for outputs in [32i64, 64, 128, 256] {
            let one = weight_gradient(batch, inputs, outputs, 1);
            let two = weight_gradient(batch, inputs, outputs, 2);
            let mut columns: Vec<i64> = one
                .iter()
                .zip(&two)
                .enumerate()
                .filter(|(_, (a, b))| a.to_bits() != b.to_bits())
                .map(|(i, _)| i as i64 % inputs)
                .collect();
            columns.sort_unstable();
            columns.dedup();
            rows.push(format!(
                "    {{\"batch\": {batch}, \"inputs\": {inputs}, \"outputs\": {outputs}, \
                 \"one_and_two_threads_equal\": {}, \"input_columns_that_differ\": {columns:?}}}",
                columns.is_empty()
            ));
        }
    }
    common::print_report(&rows);
}
