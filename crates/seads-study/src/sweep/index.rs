//! A planned sweep on disk: `sweep.json` (the index of its runs), `manifest.toml` (the manifest
//! it was planned from) and one run directory per run holding its full `config.toml`.

use std::path::{Path, PathBuf};

use crate::error::{fail, failure};
use crate::{Context as _, Result};
use seads_run::TrainConfig;
use serde::{Deserialize, Serialize};

use super::manifest::{EvaluationPlan, Manifest};

/// The index file of a sweep directory.
pub const INDEX: &str = "sweep.json";
/// The manifest a sweep was planned from, as given.
pub const MANIFEST: &str = "manifest.toml";

/// The index of a sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// Study name.
    pub name: String,
    /// What the study shows.
    pub description: String,
    /// The variant the others are tested against.
    pub reference: String,
    /// Evaluation after training.
    pub evaluation: EvaluationPlan,
    /// The runs, in order; a run's position is its index (the Slurm array task id).
    pub runs: Vec<SweepRun>,
    /// The commit of the binary that planned the sweep: its runs train on that commit, so that a
    /// cell never mixes code versions ([`Sweep::allows_commit`]). `None` for a sweep planned
    /// before it was recorded, or by code that knows no commit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planned_by: Option<String>,
}

/// One run of the index.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepRun {
    /// Environment.
    pub env: String,
    /// Variant.
    pub variant: String,
    /// Seed.
    pub seed: u64,
    /// Run directory relative to the sweep directory.
    pub dir: String,
}

/// What planning did.
#[derive(Debug, Default)]
pub struct Planned {
    /// Number of runs of the sweep.
    pub runs: usize,
    /// Run directories created by this call.
    pub created: usize,
}

impl Sweep {
    /// Whether a binary built from `commit` may train this sweep's runs: one of the commit that
    /// planned the sweep, any where the sweep records none, any with `allow_other`. Another is
    /// [`StudyError::Invalid`](crate::StudyError::Invalid), naming both commits.
    pub fn allows_commit(&self, commit: &str, allow_other: bool) -> Result<()> {
        match &self.planned_by {
            Some(planned) if planned != commit && !allow_other => {
                Err(crate::StudyError::invalid(format!(
                    "sweep {:?} was planned by commit {planned}, and this binary was built from \
                     {commit}: a study's runs train on one commit (run the binary of {planned}, \
                     scripts/freeze.sh {planned}), or pass --allow-other-commit",
                    self.name
                )))
            }
            _ => Ok(()),
        }
    }

    /// The indices of the runs with one of `seeds` (all runs for `None`), in index order; a seed
    /// the sweep does not have is [`StudyError::Invalid`](crate::StudyError::Invalid).
    pub fn runs_of_seeds(&self, seeds: Option<&[u64]>) -> Result<Vec<usize>> {
        let Some(seeds) = seeds else {
            return Ok((0..self.runs.len()).collect());
        };
        if let Some(missing) = seeds
            .iter()
            .find(|s| !self.runs.iter().any(|r| r.seed == **s))
        {
            let mut have: Vec<u64> = self.runs.iter().map(|r| r.seed).collect();
            have.sort_unstable();
            have.dedup();
            let have: Vec<String> = have.iter().map(u64::to_string).collect();
            return Err(crate::StudyError::invalid(format!(
                "sweep {:?} has no seed {missing} (its seeds: {})",
                self.name,
                have.join(", ")
            )));
        }
        Ok((0..self.runs.len())
            .filter(|&i| seeds.contains(&self.runs[i].seed))
            .collect())
    }

    /// Loads the sweep in `dir`; a missing folder or one that is not a sweep is a clear error.
    pub fn load(dir: &Path) -> Result<Self> {
        if !dir.is_dir() {
            fail!("sweep directory {} does not exist", dir.display());
        }
        let path = dir.join(INDEX);
        if !path.is_file() {
            fail!(
                "{} is not a sweep directory (no {INDEX}; make one with `seads sweep plan`)",
                dir.display()
            );
        }
        let text =
            std::fs::read_to_string(&path).doing(|| format!("reading {}", path.display()))?;
        serde_json::from_str(&text)
            .map_err(|e| failure!("{}: not a sweep index: {e}", path.display()))
    }

