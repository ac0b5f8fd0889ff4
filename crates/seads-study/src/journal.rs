//! The journal of an evaluation in progress: each task's line is appended, as the task ends, to
//! the tasks file's `.partial` beside it, headed by what decides the evaluation (its protocol and
//! checkpoint, and for a robot whether it plays the twin). An evaluation that finds a journal
//! under the same header counts the tasks written there instead of solving them again; the
//! journal is removed once the record is saved. Each task's line also names the binary that
//! solved it (`by`, when the process declared one), so that a record finished by another binary
//! names both; one with a task whose binary is unknown names none.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use seads_planner::{CheckpointId, Evaluator, Protocol, TaskSummary};

use crate::{Context as _, Result, StudyError};

/// A finished task as its journal line holds it: what it adds to its depth's result, and the
/// line the tasks file keeps (without the search time, which differs between machines).
pub(crate) type Finished = (TaskSummary, serde_json::Value);

/// An open journal.
pub(crate) struct Journal {
    partial: PathBuf,
    /// Finished tasks from before, by protocol depth and seed.
    earlier: BTreeMap<(usize, u64), Finished>,
    /// The binaries named by the tasks from before, in the order they first appear; `None` if
    /// a task from before names none (written before journals did), so that not every binary
    /// can be named.
    earlier_by: Option<Vec<Evaluator>>,
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
        Ok(finished_tasks(&self.partial, &self.header)?.0.len())
    }

    /// Opens the journal: reads the tasks a stopped evaluation under the same header wrote, or
    /// starts a new journal with the header.
    pub(crate) fn open(self) -> Result<Journal> {
        let (earlier, earlier_by) = finished_tasks(&self.partial, &self.header)?;
        if earlier.is_empty() {
            let mut text = self.header.to_string();
            text.push('\n');
            seads_rl::store::write_atomic(&self.partial, text.as_bytes())?;
        }
        Ok(Journal {
            partial: self.partial,
            earlier,
            earlier_by,
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

    /// The binaries that solved the evaluation's tasks: those named by the tasks from before,
    /// then this process's, each once; none where one of them is unknown (a task from before
    /// that names no binary, or a process that declared none).
    pub(crate) fn evaluated_by(&self) -> Vec<Evaluator> {
        let (Some(earlier), Some(this)) = (&self.earlier_by, crate::provenance::this_binary())
        else {
            return Vec::new();
        };
        let mut by = earlier.clone();
        if !by.contains(this) {
            by.push(this.clone());
        }
        by
    }

    /// Writes a task's `line` as it ends, with its search time and the binary that solved it.
    pub(crate) fn append(&mut self, line: &serde_json::Value, planning_s: f64) {
        if self.append_error.is_some() {
            return;
        }
        let mut resumable = line.clone();
        resumable["planning_s"] = planning_s.into();
        if let Some(this) = crate::provenance::this_binary() {
            resumable[BY] = serde_json::json!(this);
        }
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

/// The key of a journal line that names the binary that solved the task.
const BY: &str = "by";

/// Finished tasks by depth and seed, and the binaries their lines name (`None` if a line names
/// none).
type Earlier = (BTreeMap<(usize, u64), Finished>, Option<Vec<Evaluator>>);

/// The tasks an earlier, stopped evaluation wrote into `partial` under `header`, by depth and
/// seed, with their lines (without what only the journal keeps: the search time and the
/// binary), and the binaries those lines name, in the order they first appear (`None` if a
/// line names none). No tasks where there is no such file, or it was written under another
/// header (another protocol or checkpoint) or cannot be read back whole: the evaluation then
/// starts afresh and rewrites it.
fn finished_tasks(partial: &Path, header: &serde_json::Value) -> Result<Earlier> {
    let none = || Ok((BTreeMap::new(), Some(Vec::new())));
    if !partial.exists() {
        return none();
    }
    let Ok((lines, _torn)) = seads_rl::store::read_json_lines::<serde_json::Value>(partial) else {
        return none();
    };
    if lines.first() != Some(header) {
        return none();
    }
    let (mut tasks, mut by) = (BTreeMap::new(), Some(Vec::new()));
    for line in lines.into_iter().skip(1) {
        let key = (line["depth"].as_u64(), line["seed"].as_u64());
        let (Some(depth), Some(seed)) = key else {
            return none();
        };
        let Ok(summary) = serde_json::from_value::<TaskSummary>(line.clone()) else {
            return none();
        };
        let mut line = line;
        if let Some(fields) = line.as_object_mut() {
            fields.remove("planning_s");
            match fields.remove(BY) {
                Some(named) => {
                    let Ok(evaluator) = serde_json::from_value::<Evaluator>(named) else {
                        return none();
                    };
                    if let Some(by) = by.as_mut()
                        && !by.contains(&evaluator)
                    {
                        by.push(evaluator);
                    }
                }
                None => by = None,
            }
        }
        tasks.insert((depth as usize, seed), (summary, line));
    }
    Ok((tasks, by))
}
