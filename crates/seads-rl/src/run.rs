//! A run directory: `config.toml`, `metrics.jsonl`, checkpoints written atomically, and resuming
//! a killed run from its last checkpoint.
//!
//! ```text
//! RUN/config.toml                 the configuration (written once)
//! RUN/metrics.jsonl               one line per evaluation
//! RUN/checkpoints/epoch-000100/   actor + skill model (kept for evaluation over training)
//! RUN/checkpoints/epoch-000200/   … the latest also holds critics, optimisers, episodes, progress
//! RUN/checkpoints/latest          name of the latest complete checkpoint
//! ```

use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::learner::{Hook, Learner, Moment};
use crate::store::{
    CHECKPOINTS, CONFIG, LATEST, Latest, METRICS, MetricsLine, append_metrics, check_origin,
    checkpoint_name, checkpoints, clean_leftovers, commit_dir, hidden_sibling, read_metrics_text,
    write_atomic, write_metrics, write_origin,
};
use crate::{RlError, TrainConfig, Trainer, load_config};

/// What a call to [`Run::step`] did.
#[derive(Debug, Clone)]
pub struct RunEvent<L: Learner = Trainer> {
    /// The epoch's statistics.
    pub stats: L::Stats,
    /// The evaluation written to `metrics.jsonl`, if one was due.
    pub metrics: Option<L::Metrics>,
    /// The checkpoint written, if one was due.
    pub checkpoint: Option<PathBuf>,
}

/// A training run writing into a directory.
pub struct Run<L: Learner = Trainer> {
    dir: PathBuf,
    trainer: L,
    started: Instant,
    wall_before: f64,
    hook: Hook,
    repairs: Vec<String>,
}

impl<L: Learner> Run<L> {
    /// Starts a run in `dir` (created; it must not already hold a run).
    pub fn create(dir: &Path, config: TrainConfig) -> Result<Self, RlError> {
        Self::check_free(dir)?;
        Self::with_trainer(dir, L::build(config)?)
    }

    fn check_free(dir: &Path) -> Result<(), RlError> {
        if dir.join(CONFIG).exists() {
            return Err(RlError::config(format!(
                "{} already holds a run; resume it with --resume or choose another directory",
                dir.display()
            )));
        }
        // What is left of a run whose config was removed is never trained over.
        let checkpoints = fs::read_dir(dir.join(CHECKPOINTS)).is_ok_and(|mut d| d.next().is_some());
        if dir.join(METRICS).exists() || checkpoints {
            return Err(RlError::config(format!(
                "{} holds a run's metrics or checkpoints but no config.toml: restore its \
                 config.toml to resume it, or choose another directory",
                dir.display()
            )));
        }
        Ok(())
    }

    /// Starts a run in `dir` with a trainer built elsewhere (e.g. on the robot's environment).
    pub fn with_trainer(dir: &Path, trainer: L) -> Result<Self, RlError> {
        Self::check_free(dir)?;
        fs::create_dir_all(dir.join(CHECKPOINTS)).map_err(|e| RlError::io(dir, e))?;
        write_metrics::<L::Metrics>(dir, &[])?;
        // The config last: a folder with a config is a run.
        write_atomic(&dir.join(CONFIG), trainer.config().to_toml().as_bytes())?;
        Ok(Self::new(dir, trainer, 0.0, Vec::new()))
    }

    fn new(dir: &Path, trainer: L, wall_before: f64, repairs: Vec<String>) -> Self {
        Self {
            dir: dir.to_path_buf(),
            trainer,
            started: Instant::now(),
            wall_before,
            hook: Box::new(|_| {}),
            repairs,
        }
    }

    /// Continues the run in `dir` from its latest checkpoint (from scratch if it has none).
    pub fn resume(dir: &Path) -> Result<Self, RlError> {
        Self::resume_with(dir, L::build)
    }