    /// The absolute-or-relative path of run `index`.
    pub fn run_dir(&self, dir: &Path, index: usize) -> Result<PathBuf> {
        let run = self.runs.get(index).ok_or_else(|| {
            failure!(
                "run index {index} is out of range: the sweep has {} runs (0 to {})",
                self.runs.len(),
                self.runs.len().saturating_sub(1)
            )
        })?;
        Ok(dir.join(&run.dir))
    }

    /// The directory of run `index`, planned again from the sweep's `manifest.toml` if it was
    /// deleted (its `config.toml` is gone); the second value says whether it was.
    pub fn ensure_run_dir(&self, dir: &Path, index: usize) -> Result<(PathBuf, bool)> {
        let run = self.run_dir(dir, index)?;
        if run.join("config.toml").exists() {
            return Ok((run, false));
        }
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path)
            .doing(|| format!("reading {} to plan {} again", path.display(), run.display()))?;
        let planned = Manifest::parse(&text, &path.display().to_string())?.expand()?;
        let Some(planned) = planned
            .into_iter()
            .nth(index)
            .filter(|p| p.rel_dir() == self.runs[index].dir)
        else {
            fail!(
                "{} does not plan run {index} ({}) as the index does; plan the sweep again",
                path.display(),
                self.runs[index].dir
            );
        };
        std::fs::create_dir_all(&run).doing(|| format!("creating {}", run.display()))?;
        seads_run::store::write_atomic(
            &run.join("config.toml"),
            planned.config.to_toml().as_bytes(),
        )?;
        Ok((run, true))
    }

    /// Writes the sweep of `manifest` into `out`, recording `planned_by`, the commit of the
    /// binary that plans it. Planning the same manifest again writes nothing (only run
    /// directories that were deleted are made again; the index keeps the commit that planned it
    /// first); a different manifest in the same folder is an error, and nothing is written.
    /// Validation errors come back as `Err` before any write.
    pub fn plan(
        manifest: &Manifest,
        text: &str,
        out: &Path,
        planned_by: Option<&str>,
    ) -> Result<Planned> {
        let runs = manifest.expand()?;
        let sweep = Sweep {
            name: manifest.name.clone(),
            description: manifest.description.clone(),
            reference: manifest.reference().to_owned(),
            evaluation: manifest.evaluation.clone(),
            runs: runs
                .iter()
                .map(|r| SweepRun {
                    env: r.env.clone(),
                    variant: r.variant.clone(),
                    seed: r.seed,
                    dir: r.rel_dir(),
                })
                .collect(),
            planned_by: planned_by.map(str::to_owned),
        };
        let index_text = serde_json::to_string_pretty(&sweep)? + "\n";
        if out.join(INDEX).exists() {
            let existing = Sweep::load(out)?;
            let same = Sweep {
                planned_by: existing.planned_by.clone(),
                ..sweep.clone()
            };
            if existing != same {
                fail!(
                    "{} already holds a different sweep ({:?}); plan into another directory",
                    out.display(),
                    existing.name
                );
            }
        } else if out.exists() && std::fs::read_dir(out)?.next().is_some() {
            fail!(
                "{} exists and is not empty; plan a sweep into a new directory",
                out.display()
            );
        }
        // Every existing run's config must be the planned one before anything is written.
        let mut missing = Vec::new();
        for run in &runs {
            let config = out.join(run.rel_dir()).join("config.toml");
            let planned = run.config.to_toml();
            match std::fs::read_to_string(&config) {
                // Written by this version, or by an older one in its layout.
                Ok(text)
                    if text == planned
                        || TrainConfig::from_toml(&text).is_ok_and(|c| c == run.config) => {}
                Ok(_) => fail!(
                    "{} differs from the manifest's configuration; it was changed after planning",
                    config.display()
                ),
                Err(_) => missing.push((run, planned)),
            }
        }
        let created = missing.len();
        for (run, planned) in missing {
            let dir = out.join(run.rel_dir());
            std::fs::create_dir_all(&dir).doing(|| format!("creating {}", dir.display()))?;
            seads_run::store::write_atomic(&dir.join("config.toml"), planned.as_bytes())?;
        }
        if !out.join(INDEX).exists() {
            seads_run::store::write_atomic(&out.join(MANIFEST), text.as_bytes())?;
            // The index last: a folder with an index is a complete plan.
            seads_run::store::write_atomic(&out.join(INDEX), index_text.as_bytes())?;
        }
        Ok(Planned {
            runs: runs.len(),
            created,
        })
    }
}
