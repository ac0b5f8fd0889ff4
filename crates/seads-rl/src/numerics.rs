//! Which floating-point kernels libtorch runs, so that a seed gives the same run on every x86-64
//! machine (`TrainConfig::portable_numerics`) or the fastest run on this one.
//!
//! libtorch's matrix products come from MKL, which picks its kernels by processor: another CPU
//! (AVX-512 or not, Intel or AMD) sums in another order, and reinforcement learning amplifies
//! the last-bit differences into different runs. MKL's conditional numerical reproducibility
//! pins them: `MKL_CBWR=COMPATIBLE` is the one branch MKL honours on every x86-64 processor (it
//! answers a specific branch such as `AVX2` with `AUTO` on AMD processors). It costs about 1.8×
//! per SAC update on the 2-core development machine, so it is a setting. `AUTO`, for fast runs,
//! still makes a run repeat exactly on the same machine. ATen's own vectorised kernels are
//! pinned to AVX2 in both cases (AVX2 and AVX-512 gave identical runs; pinning costs nothing).
//!
//! The aim is not met everywhere yet: the portable demo gave one run on an AMD EPYC and another
//! on an Intel Xeon (docs/RESULTS.md, "Determinism across processors"), so runs record their
//! processor (the CLI's `provenance.jsonl`), and `cargo xtask golden` compares a processor with
//! the committed golden run.
//!
//! Both are environment variables that libtorch reads once, when it first computes: the binary
//! sets them before that, and `.cargo/config.toml` sets the portable ones for everything cargo
//! runs (tests, examples, benches).

/// The environment of portable kernels.
pub const PORTABLE_KERNELS: [(&str, &str); 2] =
    [("MKL_CBWR", "COMPATIBLE"), ("ATEN_CPU_CAPABILITY", "avx2")];

/// The environment of fast kernels (reproducible on the same machine only).
pub const FAST_KERNELS: [(&str, &str); 2] = [("MKL_CBWR", "AUTO"), ("ATEN_CPU_CAPABILITY", "avx2")];

/// The environment that [`TrainConfig::portable_numerics`](crate::TrainConfig) asks for.
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

/// An error unless a run that asks for portable numerics gets them.
pub(crate) fn check(portable: bool) -> Result<(), crate::RlError> {
    if portable && !portable_kernels_active() {
        let env: Vec<String> = PORTABLE_KERNELS
            .iter()
            .map(|(n, v)| format!("{n}={v}"))
            .collect();
        return Err(crate::RlError::Config(format!(
            "portable_numerics needs {} in the environment before libtorch starts \
             (the seads binary sets them itself)",
            env.join(" ")
        )));
    }
    Ok(())
}