    /// Continues the run in `dir`, building its trainer with `build` from the saved config.
    ///
    /// Repairs what a crash can leave: leftover temporary files and folders are removed; a
    /// checkpoint that cannot be loaded (the latest included) is passed over for the newest one
    /// that can; evaluation lines after that checkpoint, and a torn last line, are dropped.
    /// Each repair is described in [`Run::repairs`]. It is an error when no checkpoint can be
    /// loaded although the run has written one, and when a run with metrics has no checkpoints
    /// folder at all.
    pub fn resume_with(
        dir: &Path,
        mut build: impl FnMut(TrainConfig) -> Result<L, RlError>,
    ) -> Result<Self, RlError> {
        let config = load_config(dir)?;
        let copied = crate::store::is_copy_without_checkpoints(dir);
        let latest = crate::store::read_latest(dir)?;
        let written = if dir.join(CHECKPOINTS).is_dir() {
            checkpoints(dir)?
        } else {
            Vec::new()
        };
        let damaged = |reason: String| {
            RlError::from(seads_run::RunError::Damaged {
                dir: dir.display().to_string(),
                reason,
            })
        };
        // A directory planned by a sweep holds only its config: the run starts here. One whose
        // metrics are gone but whose checkpoints remain has lost its history.
        if !dir.join(METRICS).exists() {
            if latest != Latest::Absent || !written.is_empty() {
                return Err(damaged(format!(
                    "{METRICS} is missing but {CHECKPOINTS}/ holds checkpoints, so the run's \
                     history is lost"
                )));
            }
            fs::create_dir_all(dir.join(CHECKPOINTS)).map_err(|e| RlError::io(dir, e))?;
            write_metrics::<L::Metrics>(dir, &[])?;
        }
        let mut repairs: Vec<String> = clean_leftovers(&dir.join(CHECKPOINTS))?
            .into_iter()
            .map(|name| format!("removed {name}, left by an interrupted write"))
            .collect();
        let mut trainer = build(config.clone())?;
        let mut candidates: Vec<PathBuf> = Vec::new();
        let had_pointer = latest != Latest::Absent;
        match latest {
            Latest::Names(path) => candidates.push(path),
            Latest::Unusable(why) => {
                repairs.push(format!("ignored the latest pointer: {why}"));
                // A directory in the pointer's place would stop the next checkpoint's pointer.
                let pointer = dir.join(CHECKPOINTS).join(LATEST);
                if pointer.is_dir() {
                    let aside = dir.join(CHECKPOINTS).join(format!("{LATEST}.damaged"));
                    let _ = fs::remove_dir_all(&aside);
                    fs::rename(&pointer, &aside).map_err(|e| RlError::io(&pointer, e))?;
                    repairs.push(format!("moved that directory aside to {}", aside.display()));
                }
            }
            Latest::Absent => {}
        }
        for (_, path) in written.iter().rev() {
            if !candidates.contains(path) {
                candidates.push(path.clone());
            }
        }
        let mut failures: Vec<RlError> = Vec::new();
        let mut resumed = None;
        for candidate in candidates {
            let loaded = check_origin(&candidate, &config)
                .map_err(RlError::from)
                .and_then(|()| trainer.load(&candidate));
            match loaded {
                Ok(()) => {
                    resumed = Some(candidate);
                    break;
                }
                Err(e) => {
                    repairs.push(format!(
                        "passed over checkpoint {}: {e}",
                        candidate.display()
                    ));
                    failures.push(e);
                    // A failed load may have changed part of the state: start from a fresh one.
                    trainer = build(config.clone())?;
                }
            }
        }
        if let Some(checkpoint) = &resumed {
            crate::store::check_config(checkpoint, &config)?;
        }
        let (mut metrics, torn) = read_metrics_text::<L::Metrics>(dir)?;
        // Checked before anything is written (see `is_copy_without_checkpoints`); a file that
        // held only a torn line is no data.
        if copied && !metrics.is_empty() {
            return Err(RlError::CheckpointsMissing {
                dir: dir.display().to_string(),
                lines: metrics.len(),
            });
        }
        if torn {
            repairs.push(format!("dropped a torn last line of {METRICS}"));
        }
        // The first checkpoint follows the evaluation of epoch `checkpoint_every` at once, so
        // an evaluation after that epoch means a checkpoint was written: none left means they
        // were removed, and starting afresh would throw the run away.
        let last_evaluated = metrics.last().map_or(0, |m| m.epoch());
        if resumed.is_none() && written.is_empty() && last_evaluated > config.checkpoint_every {
            return Err(damaged(format!(
                "{METRICS} reaches epoch {last_evaluated} but {CHECKPOINTS}/ holds no checkpoint \
                 (one is written every {} epochs), so they were removed",
                config.checkpoint_every
            )));
        }
        if resumed.is_none() && (had_pointer || !written.is_empty()) {
            let tried = failures.len();
            return Err(match failures.into_iter().next() {
                Some(newest) => RlError::NoCheckpoint {
                    dir: dir.join(CHECKPOINTS).display().to_string(),
                    tried,
                    source: Box::new(newest),
                },
                None => RlError::from(seads_run::RunError::Checkpoint {
                    path: dir.join(CHECKPOINTS).display().to_string(),
                    reason: "the latest checkpoint is missing and no other exists".into(),
                }),
            });
        }
        // Evaluations after the checkpoint are redone; a run with no checkpoint starts afresh.
        let epoch = trainer.epoch();
        let before = metrics.len();
        metrics.retain(|m| resumed.is_some() && m.epoch() <= epoch);
        if metrics.len() < before {
            repairs.push(format!(
                "dropped {} evaluation line(s) after epoch {epoch}, to be redone",
                before - metrics.len()
            ));
        }
        if metrics.len() < before || torn {
            write_metrics(dir, &metrics)?;
        } else {
            // The TensorBoard view follows the metrics kept, whatever a crash left of it.
            seads_run::store::write_events(dir, &metrics)?;
        }
        let wall_before = metrics.last().map_or(0.0, |m| m.wall_s());
        Ok(Self::new(dir, trainer, wall_before, repairs))
    }

