//! Which floating-point kernels libtorch runs, so that a seed gives the same run on every x86-64
//! machine (portable kernels) or the fastest run on this one (fast kernels).
//!
//! Two sources make libtorch's results depend on the processor:
//! - **Matrix products** come from MKL, which picks its kernels by processor: another CPU
//!   (AVX-512 or not, Intel or AMD) sums in another order, and reinforcement learning amplifies
//!   the last-bit differences into different runs. MKL's conditional numerical reproducibility
//!   pins them: `MKL_CBWR=COMPATIBLE` is the one branch MKL honours on every x86-64 processor
//!   (it answers a specific branch such as `AVX2` with `AUTO` on AMD processors). It costs about
//!   1.8× per SAC update on the 2-core development machine, so it is a setting. ATen's own
//!   vectorised kernels are pinned to AVX2 in both cases (AVX2 and AVX-512 gave identical runs).
//! - **The square root.** `Tensor::sqrt` on the CPU is MKL's vector math (`vsSqrt`), whose
//!   kernel refines the processor's `rsqrtps` estimate by one Newton step in single precision
//!   and so inherits the estimate's last bits: 17 % of its results are one unit in the last
//!   place away from the correctly rounded root, and which ones depends on the estimate. The
//!   instruction only promises a relative error below 1.5·2⁻¹²; Intel and AMD processors
//!   compute different estimates, and Adam divides every step by this root. [`sqrt`] takes the
//!   correctly rounded root instead (IEEE 754's, the same on every processor) when the portable
//!   kernels are active.
//!
//! Both kernel choices are environment variables that libtorch reads once, when it first
//! computes: the `seads` binary sets them before that, and `.cargo/config.toml` sets the portable
//! ones for everything cargo runs (tests, examples, benches).

use std::sync::OnceLock;

use tch::{Device, Tensor};

/// The environment of portable kernels.
pub const PORTABLE_KERNELS: [(&str, &str); 2] =
    [("MKL_CBWR", "COMPATIBLE"), ("ATEN_CPU_CAPABILITY", "avx2")];

/// The environment of fast kernels (reproducible on the same machine only).
pub const FAST_KERNELS: [(&str, &str); 2] = [("MKL_CBWR", "AUTO"), ("ATEN_CPU_CAPABILITY", "avx2")];

/// The environment of portable (`true`) or fast kernels.
pub fn kernel_environment(portable: bool) -> [(&'static str, &'static str); 2] {
    if portable {
        PORTABLE_KERNELS
    } else {
        FAST_KERNELS
    }
}

/// Whether this process runs libtorch with the portable kernels.
pub fn portable_kernels_active() -> bool {
    PORTABLE_KERNELS
        .iter()
        .all(|(name, value)| std::env::var(name).is_ok_and(|v| v.eq_ignore_ascii_case(value)))
}

/// Whether this process takes correctly rounded square roots on the CPU: decided once, like
/// libtorch's own kernels, by the environment at the first square root.
fn exact_roots() -> bool {
    static EXACT: OnceLock<bool> = OnceLock::new();
    *EXACT.get_or_init(portable_kernels_active)
}

/// The element-wise square root of a single-precision tensor, as Adam takes it. With the
/// portable kernels and on the CPU it is the correctly rounded root, computed by the processor's
/// IEEE 754 square root outside libtorch. Otherwise it is libtorch's (MKL's on the CPU, whose
/// last bit depends on the processor; see the module documentation), which keeps fast runs
/// identical to those recorded before the portable root existed.
pub fn sqrt(t: &Tensor) -> Tensor {
    if t.device() != Device::Cpu || !exact_roots() {
        return t.sqrt();
    }
    let values = Vec::<f32>::try_from(t.reshape([-1]))
        .expect("square roots are taken of single-precision tensors");
    let roots: Vec<f32> = values.iter().map(|v| v.sqrt()).collect();
    Tensor::from_slice(&roots).view(t.size().as_slice())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The tests run with the portable kernels (cargo's environment): every root is the
        /// correctly rounded one, which `f64::sqrt` rounded to single precision gives exactly
        /// (the double root has more than twice the bits, so the second rounding is exact).
        #[test]
        fn roots_are_correctly_rounded(bits in proptest::collection::vec(0u32..0x7f80_0000, 1..300)) {
            prop_assert!(portable_kernels_active(), "the tests run with the portable kernels");
            let values: Vec<f32> = bits.iter().map(|&b| f32::from_bits(b)).collect();
            let t = Tensor::from_slice(&values).view([1, -1]);
            let roots = sqrt(&t);
            prop_assert_eq!(roots.size(), t.size());
            let roots = Vec::<f32>::try_from(roots.reshape([-1])).unwrap();
            for (v, r) in values.iter().zip(&roots) {
                prop_assert_eq!(r.to_bits(), (f64::from(*v).sqrt() as f32).to_bits(), "√{:e}", v);
            }
        }
    }
}
