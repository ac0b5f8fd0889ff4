//! One task of a sweep, start and end: [`Task::claim`] takes the run (planning its directory
//! again if it was deleted) and says whether there is work, the caller trains and evaluates,
//! and [`Task::finish`] records the outcome in the run's `task.json`. A Slurm array task and a
//! worker of `seads sweep run` both go through here, so the two behave alike.

use std::path::{Path, PathBuf};
use std::time::Duration;

use super::index::Sweep;
use super::state::{Claim, Missing, Outcome, Record, check_outputs};
use crate::{Result, StudyError};

/// What a claimed run needs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Work {
    /// Done, with every output in place: nothing.
    Nothing,
    /// Training (or resuming) and evaluating.
    Run,
    /// Done once, but this output is gone: running again writes it anew.
    Redo(String),
}

/// A run claimed by this task.
#[derive(Debug)]
pub struct Task {
    /// The sweep.
    pub sweep: Sweep,
    /// The run's directory.
    pub run: PathBuf,
    /// Whether the directory was deleted and has just been planned again from the manifest.
    pub replanned: bool,
    /// What the run needs.
    pub work: Work,
    attempts: u32,
    _claim: Claim,
}

impl Task {
    /// Claims run `index` of the sweep in `dir`, waiting up to `patience` for another task that
    /// holds it ([`StudyError::Taken`] if it does not let go). A run copied in without its
    /// checkpoints, an output that cannot be read, an unknown sweep or index are
    /// [`StudyError::is_invalid`]: the user's to fix.
    pub fn claim(dir: &Path, index: usize, patience: Duration) -> Result<Self> {
        let sweep = Sweep::load(dir).map_err(StudyError::into_invalid)?;
        sweep
            .run_dir(dir, index)
            .map_err(StudyError::into_invalid)?;
        let (run, replanned) = sweep.ensure_run_dir(dir, index)?;
        let claim = Claim::take(&run, patience)?;
        let previous = Record::read(&run)?;
        let mut work = Work::Run;
        if let Some(done) = previous.as_ref().filter(|r| r.outcome == Outcome::Done) {
            work = match check_outputs(&run, done) {
                Ok(()) => Work::Nothing,
                Err(Missing::Gone(name)) => Work::Redo(name),
                Err(Missing::Unreadable(why)) => return Err(StudyError::Invalid(why)),
            };
        }
        // Training it again from scratch would replace the data it holds; nothing is recorded,
        // so the run stays "copied".
        if work != Work::Nothing && seads_run::store::is_copy_without_checkpoints(&run) {
            return Err(StudyError::Invalid(format!(
                "{} holds a run's data but no checkpoints folder (copied in by `seads report \
                 --copy-runs`?): it is reported as it is and cannot be trained further",
                run.display()
            )));
        }
        Ok(Self {
            sweep,
            run,
            replanned,
            work,
            attempts: previous.map_or(0, |r| r.attempts) + 1,
            _claim: claim,
        })
    }

    /// Claims the runs `indices` of the sweep in `dir` for one task that trains them as a
    /// population ([`Task::claim`] each, before anything is written), and checks that they can
    /// share one ([`seads_run::check_population`]; not for a single run): a run of other shapes is
    /// [`StudyError::is_invalid`]; a run that another task (another population) holds past
    /// `patience` is [`StudyError::Taken`], and no run is claimed then.
    pub fn claim_population(
        dir: &Path,
        indices: &[usize],
        patience: Duration,
    ) -> Result<Vec<Self>> {
        let tasks = indices
            .iter()
            .map(|&index| Self::claim(dir, index, patience))
            .collect::<Result<Vec<_>>>()?;
        // A run alone is no population: its config is read (and a failure recorded) as it trains.
        if tasks.len() < 2 {
            return Ok(tasks);
        }
        let configs = tasks
            .iter()
            .map(|t| {
                let config = seads_run::load_config(&t.run)
                    .map_err(|e| StudyError::Invalid(e.to_string()))?;
                Ok((t.run.display().to_string(), config))
            })
            .collect::<Result<Vec<_>>>()?;
        seads_run::check_population(&configs).map_err(|e| StudyError::Invalid(e.to_string()))?;
        Ok(tasks)
    }

    /// Records that the task works on the run now.
    pub fn start(&self) -> Result<()> {
        Record::write(&self.run, Outcome::Running, self.attempts, None)
    }

    /// Records how the work went (the error's text where it failed) and lets the run go.
    pub fn finish<E: std::fmt::Display>(self, result: &std::result::Result<(), E>) -> Result<()> {
        match result {
            Ok(()) => Record::write(&self.run, Outcome::Done, self.attempts, None),
            Err(e) => Record::write(
                &self.run,
                Outcome::Failed,
                self.attempts,
                Some(format!("{e:#}")),
            ),
        }
    }
}
