//! The journal of an evaluation in progress: each task's line is appended, as the task ends, to
//! the tasks file's `.partial` beside it, headed by what decides the evaluation (its protocol and
//! checkpoint, and for a robot whether it plays the twin). An evaluation that finds a journal
//! under the same header counts the tasks written there instead of solving them again; the
//! journal is removed once the record is saved.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use seads_planner::{CheckpointId, Protocol, TaskSummary};

use crate::{Context as _, Result, StudyError};

/// A finished task as its journal line holds it: what it adds to its depth's result, and the
/// line the tasks file keeps (without the search time, which differs between machines).
pub(crate) type Finished = (TaskSummary, serde_json::Value);

/// An open journal.
pub(crate) struct Journal {
    partial: PathBuf,
    /// Finished tasks from before, by protocol depth and seed.
    earlier: BTreeMap<(usize, u64), Finished>,
    /// The first failed append (reported at the end: a task's outcome stands without its line).
    append_error: Option<StudyError>,
}

/// Where the journal of one evaluation lies, and the header its tasks are written under.
pub(crate) struct Place {
    partial: PathBuf,
    header: serde_json::Value,
}

impl Place {
    /// The `.partial` file of the evaluation of `checkpoint` (`named` by its epoch unless it is
    /// the run's latest) with `protocol` in `run`, its header holding `extra` keys beside the
    /// protocol and the checkpoint.
    pub(crate) fn new(
        run: &Path,
        protocol: &Protocol,
        checkpoint: &CheckpointId,
        named: Option<u64>,
        extra: &[(&str, serde_json::Value)],
    ) -> Self {
        let partial = run.join(format!("{}.partial", protocol.tasks_file(named)));
        let mut evaluation = serde_json::json!({ "protocol": protocol, "checkpoint": checkpoint });
        for (key, value) in extra {
            evaluation[*key] = value.clone();
        }
        let header = serde_json::json!({ "evaluation": evaluation });
        Self { partial, header }
    }

    /// How many tasks a stopped evaluation wrote under this header.
    pub(crate) fn finished_before(&self) -> Result<usize> {
        Ok(finished_tasks(&self.partial, &self.header)?.len())
    }

    /// Opens the journal: reads the tasks a stopped evaluation under the same header wrote, or
    /// starts a new journal with the header.
    pub(crate) fn open(self) -> Result<Journal> {
        let earlier = finished_tasks(&self.partial, &self.header)?;
        if earlier.is_empty() {
            let mut text = self.header.to_string();
            text.push('\n');
            seads_rl::store::write_atomic(&self.partial, text.as_bytes())?;
        }
        Ok(Journal {
            partial: self.partial,
            earlier,
            append_error: None,
        })
    }
}

impl Journal {
    /// The task of `depth` and `seed`, if it finished before.
    pub(crate) fn earlier(&self, depth: usize, seed: u64) -> Option<&Finished> {
        self.earlier.get(&(depth, seed))
    }

    /// What each task that finished before adds to its depth's result, by depth and seed.
    pub(crate) fn summaries(&self) -> BTreeMap<(usize, u64), TaskSummary> {
        self.earlier
            .iter()
            .map(|(&key, (summary, _))| (key, summary.clone()))
            .collect()
    }

    /// Writes a task's `line` as it ends, with its search time.
    pub(crate) fn append(&mut self, line: &serde_json::Value, planning_s: f64) {
        if self.append_error.is_some() {
            return;
        }
        let mut resumable = line.clone();
        resumable["planning_s"] = planning_s.into();
        if let Err(e) = seads_rl::store::append_json_line(&self.partial, &resumable) {
            self.append_error = Some(e.into());
        }
    }

    /// Saves the evaluation with `save` and removes the journal; an append that failed is the
    /// error instead.
    pub(crate) fn finish(self, save: impl FnOnce() -> Result<()>) -> Result<()> {
        if let Some(e) = self.append_error {
            return Err(e);
        }
        save()?;
        match std::fs::remove_file(&self.partial) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(e).doing(|| format!("removing {}", self.partial.display()))
            }
            _ => Ok(()),
        }
    }
}

/// The tasks an earlier, stopped evaluation wrote into `partial` under `header`, by depth and
/// seed, with their lines. None where there is no such file, or it was written under another
/// header (another protocol or checkpoint) or cannot be read back whole: the evaluation then
/// starts afresh and rewrites it.
fn finished_tasks(
    partial: &Path,
    header: &serde_json::Value,
) -> Result<BTreeMap<(usize, u64), Finished>> {
    if !partial.exists() {
        return Ok(BTreeMap::new());
    }
    let Ok((lines, _torn)) = seads_rl::store::read_json_lines::<serde_json::Value>(partial) else {
        return Ok(BTreeMap::new());
    };
    if lines.first() != Some(header) {
        return Ok(BTreeMap::new());
    }
    let mut tasks = BTreeMap::new();
    for line in lines.into_iter().skip(1) {
        let key = (line["depth"].as_u64(), line["seed"].as_u64());
        let (Some(depth), Some(seed)) = key else {
            return Ok(BTreeMap::new());
        };
        let Ok(summary) = serde_json::from_value::<TaskSummary>(line.clone()) else {
            return Ok(BTreeMap::new());
        };
        let mut line = line;
        if let Some(fields) = line.as_object_mut() {
            fields.remove("planning_s");
        }
        tasks.insert((depth as usize, seed), (summary, line));
    }
    Ok(tasks)
}
