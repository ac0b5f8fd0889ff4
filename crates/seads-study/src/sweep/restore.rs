//! A sweep laid out again from its committed copy (`seads report --copy-runs` writes one under
//! `docs/results/<study>/runs/<sweep>/`: the index, the manifest and each finished run's data,
//! never checkpoints), so that a study continues on a fresh machine: the sweep is planned again
//! from the committed manifest, it must expand to the committed index, and each committed run's
//! data files are laid into its run directory, its committed configuration (the one it trained with)
//! in place of the planned one; a run whose configuration departs from the plan is named. The
//! finished runs then count as copied in, and `sweep run` trains the rest.

use std::path::{Path, PathBuf};

use seads_run::TrainConfig;

use super::index::{INDEX, MANIFEST, Sweep};
use super::manifest::Manifest;
use crate::error::fail;
use crate::{Context as _, Result, StudyError};

/// What [`restore`] laid out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Restored {
    /// Runs in the sweep.
    pub runs: usize,
    /// Runs whose committed data were laid in.
    pub copied: usize,
    /// The committed runs (their directories in the sweep) whose configuration is not the one
    /// the manifest plans today (another commit's presets, or a setting changed on a resume).
    pub departures: Vec<String>,
}

/// Lays the committed sweep `committed` out again in `out` (which must not exist), planned by
/// this binary's `commit`. A sweep planned by another commit is refused unless `allow_other`,
/// as `sweep run` refuses it: the plan's configurations are this binary's presets. Errors that
/// the user fixes (not a sweep, `out` taken, another commit, a manifest that no longer expands to
/// the committed index) are [`StudyError::Invalid`]; nothing is left in `out` on any error.
pub fn restore(committed: &Path, out: &Path, commit: &str, allow_other: bool) -> Result<Restored> {
    let invalid = |e: StudyError| e.into_invalid();
    if !committed.join(INDEX).is_file() {
        return Err(StudyError::invalid(format!(
            "{} is not a sweep ({INDEX} missing)",
            committed.display()
        )));
    }
    let sweep = Sweep::load(committed).map_err(invalid)?;
    sweep.allows_commit(commit, allow_other).map_err(invalid)?;
    if out.exists() {
        return Err(StudyError::invalid(format!(
            "{} exists; lay the sweep out into a new directory",
            out.display()
        )));
    }
    let manifest_path = committed.join(MANIFEST);
    let text = std::fs::read_to_string(&manifest_path)
        .doing(|| format!("reading {}", manifest_path.display()))
        .map_err(invalid)?;
    let manifest = Manifest::parse(&text, &manifest_path.display().to_string()).map_err(invalid)?;
    // Planned beside its final place, then moved there whole.
    let name = out
        .file_name()
        .map_or_else(|| "sweep".to_owned(), |n| n.to_string_lossy().into_owned());
    let staging: PathBuf = out.with_file_name(format!(".{name}.restoring"));
    if staging.exists() {
        std::fs::remove_dir_all(&staging).doing(|| format!("removing {}", staging.display()))?;
    }
    let laid = lay_out(&sweep, &manifest, &text, committed, &staging);
    let restored = match laid {
        Ok(r) => r,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&staging);
            return Err(e);
        }
    };
    std::fs::rename(&staging, out).doing(|| format!("moving the sweep to {}", out.display()))?;
    Ok(restored)
}

