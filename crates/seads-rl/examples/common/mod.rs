//! What the kernel examples (`stacked_vs_solo`, `thread_count_bits`) share: fixed inputs and their
//! JSON report.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tch::Tensor;

/// Values in [-1, 1) from a fixed stream, as a tensor of `shape`.
pub fn values(shape: &[i64], seed: u64) -> Tensor {
    let n: i64 = shape.iter().product();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let v: Vec<f32> = (0..n).map(|_| rng.random_range(-1.0f32..1.0)).collect();
    Tensor::from_slice(&v).reshape(shape)
}

/// Prints the report: the kernel settings of this process and `rows` (JSON objects).
#[allow(clippy::print_stdout)] // the examples' output
pub fn print_report(rows: &[String]) {
    let kernels: Vec<String> = seads_rl::PORTABLE_KERNELS
        .iter()
        .map(|(name, _)| format!("\"{name}\": {:?}", std::env::var(name).unwrap_or_default()))
        .collect();
    println!(
        "{{\n  \"kernels\": {{{}}},\n  \"rows\": [\n{}\n  ]\n}}",
        kernels.join(", "),
        rows.join(",\n")
    );
}
