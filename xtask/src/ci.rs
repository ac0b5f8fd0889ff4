//! `cargo xtask ci`: the one command CI and developers run before a change lands.

use anyhow::Result;

use crate::{setup, step};

/// Set-up, formatting, lints (warnings are errors), then every test of every crate, the
/// integration tests under `tests/` and the benches in test mode (each bench runs once).
pub fn run() -> Result<()> {
    setup()?;
    step("cargo", &["fmt", "--all", "--check"])?;
    step(
        "cargo",
        &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    step("cargo", &["test", "--workspace", "--all-targets"])?;
    step("cargo", &["test", "--workspace", "--doc"])?;
    eprintln!("xtask: ci passed");
    Ok(())
}
