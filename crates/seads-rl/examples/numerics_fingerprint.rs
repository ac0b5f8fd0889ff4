//! A fingerprint of the floating-point primitives a training run uses: each primitive applied to
//! fixed inputs, its output's bits hashed (CRC-32). Two processors whose runs part (the golden,
//! `cargo xtask golden`) differ in the primitives whose hashes differ. Run with the portable
//! kernels (cargo's environment sets them).
//!
//! ```sh
//! cargo run --release -p seads-rl --example numerics_fingerprint      # JSON: primitive → CRC
//! ```
#![allow(clippy::print_stdout, clippy::print_stderr)] // an example prints

use std::collections::BTreeMap;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use tch::{Device, Kind, Tensor, nn, nn::Module, nn::OptimizerConfig};

/// `n` values in [lo, hi) from a fixed stream.
fn values(n: usize, lo: f32, hi: f32, seed: u64) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.random_range(lo..hi)).collect()
}

fn crc_f32(values: &[f32]) -> String {
    let mut h = crc32fast::Hasher::new();
    for v in values {
        h.update(&v.to_le_bytes());
    }
    format!("{:08x}", h.finalize())
}

fn crc_f64(values: &[f64]) -> String {
    let mut h = crc32fast::Hasher::new();
    for v in values {
        h.update(&v.to_le_bytes());
    }
    format!("{:08x}", h.finalize())
}

fn crc_tensor(t: &Tensor) -> String {
    let flat = t.flatten(0, -1).to_kind(Kind::Float);
    crc_f32(&Vec::<f32>::try_from(&flat).expect("a float tensor"))
}

fn tensor(values: &[f32], rows: i64) -> Tensor {
    Tensor::from_slice(values).reshape([rows, -1])
}

