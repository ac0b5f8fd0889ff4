//! Which floating-point kernels a run asks for (`TrainConfig::portable_numerics`): the kernel
//! environments and the square root that makes runs portable live in `seads_nn::numerics`, which
//! explains what each removes; this module refuses a portable run in a process without them.

pub use seads_nn::numerics::{PORTABLE_KERNELS, kernel_environment, portable_kernels_active};

/// An error unless a run that asks for portable numerics gets them.
pub(crate) fn check(portable: bool) -> Result<(), crate::RlError> {
    if portable && !portable_kernels_active() {
        let env: Vec<String> = PORTABLE_KERNELS
            .iter()
            .map(|(n, v)| format!("{n}={v}"))
            .collect();
        return Err(crate::RlError::config(format!(
            "portable_numerics needs {} in the environment before libtorch starts \
             (the seads binary sets them itself)",
            env.join(" ")
        )));
    }
    Ok(())
}
