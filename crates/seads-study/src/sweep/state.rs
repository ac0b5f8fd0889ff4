//! The state of one run of a sweep, read from its directory alone (never from Slurm), so that
//! `seads sweep status` tells the same on a laptop, a login node or inside a job:
//! - `task.lock` is locked (the run's [`seads_run::store::RunLock`], an OS file lock) while a task or any
//!   other writer works on the run: a killed one releases it, so "running" can never be stale;
//! - `task.json` records the last task's outcome: running, done or failed (with the error).

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::error::Taken;
use crate::{Context as _, Result};
use serde::{Deserialize, Serialize};

/// The task record of a run directory.
pub const RECORD: &str = "task.json";
/// The log of the tasks' output (`seads sweep run` appends each task's stdout and stderr).
pub const LOG: &str = "task.log";

/// What the last task recorded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// A task started (if the lock is free now, it was killed).
    Running,
    /// Trained and evaluated.
    Done,
    /// Stopped with an error.
    Failed,
}

/// `task.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Record {
    /// Outcome.
    pub outcome: Outcome,
    /// Host of the task.
    pub host: String,
    /// Process id of the task.
    pub pid: u32,
    /// Tasks started on this run so far (re-queues and re-runs included).
    pub attempts: u32,
    /// Seconds since the Unix epoch when the record was written.
    pub written_unix: u64,
    /// The error of a failed task.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The files a finished task's results rest on, relative to the run: its metrics and the
    /// evaluations it wrote.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<String>,
}

impl Record {
    /// Reads the record of `run` (`None` before the first task).
    pub fn read(run: &Path) -> Result<Option<Self>> {
        let path = run.join(RECORD);
        match std::fs::read_to_string(&path) {
            Ok(text) => {
                Ok(Some(serde_json::from_str(&text).doing(|| {
                    format!("{} is not a task record", path.display())
                })?))
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e).doing(|| format!("reading {}", path.display())),
        }
    }

    /// Writes a record of this process with `outcome` into `run`; a `Done` record lists the
    /// run's metrics and evaluation files as its outputs.
    pub fn write(run: &Path, outcome: Outcome, attempts: u32, error: Option<String>) -> Result<()> {
        let outputs = if outcome == Outcome::Done {
            present_outputs(run)
        } else {
            Vec::new()
        };
        let record = Self {
            outputs,
            outcome,
            host: hostname(),
            pid: std::process::id(),
            attempts,
            written_unix: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
            error,
        };
        seads_run::store::write_atomic(
            &run.join(RECORD),
            (serde_json::to_string_pretty(&record)? + "\n").as_bytes(),
        )?;
        Ok(())
    }
}

/// The metrics file and every evaluation file of `run` that exist, sorted.
fn present_outputs(run: &Path) -> Vec<String> {
    let mut outputs: Vec<String> = std::fs::read_dir(run)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("evaluation") && n.ends_with(".json"))
        .collect();
    outputs.sort();
    outputs.insert(0, seads_run::store::METRICS.to_owned());
    outputs
}

/// What is wrong with the outputs of a run whose task finished.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Missing {
    /// A file is gone: the task is to be run again, which writes it anew.
    Gone(String),
    /// A file cannot be read: named with why, left for the user (remove it to have it redone).
    Unreadable(String),
}

/// Checks that the outputs of a finished task are readable: those its record lists, or for a
/// record from before outputs were listed, the metrics and the evaluation files present.
pub fn check_outputs(run: &Path, record: &Record) -> std::result::Result<(), Missing> {
    let listed = if record.outputs.is_empty() {
        present_outputs(run)
    } else {
        record.outputs.clone()
    };
    for name in listed {
        let path = run.join(&name);
        let readable = if name == seads_run::store::METRICS {
            match seads_run::store::read_json_lines::<serde_json::Value>(&path) {
                Ok((lines, false)) if !lines.is_empty() => metrics_in_order(&lines),
                Ok(_) => Err("it is empty or ends in a torn line".to_owned()),
                Err(e) => Err(format!("{e}")),
            }
        } else {
            std::fs::read_to_string(&path)
                .map_err(|e| e.to_string())
                .and_then(|t| {
                    serde_json::from_str::<serde_json::Value>(&t)
                        .map(|_| ())
                        .map_err(|e| e.to_string())
                })
        };
        match readable {
            Ok(()) => {}
            Err(_) if !path.exists() => return Err(Missing::Gone(name)),
            Err(why) => {
                return Err(Missing::Unreadable(format!(
                    "{} cannot be read ({why}); remove it to have it made again",
                    path.display()
                )));
            }
        }
    }
    Ok(())
}

