//! How many of libtorch's single-precision square roots are not the correctly rounded root, over
//! every float in [1, 4) (every binade of a square root looks alike), against the root Adam takes
//! with the portable kernels (`seads_nn::numerics::sqrt`). Run through cargo, which sets the
//! portable kernels; prints JSON.
//!
//! ```sh
//! cargo run --release -p seads-nn --example sqrt_rounding
//! ```
#![allow(clippy::print_stdout, clippy::print_stderr)] // an example prints

use tch::Tensor;

/// The floats whose root in `roots` is not the correctly rounded one (`f64::sqrt` rounded to
/// single precision, exact since the double root has more than twice the bits).
fn not_correctly_rounded(values: &[f32], roots: &Tensor) -> usize {
    let roots = Vec::<f32>::try_from(roots).expect("single-precision roots");
    values
        .iter()
        .zip(&roots)
        .filter(|(v, r)| (f64::from(**v).sqrt() as f32).to_bits() != r.to_bits())
        .count()
}

fn main() -> std::process::ExitCode {
    if !seads_nn::numerics::portable_kernels_active() {
        eprintln!("sqrt_rounding: needs the portable kernels; run it through cargo");
        return std::process::ExitCode::from(2);
    }
    tch::set_num_threads(1);
    let values: Vec<f32> = (1.0f32.to_bits()..4.0f32.to_bits())
        .map(f32::from_bits)
        .collect();
    let t = Tensor::from_slice(&values);
    println!(
        "{{\"range\": \"[1, 4)\", \"floats\": {}, \"libtorch_sqrt_not_correctly_rounded\": {}, \"seads_nn_sqrt_not_correctly_rounded\": {}}}",
        values.len(),
        not_correctly_rounded(&values, &t.sqrt()),
        not_correctly_rounded(&values, &seads_nn::numerics::sqrt(&t)),
    );
    std::process::ExitCode::SUCCESS
}
