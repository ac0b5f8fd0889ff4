//! The data a run's results rest on: which of its files (never checkpoints), and copying them,
//! for a report's `--copy-runs` and for a sweep laid out again from such a copy.

use std::path::{Path, PathBuf};

use crate::{Context as _, Result};

/// The files of a run that results rest on (small; never checkpoints), by their paths inside the
/// run: its configuration (with a robot run's `robot.toml`), metrics, evaluations, which code on
/// which machine trained it (`provenance.jsonl`), and the record of a model fitted to its skills
/// (`fitted-model/fit.json`; not the model's weights).
pub fn data_files(run: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(run).doing(|| format!("reading {}", run.display()))? {
        let path = entry?.path();
        let name = path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let wanted = name == "config.toml"
            || name == "robot.toml"
            || name == "metrics.jsonl"
            || name == crate::provenance::PROVENANCE
            || (name.starts_with("evaluation")
                && (name.ends_with(".json") || name.ends_with(".jsonl")));
        if wanted && path.is_file() {
            files.push(PathBuf::from(name));
        }
    }
    let fit_record = Path::new(seads_run::fitted::FITTED_MODEL).join(seads_run::fitted::FIT_RECORD);
    if run.join(&fit_record).is_file() {
        files.push(fit_record);
    }
    files.sort();
    Ok(files)
}

/// Copies the data files ([`data_files`]) of the run in `from` into `to` (folders created),
/// each written atomically.
pub fn copy_data(from: &Path, to: &Path) -> Result<()> {
    std::fs::create_dir_all(to).doing(|| format!("creating {}", to.display()))?;
    for file in data_files(from)? {
        let source = from.join(&file);
        let bytes = std::fs::read(&source).doing(|| format!("reading {}", source.display()))?;
        let target = to.join(&file);
        if let Some(parent) = target.parent() {
            std::fs::create_dir_all(parent).doing(|| format!("creating {}", parent.display()))?;
        }
        seads_run::store::write_atomic(&target, &bytes)?;
    }
    Ok(())
}