/// Whether metrics lines are what training writes: each an object with a whole `epoch` and
/// `env_steps`, the epochs strictly rising (a line of another type, a repeated or an
/// out-of-order epoch is damage, not progress).
fn metrics_in_order(lines: &[serde_json::Value]) -> std::result::Result<(), String> {
    let mut last: Option<u64> = None;
    for (i, line) in lines.iter().enumerate() {
        let field = |key: &str| line.get(key).and_then(serde_json::Value::as_u64);
        let (Some(epoch), Some(_)) = (field("epoch"), field("env_steps")) else {
            return Err(format!("line {} is not a metrics line", i + 1));
        };
        if last.is_some_and(|l| epoch <= l) {
            return Err(format!(
                "line {} has epoch {epoch} after epoch {}",
                i + 1,
                last.unwrap_or_default()
            ));
        }
        last = Some(epoch);
    }
    Ok(())
}

/// Whether the run's budget (`config.toml`) lies beyond its last metrics line: raised with
/// `train --resume --env-steps` after its task finished, so there is training left.
fn budget_raised(run: &Path) -> bool {
    let Ok(config) = seads_run::load_config(run) else {
        return false;
    };
    let Ok((lines, _)) = seads_run::store::read_json_lines::<serde_json::Value>(
        &run.join(seads_run::store::METRICS),
    ) else {
        return false;
    };
    let steps = lines
        .last()
        .and_then(|l| l.get("env_steps"))
        .and_then(serde_json::Value::as_u64);
    steps.is_some_and(|s| s < config.env_steps)
}

/// The host name, for the record (empty if unknown).
fn hostname() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_owned())
        .unwrap_or_default()
}

/// Notes in the `task.log` of each run in `others` that it trains in a population whose output
/// goes to `log` (the first member's).
pub fn note_population_log(others: &[PathBuf], members: &str, log: &Path) -> Result<()> {
    for run in others {
        let path = run.join(LOG);
        let note = format!(
            "trained in a population with runs {members}; see {}\n",
            log.display()
        );
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .doing(|| format!("opening {}", path.display()))?;
        std::io::Write::write_all(&mut file, note.as_bytes())
            .doing(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// The exclusive claim of a task on a run (its [`seads_run::store::RunLock`]), held until dropped (or
/// the process dies).
#[derive(Debug)]
pub struct Claim {
    _lock: seads_run::store::RunLock,
}

/// How long a Slurm task or a task started by hand waits for a run that another task holds:
/// a task that was just killed (a Slurm re-queue) may take a few seconds to die.
pub const PATIENCE: Duration = Duration::from_secs(60);

/// The exit status of a `seads sweep task` that found its run held by another task, so that
/// `seads sweep run` can tell "taken elsewhere" from "failed".
pub const TAKEN_EXIT: u8 = 3;

impl Claim {
    /// Claims `run`, waiting up to `patience` for another task to release it; [`Taken`] if it
    /// does not.
    pub fn take(run: &Path, patience: Duration) -> Result<Self> {
        match seads_run::store::RunLock::acquire(run, "seads sweep task", patience) {
            Ok(lock) => Ok(Self { _lock: lock }),
            Err(seads_run::RunError::Busy { .. }) => Err(Taken(run.to_path_buf()).into()),
            Err(e) => Err(e).doing(|| format!("locking {}", run.display())),
        }
    }
}

/// Whether a task holds `run` now.
pub fn is_claimed(run: &Path) -> bool {
    seads_run::store::run_is_locked(run)
}

/// Where a run stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Trained and evaluated.
    Done,
    /// A task works on it now.
    Running,
    /// The last task failed.
    Failed,
    /// Not started, or interrupted (killed) and waiting to be resumed.
    Pending,
    /// Its data was copied in without checkpoints (`seads report --copy-runs`, copied back into
    /// a sweep): reported as it is, never trained further.
    Copied,
    /// Its task record cannot be read: shown with why ([`damage`]), left alone by `sweep run`
    /// while the other runs go on.
    Damaged,
}

impl Status {
    /// Every status, in the order of the summary.
    pub const ALL: [Status; 6] = [
        Self::Done,
        Self::Running,
        Self::Failed,
        Self::Pending,
        Self::Copied,
        Self::Damaged,
    ];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Done => "done",
            Self::Running => "running",
            Self::Failed => "failed",
            Self::Pending => "pending",
            Self::Copied => "copied",
            Self::Damaged => "damaged",
        }
    }
}