fn main() -> std::process::ExitCode {
    if !seads_rl::portable_kernels_active() {
        eprintln!(
            "numerics_fingerprint: needs the portable kernels ({:?}); run it through cargo",
            seads_rl::PORTABLE_KERNELS
        );
        return std::process::ExitCode::from(2);
    }
    tch::set_num_threads(1);
    let mut out: BTreeMap<&str, String> = BTreeMap::new();
    let x = tensor(&values(128 * 256, -2.0, 2.0, 1), 128);
    let w = tensor(&values(256 * 256, -0.1, 0.1, 2), 256);
    let small = tensor(&values(32 * 7, -3.0, 3.0, 3), 32);
    let ws = tensor(&values(7 * 256, -0.3, 0.3, 4), 7);
    out.insert("tch.matmul_128x256x256", crc_tensor(&x.matmul(&w)));
    out.insert("tch.matmul_32x7x256", crc_tensor(&small.matmul(&ws)));
    out.insert(
        "tch.matmul_t_256x128x256",
        crc_tensor(&x.tr().matmul(&x.matmul(&w))),
    );
    let wide = tensor(&values(4096, -8.0, 8.0, 5), 64);
    let positive = tensor(&values(4096, 1e-3, 10.0, 6), 64);
    out.insert("tch.exp", crc_tensor(&wide.exp()));
    out.insert("tch.log", crc_tensor(&positive.log()));
    out.insert("tch.tanh", crc_tensor(&wide.tanh()));
    out.insert("tch.sigmoid", crc_tensor(&wide.sigmoid()));
    out.insert("tch.softplus", crc_tensor(&wide.softplus()));
    out.insert("tch.relu", crc_tensor(&wide.relu()));
    // libtorch's root (MKL's, from the processor's rsqrtps estimate) and the one Adam takes
    // with the portable kernels (correctly rounded): only the first may differ between processors.
    out.insert("tch.sqrt", crc_tensor(&positive.sqrt()));
    out.insert(
        "seads_nn.sqrt",
        crc_tensor(&seads_nn::numerics::sqrt(&positive)),
    );
    out.insert("tch.reciprocal", crc_tensor(&positive.reciprocal()));
    out.insert(
        "tch.log_softmax",
        crc_tensor(&wide.log_softmax(1, Kind::Float)),
    );
    out.insert("tch.logsumexp", crc_tensor(&wide.logsumexp(1, false)));
    out.insert(
        "tch.sum_mean",
        crc_tensor(&Tensor::stack(
            &[wide.sum(Kind::Float), wide.mean(Kind::Float)],
            0,
        )),
    );
    out.insert(
        "tch.bce_with_logits",
        crc_tensor(&wide.binary_cross_entropy_with_logits::<Tensor>(
            &positive.sigmoid(),
            None,
            None,
            tch::Reduction::None,
        )),
    );
    // A small MLP's loss, its gradients (the transposed products of backward) and one Adam step.
    let vs = nn::VarStore::new(Device::Cpu);
    let root = vs.root();
    let l1 = nn::linear(&root / "l1", 256, 64, Default::default());
    let l2 = nn::linear(&root / "l2", 64, 1, Default::default());
    // The variables by name: the store's own order is a hash map's.
    let mut variables: Vec<(String, Tensor)> = vs.variables().into_iter().collect();
    variables.sort_by(|a, b| a.0.cmp(&b.0));
    tch::no_grad(|| {
        for (i, (_, p)) in variables.iter_mut().enumerate() {
            let n = p.numel();
            let init = Tensor::from_slice(&values(n, -0.1, 0.1, 100 + i as u64));
            p.copy_(&init.reshape(p.size()));
        }
    });
    let mut opt = nn::Adam::default().build(&vs, 3e-4).expect("an optimiser");
    let loss = l2
        .forward(&l1.forward(&x).relu())
        .square()
        .mean(Kind::Float);
    opt.zero_grad();
    loss.backward();
    let mut grads: Vec<f32> = Vec::new();
    for (_, p) in &variables {
        grads.extend(Vec::<f32>::try_from(&p.grad().flatten(0, -1)).expect("float grads"));
    }
    out.insert("tch.mlp_backward", crc_f32(&grads));
    opt.step();
    let mut params: Vec<f32> = Vec::new();
    for (_, p) in &variables {
        params.extend(Vec::<f32>::try_from(&p.detach().flatten(0, -1)).expect("floats"));
    }
    out.insert("tch.adam_step", crc_f32(&params));
    // Rust's own math: the system libm and rand_distr's normal sampler.
    let xs = values(4096, -8.0, 8.0, 7);
    let ps = values(4096, 1e-3, 10.0, 8);
    out.insert(
        "rust.f32_exp",
        crc_f32(&xs.iter().map(|v| v.exp()).collect::<Vec<_>>()),
    );
    out.insert(
        "rust.f32_ln",
        crc_f32(&ps.iter().map(|v| v.ln()).collect::<Vec<_>>()),
    );
    out.insert(
        "rust.f32_tanh",
        crc_f32(&xs.iter().map(|v| v.tanh()).collect::<Vec<_>>()),
    );
    out.insert(
        "rust.f32_powf",
        crc_f32(&ps.iter().map(|v| v.powf(0.37)).collect::<Vec<_>>()),
    );
    out.insert(
        "rust.f64_exp_ln",
        crc_f64(
            &ps.iter()
                .map(|&v| f64::from(v).ln() + f64::from(v).exp())
                .collect::<Vec<_>>(),
        ),
    );
    out.insert(
        "rust.f64_sin_cos",
        crc_f64(
            &xs.iter()
                .map(|&v| f64::from(v).sin() + f64::from(v).cos())
                .collect::<Vec<_>>(),
        ),
    );
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let normal: Vec<f32> = (0..4096).map(|_| rng.sample(StandardNormal)).collect();
    out.insert("rust.standard_normal", crc_f32(&normal));
    println!(
        "{}",
        serde_json::to_string_pretty(&out).expect("a map of strings serialises")
    );
    std::process::ExitCode::SUCCESS
}
