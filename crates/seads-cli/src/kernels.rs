//! Chooses libtorch's floating-point kernels for this process (`seads_rl::kernel_environment`):
//! portable or fast, as the run asks, before libtorch first computes.

use std::sync::OnceLock;

use anyhow::{Result, bail};

/// The choice made in this process, once.
static CHOSEN: OnceLock<bool> = OnceLock::new();

/// Sets the kernel environment for runs with `portable_numerics = portable`. Call it before
/// anything uses libtorch; a later call must ask for the same kernels (libtorch has read them).
pub fn use_kernels(portable: bool) -> Result<()> {
    let chosen = *CHOSEN.get_or_init(|| {
        for (name, value) in seads_rl::kernel_environment(portable) {
            #[allow(unsafe_code)]
            // SAFETY: the first call happens on the main thread before libtorch, rayon or the
            // progress bar have started a thread, so no other thread reads the environment.
            unsafe {
                std::env::set_var(name, value);
            }
        }
        portable
    });
    if chosen != portable {
        bail!(
            "this process already runs libtorch with {} kernels; run the other command separately",
            if chosen { "portable" } else { "fast" }
        );
    }
    Ok(())
}
