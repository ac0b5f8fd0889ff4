//! `cargo xtask gen-splits`: regenerate the depth and split tables under `data/`.

use std::path::Path;

use anyhow::{Context, Result};
use seads_games::tables::{depth_counts_csv, split_counts_csv};

/// Writes `data/depth_counts.csv` and `data/split_counts.csv`.
pub fn run(root: &Path) -> Result<()> {
    let data = root.join("data");
    std::fs::create_dir_all(&data)?;
    for (name, csv) in [
        ("depth_counts.csv", depth_counts_csv()),
        ("split_counts.csv", split_counts_csv()),
    ] {
        let path = data.join(name);
        std::fs::write(&path, csv).with_context(|| format!("writing {}", path.display()))?;
        eprintln!("xtask: wrote {}", path.display());
    }
    Ok(())
}
