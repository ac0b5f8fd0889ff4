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
pub type Finished = (TaskSummary, serde_json::Value);

/// An open journal.
pub struct Journal {
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
pub struct Place {
    partial: PathBuf,
    header: serde_json::Value,
}

impl Place {
    /// The `.partial` file of the evaluation of `checkpoint` (`named` by its epoch unless it is
    /// the run's latest) with `protocol` in `run`, its header holding `extra` keys beside the
    /// protocol and the checkpoint.
    pub fn new(
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

    /// What a stopped evaluation wrote under this header: its finished tasks, and its damaged
    /// lines, whose tasks are solved again.
    pub fn finished_before(&self) -> Result<Resumed> {
        let earlier = finished_tasks(&self.partial, &self.header)?;
        Ok(Resumed {
            finished: earlier.tasks.len(),
            damaged: earlier.damaged,
        })
    }

    /// Opens the journal: reads the tasks a stopped evaluation under the same header wrote, or
    /// starts a new journal with the header. A journal with damaged lines is written again
    /// without them, so that the tasks appended now follow whole lines only.
    pub fn open(self) -> Result<Journal> {
        let Earlier {
            tasks: earlier,
            by: earlier_by,
            damaged,
            kept,
        } = finished_tasks(&self.partial, &self.header)?;
        if earlier.is_empty() || damaged > 0 {
            let mut text = self.header.to_string();
            text.push('\n');
            for line in &kept {
                text += line;
                text.push('\n');
            }
            seads_run::store::write_atomic(&self.partial, text.as_bytes())?;
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
    pub fn earlier(&self, depth: usize, seed: u64) -> Option<&Finished> {
        self.earlier.get(&(depth, seed))
    }

    /// What each task that finished before adds to its depth's result, by depth and seed.
    pub fn summaries(&self) -> BTreeMap<(usize, u64), TaskSummary> {
        self.earlier
            .iter()
            .map(|(&key, (summary, _))| (key, summary.clone()))
            .collect()
    }

    /// The binaries that solved the evaluation's tasks: those named by the tasks from before,
    /// then this process's, each once; none where one of them is unknown (a task from before
    /// that names no binary, or a process that declared none).
    pub fn evaluated_by(&self) -> Vec<Evaluator> {
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
    pub fn append(&mut self, line: &serde_json::Value, planning_s: f64) {
        if self.append_error.is_some() {
            return;
        }
        let mut resumable = line.clone();
        resumable["planning_s"] = planning_s.into();
        if let Some(this) = crate::provenance::this_binary() {
            resumable[BY] = serde_json::json!(this);
        }
        if let Err(e) = seads_run::store::append_json_line(&self.partial, &resumable) {
            self.append_error = Some(e.into());
        }
    }

    /// Saves the evaluation with `save` and removes the journal; an append that failed is the
    /// error instead.
    pub fn finish(self, save: impl FnOnce() -> Result<()>) -> Result<()> {
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

/// What a stopped evaluation left in its journal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resumed {
    /// Tasks it finished, counted instead of solved again.
    pub finished: usize,
    /// Lines that could not be read back (garbled by a fault of the disk or a hand), left out:
    /// their tasks are solved again.
    pub damaged: usize,
}

/// What a journal holds under the expected header.
struct Earlier {
    /// Finished tasks by depth and seed.
    tasks: BTreeMap<(usize, u64), Finished>,
    /// The binaries their lines name, in the order they first appear (`None` if a line names
    /// none).
    by: Option<Vec<Evaluator>>,
    /// Lines that could not be read back as a task.
    damaged: usize,
    /// The whole task lines as written, without the damaged ones.
    kept: Vec<String>,
}

impl Earlier {
    fn none() -> Self {
        Self {
            tasks: BTreeMap::new(),
            by: Some(Vec::new()),
            damaged: 0,
            kept: Vec::new(),
        }
    }
}

/// The tasks an earlier, stopped evaluation wrote into `partial` under `header`, by depth and
/// seed, with their lines (without what only the journal keeps: the search time and the
/// binary), and the binaries those lines name. No tasks where there is no such file, or it was
/// written under another header (another protocol or checkpoint): the evaluation then starts
/// afresh and rewrites it. A line that is not a task (damaged) is counted and left out, and so
/// is a torn last line (a crash during an append); every other task stands.
fn finished_tasks(partial: &Path, header: &serde_json::Value) -> Result<Earlier> {
    if !partial.exists() {
        return Ok(Earlier::none());
    }
    let text = std::fs::read(partial).doing(|| format!("reading {}", partial.display()))?;
    let text = String::from_utf8_lossy(&text);
    // Whole lines only: what follows the last newline is a torn append.
    let whole = text.rfind('\n').map_or("", |end| &text[..end]);
    let mut lines = whole.lines().filter(|l| !l.trim().is_empty());
    let first = lines
        .next()
        .and_then(|l| serde_json::from_str::<serde_json::Value>(l).ok());
    if first.as_ref() != Some(header) {
        return Ok(Earlier::none());
    }
    let mut earlier = Earlier::none();
    for text in lines {
        let Some((key, finished, named)) = task_of(text) else {
            earlier.damaged += 1;
            continue;
        };
        match named {
            Some(evaluator) => {
                if let Some(by) = earlier.by.as_mut()
                    && !by.contains(&evaluator)
                {
                    by.push(evaluator);
                }
            }
            None => earlier.by = None,
        }
        earlier.tasks.insert(key, finished);
        earlier.kept.push(text.to_owned());
    }
    Ok(earlier)
}

/// A journal line as a task: its depth and seed, what it adds and its line without what only
/// the journal keeps, and the binary it names; `None` for a line that is not one.
fn task_of(text: &str) -> Option<((usize, u64), Finished, Option<Evaluator>)> {
    let mut line: serde_json::Value = serde_json::from_str(text).ok()?;
    let depth = usize::try_from(line["depth"].as_u64()?).ok()?;
    let seed = line["seed"].as_u64()?;
    let summary = serde_json::from_value::<TaskSummary>(line.clone()).ok()?;
    let fields = line.as_object_mut()?;
    fields.remove("planning_s");
    let named = match fields.remove(BY) {
        Some(named) => Some(serde_json::from_value::<Evaluator>(named).ok()?),
        None => None,
    };
    Some(((depth, seed), (summary, line), named))
}