/// Plans `manifest` into `staging` with the committed sweep's `planned_by`, checks that it is
/// the committed sweep, and lays the committed runs in.
fn lay_out(
    sweep: &Sweep,
    manifest: &Manifest,
    text: &str,
    committed: &Path,
    staging: &Path,
) -> Result<Restored> {
    Sweep::plan(manifest, text, staging, sweep.planned_by.as_deref())?;
    let planned = Sweep::load(staging)?;
    if planned.runs != sweep.runs {
        return Err(StudyError::invalid(format!(
            "{}: its manifest no longer expands to its index ({} runs planned, {} committed)",
            committed.display(),
            planned.runs.len(),
            sweep.runs.len()
        )));
    }
    let mut copied = 0;
    let mut departures = Vec::new();
    for run in &sweep.runs {
        let from = committed.join(&run.dir);
        let config_file = from.join("config.toml");
        if !config_file.is_file() {
            continue;
        }
        let to = staging.join(&run.dir);
        let planned_config = seads_run::load_config(&to)?;
        let committed_text = std::fs::read_to_string(&config_file)
            .doing(|| format!("reading {}", config_file.display()))?;
        match TrainConfig::from_toml(&committed_text) {
            Ok(c) if c == planned_config => {}
            Ok(_) => departures.push(run.dir.clone()),
            Err(e) => fail!("{}: {e}", config_file.display()),
        }
        crate::run_data::copy_data(&from, &to)?;
        copied += 1;
    }
    Ok(Restored {
        runs: sweep.runs.len(),
        copied,
        departures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::{Status, status};

    const MANIFEST_TEXT: &str = r#"
name = "small"
environments = ["lightsout-cursor"]
seeds = [1, 2]
overrides = { env_steps = 1000 }

[[variant]]
name = "seads"

[[variant]]
name = "no-relabelling"
overrides = { seads = { relabel = { skill_model_p = 0.0, sac_p = 0.0 } } }
"#;

    /// A committed copy as `seads report --copy-runs` leaves it: index, manifest, and one
    /// finished run's files (config, metrics, an evaluation, a file in a subfolder), no
    /// checkpoints; the other three runs are absent.
    fn committed(root: &Path) -> (PathBuf, String) {
        let planned = root.join("planned");
        let manifest = Manifest::parse(MANIFEST_TEXT, "small.toml").unwrap();
        Sweep::plan(&manifest, MANIFEST_TEXT, &planned, Some("abc")).unwrap();
        let sweep = Sweep::load(&planned).unwrap();
        let copy = root.join("committed");
        std::fs::create_dir_all(&copy).unwrap();
        for name in [INDEX, MANIFEST] {
            std::fs::copy(planned.join(name), copy.join(name)).unwrap();
        }
        let dir = sweep.runs[1].dir.clone();
        let run = copy.join(&dir);
        std::fs::create_dir_all(run.join("fitted-model")).unwrap();
        std::fs::copy(
            planned.join(&dir).join("config.toml"),
            run.join("config.toml"),
        )
        .unwrap();
        std::fs::write(run.join("metrics.jsonl"), "{\"epoch\":1}\n").unwrap();
        std::fs::write(run.join("evaluation-replan.json"), "{}").unwrap();
        std::fs::write(run.join("fitted-model/fit.json"), "{}").unwrap();
        (copy, dir)
    }

    /// The sweep comes back whole: every run planned, the committed run's files as they were,
    /// counted as copied in; the others pending with their planned configs.
    #[test]
    fn a_committed_sweep_is_laid_out_again_with_its_runs() {
        let root = tempfile::tempdir().unwrap();
        let (copy, dir) = committed(root.path());
        let out = root.path().join("again");
        let restored = restore(&copy, &out, "abc", false).unwrap();
        assert_eq!(
            restored,
            Restored {
                runs: 4,
                copied: 1,
                departures: Vec::new()
            }
        );
        let sweep = Sweep::load(&out).unwrap();
        assert_eq!(sweep.planned_by.as_deref(), Some("abc"));
        for name in [
            "metrics.jsonl",
            "evaluation-replan.json",
            "fitted-model/fit.json",
        ] {
            assert_eq!(
                std::fs::read(out.join(&dir).join(name)).unwrap(),
                std::fs::read(copy.join(&dir).join(name)).unwrap(),
                "{name}"
            );
        }
        for (i, run) in sweep.runs.iter().enumerate() {
            let (s, _) = status(&out.join(&run.dir)).unwrap();
            let expected = if run.dir == dir {
                Status::Copied
            } else {
                Status::Pending
            };
            assert_eq!(s, expected, "run {i}");
            assert!(out.join(&run.dir).join("config.toml").is_file());
        }
        // Nothing staged is left beside it.
        let left: Vec<_> = std::fs::read_dir(root.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.contains("restoring"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
    }

    /// Another commit's binary, a taken folder, something that is not a sweep, or a manifest
    /// that no longer gives the committed index: refused as the user's to fix, and no sweep is
    /// left behind. A committed run whose configuration departs from the plan is laid in as it
    /// trained, and named.
    #[test]
    fn a_restore_that_cannot_be_made_leaves_nothing() {
        let root = tempfile::tempdir().unwrap();
        let (copy, dir) = committed(root.path());
        let out = root.path().join("again");
        let e = restore(&copy, &out, "def", false).unwrap_err();
        assert!(
            e.is_invalid() && e.to_string().contains("planned by commit abc"),
            "{e}"
        );
        assert!(!out.exists());
        assert_eq!(restore(&copy, &out, "def", true).unwrap().copied, 1);
        let e = restore(&copy, &out, "abc", false).unwrap_err();
        assert!(e.is_invalid() && e.to_string().contains("exists"), "{e}");
        let e = restore(
            &root.path().join("nothing"),
            &root.path().join("x"),
            "abc",
            false,
        )
        .unwrap_err();
        assert!(
            e.is_invalid() && e.to_string().contains("is not a sweep"),
            "{e}"
        );
        let config = copy.join(&dir).join("config.toml");
        let text = std::fs::read_to_string(&config).unwrap();
        let manifest = copy.join(MANIFEST);
        let planned = std::fs::read_to_string(&manifest).unwrap();
        std::fs::write(
            &manifest,
            planned.replace("seeds = [1, 2]", "seeds = [1, 2, 3]"),
        )
        .unwrap();
        let fresh = root.path().join("fresh");
        let e = restore(&copy, &fresh, "abc", false).unwrap_err();
        assert!(
            e.is_invalid() && e.to_string().contains("no longer expands"),
            "{e}"
        );
        assert!(!fresh.exists());
        std::fs::write(&manifest, planned).unwrap();
        // A committed run that trained with another setting keeps its own configuration, and is
        // named.
        let changed = text.replace("env_steps = 1000", "env_steps = 2000");
        assert_ne!(changed, text);
        std::fs::write(&config, &changed).unwrap();
        let restored = restore(&copy, &fresh, "abc", false).unwrap();
        assert_eq!(restored.departures, vec![dir.clone()]);
        assert_eq!(
            std::fs::read_to_string(fresh.join(&dir).join("config.toml")).unwrap(),
            changed
        );
        assert!(!root.path().join(".fresh.restoring").exists());
    }
}