    /// What resuming repaired, one sentence each (empty for a new run or a clean resume).
    pub fn repairs(&self) -> &[String] {
        &self.repairs
    }

    /// Calls `hook` at every [`Moment`] from now on.
    pub fn set_hook(&mut self, hook: Hook) {
        self.hook = hook;
    }

    /// The trainer.
    pub fn trainer(&self) -> &L {
        &self.trainer
    }

    /// The run directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Whether the budget is spent.
    pub fn finished(&self) -> bool {
        self.trainer.finished()
    }

    /// Wall-clock seconds of the run so far (across resumes).
    pub fn wall_s(&self) -> f64 {
        self.wall_before + self.started.elapsed().as_secs_f64()
    }

    /// Evaluates the agent (SEADS: skill coverage) and appends a metrics line.
    pub fn evaluate(&mut self, stats: &L::Stats) -> Result<L::Metrics, RlError> {
        let wall_s = self.wall_s();
        let metrics = self.trainer.metrics(stats, wall_s)?;
        append_metrics(&self.dir, &metrics)?;
        (self.hook)(Moment::MetricsAppended);
        Ok(metrics)
    }

    /// Writes a complete checkpoint durably (a temporary folder renamed into place, then the
    /// `latest` pointer), then strips the resume-only files from all but the two newest.
    pub fn checkpoint(&mut self) -> Result<PathBuf, RlError> {
        let root = self.dir.join(CHECKPOINTS);
        let name = checkpoint_name(self.trainer.epoch());
        let dest = root.join(&name);
        let tmp = hidden_sibling(&dest, "tmp");
        let _ = fs::remove_dir_all(&tmp);
        fs::create_dir_all(&tmp).map_err(|e| RlError::io(&tmp, e))?;
        self.trainer.save(&tmp)?;
        write_origin(&tmp, self.trainer.config())?;
        (self.hook)(Moment::CheckpointWritten);
        commit_dir(&tmp, &dest)?;
        (self.hook)(Moment::CheckpointRenamed);
        write_atomic(&root.join(LATEST), name.as_bytes())?;
        (self.hook)(Moment::LatestWritten);
        let epoch = self.trainer.epoch();
        let older: Vec<PathBuf> = checkpoints(&self.dir)?
            .into_iter()
            .filter(|(e, _)| *e <= epoch)
            .map(|(_, p)| p)
            .collect();
        for old in older.iter().rev().skip(2) {
            for file in L::resume_only_files() {
                match fs::remove_file(old.join(file)) {
                    Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                        return Err(RlError::io(&old.join(file), e));
                    }
                    _ => {}
                }
            }
        }
        Ok(dest)
    }

    /// One epoch, plus the evaluation and checkpoint that are due after it (both also before
    /// the first epoch's updates, i.e. at epoch 1, and when the budget is spent).
    pub fn step(&mut self) -> Result<RunEvent<L>, RlError> {
        let first = self.trainer.epoch() == 0;
        let stats = self.trainer.run_epoch_observed(&mut self.hook)?;
        self.after_epoch(first, stats)
    }

    /// The learner and the hook, for a population that runs the parts of an epoch itself.
    pub(crate) fn parts(&mut self) -> (&mut L, &mut Hook) {
        (&mut self.trainer, &mut self.hook)
    }

    /// The evaluation and checkpoint due after an epoch that gave `stats` (`first`: it was the
    /// run's first epoch).
    pub(crate) fn after_epoch(
        &mut self,
        first: bool,
        stats: L::Stats,
    ) -> Result<RunEvent<L>, RlError> {
        (self.hook)(Moment::EpochDone);
        let (eval_due, checkpoint_due) = due(
            self.trainer.config(),
            first,
            self.trainer.epoch(),
            self.trainer.finished(),
        );
        let metrics = if eval_due {
            Some(self.evaluate(&stats)?)
        } else {
            None
        };
        let checkpoint = if checkpoint_due {
            Some(self.checkpoint()?)
        } else {
            None
        };
        Ok(RunEvent {
            stats,
            metrics,
            checkpoint,
        })
    }
}

/// Whether an evaluation and whether a checkpoint are due once `epoch` epochs are done (`first`:
/// the run's first epoch was the last; `done`: the budget is spent).
pub(crate) fn due(config: &TrainConfig, first: bool, epoch: u64, done: bool) -> (bool, bool) {
    (
        first || epoch.is_multiple_of(config.eval_every) || done,
        epoch.is_multiple_of(config.checkpoint_every) || done,
    )
}
