//! `cargo xtask gen-splits`: regenerate the depth and split tables under `data/`.

use std::path::Path;

use anyhow::Result;

use crate::step;

/// Writes `data/depth_counts.csv` and `data/split_counts.csv` by seads-games's example `tables`
/// (built optimised: it enumerates every board of LightsOut 5×5). xtask runs it rather than
/// linking the crate, so that building xtask, the first thing `cargo xtask ci` does on a fresh
/// clone, compiles no workspace crate.
pub fn run(root: &Path) -> Result<()> {
    let data = root.join("data");
    step(
        "cargo",
        &[
            "run",
            "--release",
            "--quiet",
            "--package",
            "seads-games",
            "--example",
            "tables",
            "--",
            &data.to_string_lossy(),
        ],
    )
}