/// The status of `run` and its record. A run that a task finished stays done when its
/// checkpoints are removed; one whose data was copied in without them, with no record of a
/// finished task, is [`Status::Copied`].
pub fn status(run: &Path) -> Result<(Status, Option<Record>)> {
    let record = match Record::read(run) {
        Ok(record) => record,
        Err(_) if is_claimed(run) => return Ok((Status::Running, None)),
        Err(_) => return Ok((Status::Damaged, None)),
    };
    let status = if is_claimed(run) {
        Status::Running
    } else {
        match record.as_ref().map(|r| r.outcome) {
            Some(Outcome::Done) => match check_outputs(run, record.as_ref().expect("done")) {
                Ok(()) if budget_raised(run) => Status::Pending,
                Ok(()) => Status::Done,
                Err(Missing::Gone(_)) => Status::Pending,
                Err(Missing::Unreadable(_)) => Status::Damaged,
            },
            _ if seads_run::store::is_copy_without_checkpoints(run) => Status::Copied,
            Some(Outcome::Failed) => Status::Failed,
            Some(Outcome::Running) | None => Status::Pending,
        }
    };
    Ok((status, record))
}

/// Why `run` is [`Status::Damaged`] (its task record, or an output of its finished task,
/// cannot be read), or why a finished run is pending again (an output is gone, or the whole
/// directory, planned again when it runs); `None` if nothing is.
pub fn damage(run: &Path) -> Option<String> {
    if !run.exists() {
        return Some("deleted: planned again from the manifest when it runs".into());
    }
    match Record::read(run) {
        Err(e) => Some(format!("{e:#}")),
        Ok(Some(record)) if record.outcome == Outcome::Done => match check_outputs(run, &record) {
            Ok(()) => None,
            Err(Missing::Gone(name)) => Some(format!("{name} is gone: to be made again")),
            Err(Missing::Unreadable(why)) => Some(why),
        },
        Ok(_) => None,
    }
}

