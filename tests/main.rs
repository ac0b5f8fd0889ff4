//! Workspace-level integration tests (one binary): data tables against the paper's numbers, the
//! promises the repository makes in its docs and CI script, and the long studies' scripts.

mod studies;
mod tables;
mod tidy;

use std::path::{Path, PathBuf};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ lives in the repository")
        .to_path_buf()
}

/// A file of the repository as text.
pub fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("reading {rel}: {e}"))
}