/// `todo` (runs of the sweep in `dir` to train, in their order) with the runs already begun
/// (environment steps in their metrics) first, each part in its order, so that a restarted
/// sweep finishes what it had begun before it starts anything new. A run whose metrics cannot
/// be read counts as not begun.
pub fn begun_first(run_dirs: &[std::path::PathBuf], todo: &[usize]) -> Vec<usize> {
    let begun = |i: usize| {
        run_dirs
            .get(i)
            .and_then(|run| seads_run::store::last_env_steps(run).ok())
            .is_some_and(|steps| steps > 0)
    };
    let (first, rest): (Vec<usize>, Vec<usize>) = todo.iter().partition(|&&i| begun(i));
    first.into_iter().chain(rest).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Of four runs to train, the two with steps in their metrics come first, each part in its
    /// order; a run without metrics, or with only its first line at step 0, is not begun.
    #[test]
    fn begun_runs_come_before_new_ones() {
        let dir = tempfile::tempdir().unwrap();
        let runs: Vec<std::path::PathBuf> =
            (0..5).map(|i| dir.path().join(format!("r{i}"))).collect();
        for run in &runs {
            std::fs::create_dir(run).unwrap();
        }
        let line = |steps: u64| format!("{{\"epoch\":1,\"env_steps\":{steps},\"wall_s\":0.1}}\n");
        std::fs::write(runs[1].join("metrics.jsonl"), line(0)).unwrap();
        std::fs::write(runs[2].join("metrics.jsonl"), line(0) + &line(4200)).unwrap();
        std::fs::write(runs[4].join("metrics.jsonl"), line(137)).unwrap();
        assert_eq!(begun_first(&runs, &[0, 1, 2, 3, 4]), [2, 4, 0, 1, 3]);
        assert_eq!(begun_first(&runs, &[4, 3, 0]), [4, 3, 0]);
        assert_eq!(begun_first(&runs, &[]), Vec::<usize>::new());
    }

    #[test]
    fn a_claim_shows_as_running_and_excludes_a_second_task() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(status(dir.path()).unwrap().0, Status::Pending);
        let claim = Claim::take(dir.path(), PATIENCE).unwrap();
        Record::write(dir.path(), Outcome::Running, 1, None).unwrap();
        assert_eq!(status(dir.path()).unwrap().0, Status::Running);
        // A second claim waits for the first, and gets it once it is released.
        let path = dir.path().to_path_buf();
        let impatient = Claim::take(dir.path(), Duration::from_millis(200)).unwrap_err();
        assert!(
            matches!(impatient, crate::StudyError::Taken(_)),
            "{impatient}"
        );
        let waiter = std::thread::spawn(move || Claim::take(&path, PATIENCE).map(|_| ()));
        std::thread::sleep(Duration::from_millis(300));
        assert!(!waiter.is_finished());
        drop(claim);
        waiter.join().unwrap().unwrap();
        // Released without a final record: a killed task, to be resumed.
        assert_eq!(status(dir.path()).unwrap().0, Status::Pending);
        Record::write(dir.path(), Outcome::Failed, 1, Some("boom".into())).unwrap();
        let (s, r) = status(dir.path()).unwrap();
        assert_eq!(s, Status::Failed);
        assert_eq!(r.unwrap().error.as_deref(), Some("boom"));
    }

    #[test]
    fn data_copied_without_checkpoints_is_copied_unless_a_task_finished_it() {
        let dir = tempfile::tempdir().unwrap();
        let run = dir.path();
        std::fs::create_dir(run.join("checkpoints")).unwrap();
        std::fs::write(
            run.join("metrics.jsonl"),
            "{\"epoch\":1,\"env_steps\":10}\n",
        )
        .unwrap();
        // A run that trained (checkpoints folder present) and was killed: to be resumed.
        assert_eq!(status(run).unwrap().0, Status::Pending);
        std::fs::remove_dir(run.join("checkpoints")).unwrap();
        assert_eq!(status(run).unwrap().0, Status::Copied);
        // A failed record does not make copied data trainable.
        Record::write(run, Outcome::Failed, 1, Some("no checkpoints".into())).unwrap();
        assert_eq!(status(run).unwrap().0, Status::Copied);
        // A run a task finished is done, with or without its checkpoints.
        Record::write(run, Outcome::Done, 1, None).unwrap();
        assert_eq!(status(run).unwrap().0, Status::Done);
        // An empty metrics file is no data: a planned run.
        let planned = tempfile::tempdir().unwrap();
        std::fs::write(planned.path().join("metrics.jsonl"), "").unwrap();
        assert_eq!(status(planned.path()).unwrap().0, Status::Pending);
        // Done needs readable outputs: a gone evaluation is made again, an unreadable one is
        // damage, named.
        std::fs::write(
            run.join("metrics.jsonl"),
            "{\"epoch\":1,\"env_steps\":10}\n",
        )
        .unwrap();
        std::fs::write(run.join("evaluation-replan.json"), "{}").unwrap();
        Record::write(run, Outcome::Done, 1, None).unwrap();
        let record = Record::read(run).unwrap().unwrap();
        assert_eq!(record.outputs, ["metrics.jsonl", "evaluation-replan.json"]);
        assert_eq!(status(run).unwrap().0, Status::Done);
        assert_eq!(damage(run), None);
        std::fs::write(run.join("evaluation-replan.json"), "{").unwrap();
        assert_eq!(status(run).unwrap().0, Status::Damaged);
        assert!(
            damage(run)
                .unwrap()
                .contains("evaluation-replan.json cannot be read")
        );
        std::fs::remove_file(run.join("evaluation-replan.json")).unwrap();
        assert_eq!(status(run).unwrap().0, Status::Pending);
        assert!(
            damage(run)
                .unwrap()
                .contains("evaluation-replan.json is gone")
        );
        std::fs::write(run.join("evaluation-replan.json"), "{}").unwrap();
        std::fs::write(
            run.join("metrics.jsonl"),
            "{\"epoch\":1,\"env_steps\":10}\n{\"ep",
        )
        .unwrap();
        assert_eq!(status(run).unwrap().0, Status::Damaged);
        std::fs::write(
            run.join("metrics.jsonl"),
            "{\"epoch\":1,\"env_steps\":10}\n",
        )
        .unwrap();
        // Held by a task, it is running whatever its files say.
        let _claim = Claim::take(run, PATIENCE).unwrap();
        assert_eq!(status(run).unwrap().0, Status::Running);
    }

    /// Metrics that are not what training writes (a valid JSON line of another type, a repeated
    /// or an out-of-order epoch) are damage, not progress; a finished run whose budget was
    /// raised since (`train --resume --env-steps`) is pending again, so that a sweep trains
    /// and evaluates it on.
    #[test]
    fn bad_metrics_are_damage_and_a_raised_budget_is_pending() {
        let dir = tempfile::tempdir().unwrap();
        let run = dir.path();
        let line = |e: u64, s: u64| format!("{{\"epoch\":{e},\"env_steps\":{s}}}\n");
        std::fs::write(run.join("metrics.jsonl"), line(1, 10) + &line(2, 20)).unwrap();
        Record::write(run, Outcome::Done, 1, None).unwrap();
        assert_eq!(status(run).unwrap().0, Status::Done);
        for (bad, why) in [
            (line(1, 10) + "[1, 2]\n", "line 2 is not a metrics line"),
            (
                line(1, 10) + "{\"epoch\":\"2\",\"env_steps\":20}\n",
                "line 2 is not",
            ),
            (line(1, 10) + &line(1, 10), "epoch 1 after epoch 1"),
            (line(2, 20) + &line(1, 10), "epoch 1 after epoch 2"),
        ] {
            std::fs::write(run.join("metrics.jsonl"), bad).unwrap();
            assert_eq!(status(run).unwrap().0, Status::Damaged, "{why}");
            assert!(damage(run).unwrap().contains(why), "{:?}", damage(run));
        }
        // The budget of config.toml beyond the last line: pending, not done.
        std::fs::write(run.join("metrics.jsonl"), line(1, 10) + &line(2, 20)).unwrap();
        let config = seads_run::TrainConfig {
            env_steps: 20,
            ..seads_run::TrainConfig::preset("lightsout-cursor").unwrap()
        };
        std::fs::write(run.join("config.toml"), config.to_toml()).unwrap();
        assert_eq!(status(run).unwrap().0, Status::Done);
        let raised = seads_run::TrainConfig {
            env_steps: 30,
            ..config
        };
        std::fs::write(run.join("config.toml"), raised.to_toml()).unwrap();
        assert_eq!(status(run).unwrap().0, Status::Pending);
    }
}
