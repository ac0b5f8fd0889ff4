//! The run store: the files of a run directory and how they are written, so that a crash at any
//! point leaves a directory that resumes to exactly the run it would have been. Its public API is
//! what studies and the command line read and write beside a run: atomic writes
//! ([`write_atomic`]), JSON Lines ([`read_json_lines`], [`append_json_line`]), the metrics
//! ([`METRICS`], [`read_metrics_as`], [`last_env_steps`]), the checkpoints ([`checkpoints`],
//! [`latest_checkpoint`], [`checkpoint_id`], [`is_copy_without_checkpoints`]) and the run's one
//! writer ([`RunLock`], [`run_is_locked`]); the rest serves `seads-rl`'s `Run` alone.
//!
//! The contract (docs/ARCHITECTURE.md, "Invariants"):
//! - every file is written to a temporary name, fsynced, renamed into place and its folder
//!   fsynced ([`write_atomic`]); a checkpoint is a folder written the same way (`commit_dir`);
//! - `metrics.jsonl` only grows by whole lines, each fsynced before the checkpoint that follows
//!   it; a line cut by a crash has no newline and is dropped when read ([`read_metrics_as`]);
//! - the two newest checkpoints keep what resuming needs, so one that cannot be read has a
//!   complete predecessor to fall back to.
//!
//! Resuming (`Run::resume`) loads `latest`, or, if it cannot be loaded, the newest checkpoint
//! that can; drops evaluation lines after that checkpoint and a torn last line; says what it
//! repaired on stderr; and continues exactly: environments, RNG streams, buffers, optimiser
//! moments (required, never silently reset) and prepared updates are all restored. It is an
//! error when checkpoints were written and none can be loaded; a run killed before its first
//! checkpoint starts again. A run with metrics but no `checkpoints/` folder (a `seads report
//! --copy-runs` copy) is refused, not trained again over its metrics. Every checkpoint names the
//! environment and algorithm that wrote it (`origin.json`), and loading refuses another's.

use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use serde::Serialize;
use serde::de::DeserializeOwned;

use seads_planner::CheckpointId;

use crate::{RunError, TrainConfig};

/// A line of `metrics.jsonl`: what resuming needs to know of it.
pub trait MetricsLine: Serialize + DeserializeOwned {
    /// Epochs completed when it was written.
    fn epoch(&self) -> u64;
    /// Wall-clock seconds of the run when it was written.
    fn wall_s(&self) -> f64;
    /// Environment steps when it was written.
    fn env_steps(&self) -> u64;
    /// Environment steps per wall-clock second of the run until then.
    fn steps_per_s(&self) -> f64;
}

/// The folder of checkpoints in a run directory.
pub const CHECKPOINTS: &str = "checkpoints";
/// The file in [`CHECKPOINTS`] that names the latest complete checkpoint.
pub const LATEST: &str = "latest";
/// The evaluation log of a run directory.
pub const METRICS: &str = "metrics.jsonl";
/// The configuration of a run directory.
pub const CONFIG: &str = "config.toml";
/// In every checkpoint folder: the environment and algorithm that wrote it.
pub const ORIGIN: &str = "origin.json";

// The files of a checkpoint that its learner writes beside its networks (`seads-rl`).
/// The episode buffer (long-term buffer; the recent episodes are its tail).
pub const EPISODES_FILE: &str = "episodes.safetensors";
/// The next epoch's updates, prepared while SAC updated (absent when there are none).
pub const PREPARED_FILE: &str = "prepared.safetensors";
/// Epoch, environment steps, time per phase and the random streams.
pub const PROGRESS_FILE: &str = "progress.json";
/// What the environments carry from one episode to the next (absent when they carry nothing):
/// a JSON list of each training slot's state, then the coverage environment's.
pub const ENVIRONMENT_FILE: &str = "environment.json";

/// Where a checkpoint comes from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
struct Origin {
    env: String,
    algorithm: String,
    /// Whether the checkpoint keeps the state its environments carry from episode to episode
    /// (`environment.json`: the robot's twin); left out where it does not, and in checkpoints
    /// written before it was recorded.
    #[serde(default, skip_serializing_if = "is_false")]
    carried_state: bool,
}

fn is_false(value: &bool) -> bool {
    !*value
}

/// Writes the origin of a checkpoint of a run with `config` into its folder `dir`, after the
/// learner's files (whether it kept its environments' carried state is read from them).
pub fn write_origin(dir: &Path, config: &crate::TrainConfig) -> Result<(), RunError> {
    let origin = Origin {
        env: config.env.clone(),
        algorithm: config.algorithm().to_owned(),
        carried_state: dir.join(ENVIRONMENT_FILE).is_file(),
    };
    let path = dir.join(ORIGIN);
    let text = serde_json::to_string(&origin).map_err(|e| RunError::io(&path, e))?;
    fs::write(&path, text).map_err(|e| RunError::io(&path, e))?;
    // The whole configuration the checkpoint was trained with, which a resume compares with
    // the run's `config.toml`.
    let path = dir.join(CONFIG);
    fs::write(&path, config.to_toml()).map_err(|e| RunError::io(&path, e))
}

/// Refuses to resume from `checkpoint` with a `config` other than the one it was trained with
/// (its `config.toml`), naming the first field that differs; the budget and thread counts may
/// differ. A checkpoint written before it kept its configuration passes.
pub fn check_config(checkpoint: &Path, config: &crate::TrainConfig) -> Result<(), RunError> {
    let path = checkpoint.join(CONFIG);
    let Ok(text) = fs::read_to_string(&path) else {
        return Ok(());
    };
    let trained =
        crate::TrainConfig::from_toml(&text).map_err(|e| RunError::unreadable(&path, e))?;
    match crate::config::config_difference(config, &trained) {
        None => Ok(()),
        Some((field, now, then)) => Err(RunError::Config(format!(
            "config.toml differs from the configuration that checkpoint {} was trained with: \
             `{field}` is {now}, was {then} (only env_steps, with --env-steps, and thread counts may change)",
            checkpoint.display()
        ))),
    }
}

/// Whether the origin of `checkpoint` says that it was written with the state its environments
/// carry (so a checkpoint without that file is damaged, not old).
pub fn keeps_carried_state(checkpoint: &Path) -> bool {
    fs::read_to_string(checkpoint.join(ORIGIN))
        .ok()
        .and_then(|text| serde_json::from_str::<Origin>(&text).ok())
        .is_some_and(|origin| origin.carried_state)
}

/// Refuses a checkpoint written by a run of another environment or algorithm than `config`'s,
/// naming both. A checkpoint without an origin (written before it was recorded) passes.
pub fn check_origin(checkpoint: &Path, config: &crate::TrainConfig) -> Result<(), RunError> {
    let path = checkpoint.join(ORIGIN);
    let Ok(text) = fs::read_to_string(&path) else {
        return Ok(());
    };
    let origin: Origin = serde_json::from_str(&text).map_err(|e| RunError::unreadable(&path, e))?;
    if origin.env != config.env || origin.algorithm != config.algorithm() {
        return Err(RunError::Checkpoint {
            path: checkpoint.display().to_string(),
            reason: format!(
                "it was written by a {} run on {}, not a {} run on {}",
                origin.algorithm,
                origin.env,
                config.algorithm(),
                config.env
            ),
        });
    }
    Ok(())
}

/// Writes `bytes` to `path` atomically and durably: a temporary file in the same folder,
/// fsynced, renamed over `path`, and the folder fsynced.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), RunError> {
    refuse_special(path)?;
    let mut file =
        atomic_write_file::AtomicWriteFile::open(path).map_err(|e| RunError::io(path, e))?;
    file.write_all(bytes).map_err(|e| RunError::io(path, e))?;
    file.commit().map_err(|e| RunError::io(path, e))
}

/// An error where `path` exists and is not a regular file: an atomic write renames a new file over
/// the path, which would replace a device, a FIFO or a symbolic link (not write to its target).
fn refuse_special(path: &Path) -> Result<(), RunError> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if !meta.file_type().is_file() => Err(RunError::io(
            path,
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file: an output replaces only a regular file",
            ),
        )),
        _ => Ok(()),
    }
}

/// A file written as a stream and put in place of `path` only by [`AtomicFile::commit`]
/// (temporary file beside it, fsynced, renamed): dropped without it (an error on the way),
/// `path` stays as it was.
pub struct AtomicFile {
    out: std::io::BufWriter<atomic_write_file::AtomicWriteFile>,
    path: std::path::PathBuf,
}

impl AtomicFile {
    /// Starts the file that will replace `path`.
    pub fn open(path: &Path) -> Result<Self, RunError> {
        refuse_special(path)?;
        let file =
            atomic_write_file::AtomicWriteFile::open(path).map_err(|e| RunError::io(path, e))?;
        Ok(Self {
            out: std::io::BufWriter::new(file),
            path: path.to_path_buf(),
        })
    }

    /// Puts what was written in place of the path.
    pub fn commit(self) -> Result<(), RunError> {
        let path = self.path;
        self.out
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|file| file.commit())
            .map_err(|e| RunError::io(&path, e))
    }
}

impl std::io::Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.out.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// fsyncs a folder, so that the names created or renamed in it survive a power loss.
pub fn sync_dir(dir: &Path) -> Result<(), RunError> {
    fs::File::open(dir)
        .and_then(|d| d.sync_all())
        .map_err(|e| RunError::io(dir, e))
}

/// Makes the folder `tmp`, filled by the caller, the folder `dest`: fsyncs its files and itself,
/// moves an existing `dest` aside, renames, fsyncs the parent, then removes what was aside.
/// A crash leaves either the old `dest` or the new one (and at most a hidden leftover that
/// [`clean_leftovers`] removes).
pub fn commit_dir(tmp: &Path, dest: &Path) -> Result<(), RunError> {
    for entry in fs::read_dir(tmp).map_err(|e| RunError::io(tmp, e))? {
        let path = entry.map_err(|e| RunError::io(tmp, e))?.path();
        fs::File::open(&path)
            .and_then(|f| f.sync_all())
            .map_err(|e| RunError::io(&path, e))?;
    }
    sync_dir(tmp)?;
    let parent = dest.parent().unwrap_or(Path::new("."));
    let aside = hidden_sibling(dest, "old");
    if dest.exists() {
        let _ = fs::remove_dir_all(&aside);
        fs::rename(dest, &aside).map_err(|e| RunError::io(dest, e))?;
    }
    fs::rename(tmp, dest).map_err(|e| RunError::io(dest, e))?;
    sync_dir(parent)?;
    if aside.exists() {
        fs::remove_dir_all(&aside).map_err(|e| RunError::io(&aside, e))?;
    }
    Ok(())
}

/// `.NAME.SUFFIX` beside `path`: where a checkpoint folder is written or set aside.
pub fn hidden_sibling(path: &Path, suffix: &str) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(Default::default, |n| n.to_string_lossy());
    path.with_file_name(format!(".{name}.{suffix}"))
}

/// Removes the hidden leftovers of interrupted writes in `dir` (temporary checkpoint folders,
/// folders set aside, temporary files). Returns their names.
pub fn clean_leftovers(dir: &Path) -> Result<Vec<String>, RunError> {
    let mut removed = Vec::new();
    let entries = match fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(removed),
        Err(e) => return Err(RunError::io(dir, e)),
    };
    for entry in entries {
        let entry = entry.map_err(|e| RunError::io(dir, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !name.starts_with('.') {
            continue;
        }
        let path = entry.path();
        let result = if path.is_dir() {
            fs::remove_dir_all(&path)
        } else {
            fs::remove_file(&path)
        };
        result.map_err(|e| RunError::io(&path, e))?;
        removed.push(name);
    }
    Ok(removed)
}

/// The lock file of a run directory.
pub const RUN_LOCK: &str = "task.lock";

/// The right to write into a run directory, held by one process at a time: an OS file lock on
/// `task.lock`, which the operating system releases when the process dies, so it is never stale.
/// Everything that writes into a run (training, resuming, sweep tasks, evaluations, plots) holds
/// it; readers (status, reports) never take it. The file names the holder for a second writer.
#[derive(Debug)]
pub struct RunLock {
    _file: fs::File,
}

impl RunLock {
    /// Locks the run in `dir` (which must exist) for `holder` (a few words: what holds it),
    /// waiting up to `patience` for another holder to let go; [`RunError::Busy`] if it does not.
    pub fn acquire(dir: &Path, holder: &str, patience: Duration) -> Result<Self, RunError> {
        let path = dir.join(RUN_LOCK);
        let mut file = fs::File::options()
            .create(true)
            .truncate(false)
            .read(true)
            .write(true)
            .open(&path)
            .map_err(|e| RunError::io(&path, e))?;
        let start = Instant::now();
        loop {
            match file.try_lock() {
                Ok(()) => break,
                Err(fs::TryLockError::WouldBlock) if start.elapsed() < patience => {
                    std::thread::sleep(Duration::from_millis(50));
                }
                Err(fs::TryLockError::WouldBlock) => {
                    let named = fs::read_to_string(&path).unwrap_or_default();
                    let named = named.trim();
                    return Err(RunError::Busy {
                        dir: dir.display().to_string(),
                        holder: if named.is_empty() {
                            "another process".into()
                        } else {
                            named.to_owned()
                        },
                    });
                }
                Err(fs::TryLockError::Error(e)) => return Err(RunError::io(&path, e)),
            }
        }
        let line = format!("pid {} ({holder})\n", std::process::id());
        file.set_len(0)
            .and_then(|()| file.write_all(line.as_bytes()))
            .map_err(|e| RunError::io(&path, e))?;
        Ok(Self { _file: file })
    }
}

/// Whether some process holds the lock of the run in `dir` now (it is taken for an instant to
/// look, so a writer waits a little before it gives up).
pub fn run_is_locked(dir: &Path) -> bool {
    let Ok(file) = fs::File::open(dir.join(RUN_LOCK)) else {
        return false;
    };
    matches!(file.try_lock(), Err(fs::TryLockError::WouldBlock))
}

/// The name of the checkpoint of epoch `epoch`.
///
/// ```
/// assert_eq!(seads_run::store::checkpoint_name(1800), "epoch-001800");
/// ```
pub fn checkpoint_name(epoch: u64) -> String {
    format!("epoch-{epoch:06}")
}

/// The epoch of a checkpoint folder name (`epoch-` and digits only), or `None`.
pub fn checkpoint_epoch(name: &str) -> Option<u64> {
    let digits = name.strip_prefix("epoch-")?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

/// Every checkpoint folder of the run in `dir`, oldest first, as (epoch, path). Other entries
/// (leftovers, the pointer) are not checkpoints.
pub fn checkpoints(dir: &Path) -> Result<Vec<(u64, PathBuf)>, RunError> {
    let root = dir.join(CHECKPOINTS);
    let mut out = Vec::new();
    for entry in fs::read_dir(&root).map_err(|e| RunError::io(&root, e))? {
        let entry = entry.map_err(|e| RunError::io(&root, e))?;
        let name = entry.file_name();
        if let Some(epoch) = name.to_str().and_then(checkpoint_epoch)
            && entry.path().is_dir()
        {
            out.push((epoch, entry.path()));
        }
    }
    out.sort();
    Ok(out)
}

/// What `checkpoints/latest` holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Latest {
    /// There is no pointer.
    Absent,
    /// The pointer names this checkpoint folder of the run (which may be missing).
    Names(PathBuf),
    /// The pointer exists but names no checkpoint of this run: why (bytes that are not a
    /// checkpoint name, a path leading elsewhere, a directory in its place).
    Unusable(String),
}

/// Reads `checkpoints/latest`. Only a checkpoint name (`epoch-NNNNNN`) is followed, so the
/// pointer never leads outside the run.
pub fn read_latest(dir: &Path) -> Result<Latest, RunError> {
    let pointer = dir.join(CHECKPOINTS).join(LATEST);
    match fs::read(&pointer) {
        Ok(bytes) => Ok(match std::str::from_utf8(&bytes).map(str::trim) {
            Ok(name) if checkpoint_epoch(name).is_some() => {
                Latest::Names(dir.join(CHECKPOINTS).join(name))
            }
            Ok(name) => Latest::Unusable(format!(
                "{} names {name:?}, which is not a checkpoint of this run",
                pointer.display()
            )),
            Err(_) => Latest::Unusable(format!("{} is not text", pointer.display())),
        }),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Latest::Absent),
        Err(_) if pointer.is_dir() => Ok(Latest::Unusable(format!(
            "{} is a directory, not a pointer",
            pointer.display()
        ))),
        Err(e) => Err(RunError::io(&pointer, e)),
    }
}

/// The checkpoint `checkpoints/latest` names, if the pointer exists and names one of the run's
/// checkpoints; the folder may be missing.
pub fn latest_pointer(dir: &Path) -> Result<Option<PathBuf>, RunError> {
    Ok(match read_latest(dir)? {
        Latest::Names(path) => Some(path),
        Latest::Absent | Latest::Unusable(_) => None,
    })
}

/// The latest checkpoint of the run in `dir`, if any: the one `latest` names, or, if that is
/// missing, the newest checkpoint folder.
pub fn latest_checkpoint(dir: &Path) -> Result<Option<PathBuf>, RunError> {
    if let Some(path) = latest_pointer(dir)?
        && path.is_dir()
    {
        return Ok(Some(path));
    }
    Ok(checkpoints(dir)?.pop().map(|(_, path)| path))
}

/// The lines of `dir/metrics.jsonl`, of any kind (SEADS's [`Metrics`](crate::Metrics), a
/// baseline's [`TaskMetrics`](crate::TaskMetrics)). A last line without its newline is the trace
/// of a crash during the append and is left out; any other line that does not parse is an error.
pub fn read_metrics_as<M: MetricsLine>(dir: &Path) -> Result<Vec<M>, RunError> {
    Ok(read_metrics_text(dir)?.0)
}

/// Environment steps at the last evaluation in `dir/metrics.jsonl` (0 before the first),
/// whatever the run trains: every kind of metrics line has `env_steps`.
pub fn last_env_steps(dir: &Path) -> Result<u64, RunError> {
    #[derive(serde::Deserialize)]
    struct Steps {
        env_steps: u64,
    }
    let (lines, _) = read_json_lines::<Steps>(&dir.join(METRICS))?;
    Ok(lines.last().map_or(0, |l| l.env_steps))
}

/// Which checkpoint the folder `checkpoint` of the run in `dir` is: its epoch (from its name)
/// and the environment steps of training there, from the run's metrics line of that epoch (the
/// presets evaluate wherever they checkpoint), else from the checkpoint's progress file, else
/// unknown.
pub fn checkpoint_id(dir: &Path, checkpoint: &Path) -> Result<CheckpointId, RunError> {
    #[derive(serde::Deserialize)]
    struct Steps {
        #[serde(default)]
        epoch: u64,
        env_steps: u64,
    }
    let epoch = checkpoint
        .file_name()
        .and_then(|n| n.to_str())
        .and_then(checkpoint_epoch)
        .ok_or_else(|| RunError::Checkpoint {
            path: checkpoint.display().to_string(),
            reason: "not a checkpoint folder (epoch-NNNNNN)".into(),
        })?;
    let metrics = dir.join(METRICS);
    let from_metrics = if metrics.is_file() {
        let (lines, _) = read_json_lines::<Steps>(&metrics)?;
        lines.iter().find(|l| l.epoch == epoch).map(|l| l.env_steps)
    } else {
        None
    };
    let from_progress = || {
        let text = fs::read_to_string(checkpoint.join(PROGRESS_FILE)).ok()?;
        let steps = serde_json::from_str::<Steps>(&text).ok()?;
        (steps.epoch == epoch).then_some(steps.env_steps)
    };
    Ok(CheckpointId {
        epoch,
        env_steps: from_metrics.or_else(from_progress),
    })
}

/// Whether `dir` holds a run's metrics but no checkpoints folder: a run copied without its
/// checkpoints (as `seads report --copy-runs` copies), whose data can be reported but which can
/// never be trained further. Every run makes its checkpoints folder before its first metrics
/// line, and nothing removes it, so a crash never leaves a run in this state.
pub fn is_copy_without_checkpoints(dir: &Path) -> bool {
    !dir.join(CHECKPOINTS).is_dir()
        && fs::metadata(dir.join(METRICS)).is_ok_and(|m| m.is_file() && m.len() > 0)
}

/// The whole lines of `dir/metrics.jsonl`, and whether a torn last line was left out.
pub fn read_metrics_text<M: MetricsLine>(dir: &Path) -> Result<(Vec<M>, bool), RunError> {
    let (lines, torn): (Vec<M>, bool) = read_json_lines(&dir.join(METRICS))?;
    // Training appends one line per evaluated epoch, in order: a repeated or an earlier epoch is
    // damage, which neither resume nor a report may take as progress.
    for (i, pair) in lines.windows(2).enumerate() {
        let (before, after) = (pair[0].epoch(), pair[1].epoch());
        if after <= before {
            return Err(RunError::Damaged {
                dir: dir.display().to_string(),
                reason: format!(
                    "{METRICS} line {} has epoch {after} after epoch {before}",
                    i + 2
                ),
            });
        }
    }
    Ok((lines, torn))
}

/// The whole lines of a JSON Lines file, and whether a torn last line (a line without its
/// newline: the trace of a crash during an append) was left out. Any other line that does not
/// parse is an error naming its line number.
pub fn read_json_lines<T: DeserializeOwned>(path: &Path) -> Result<(Vec<T>, bool), RunError> {
    let text = fs::read_to_string(path).map_err(|e| RunError::io(path, e))?;
    let (whole, torn) = match text.rfind('\n') {
        Some(end) => (&text[..=end], !text[end + 1..].trim().is_empty()),
        None => ("", !text.trim().is_empty()),
    };
    let lines = whole
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            serde_json::from_str(l).map_err(|e| RunError::Unreadable {
                path: format!("{}:{}", path.display(), i + 1),
                source: e.into(),
            })
        })
        .collect::<Result<_, _>>()?;
    Ok((lines, torn))
}

/// Appends one line to `dir/metrics.jsonl` and fsyncs it, then its event to the TensorBoard
/// view of the metrics ([`crate::tensorboard`]).
pub fn append_metrics<M: MetricsLine>(dir: &Path, metrics: &M) -> Result<(), RunError> {
    append_json_line(&dir.join(METRICS), metrics)?;
    let path = dir.join(crate::tensorboard::EVENTS);
    let bytes =
        crate::tensorboard::event(metrics, !path.exists()).map_err(|e| RunError::io(&path, e))?;
    let mut file = fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(|e| RunError::io(&path, e))?;
    file.write_all(&bytes)
        .and_then(|()| file.sync_data())
        .map_err(|e| RunError::io(&path, e))
}

/// Writes `dir`'s TensorBoard event file anew with the events of exactly `metrics` (atomically).
pub fn write_events<M: MetricsLine>(dir: &Path, metrics: &[M]) -> Result<(), RunError> {
    let path = dir.join(crate::tensorboard::EVENTS);
    let bytes = crate::tensorboard::events(metrics).map_err(|e| RunError::io(&path, e))?;
    write_atomic(&path, &bytes)
}

/// Appends `value` as one JSON line to `path` (created if missing) and fsyncs it. A torn last
/// line that a crash left is cut off first, so the file only ever holds whole lines after it.
pub fn append_json_line<T: Serialize>(path: &Path, value: &T) -> Result<(), RunError> {
    let mut line = serde_json::to_string(value).map_err(|e| RunError::io(path, e))?;
    line.push('\n');
    let mut file = fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(|e| RunError::io(path, e))?;
    let text = fs::read_to_string(path).map_err(|e| RunError::io(path, e))?;
    if !text.is_empty() && !text.ends_with('\n') {
        let keep = text.rfind('\n').map_or(0, |i| i + 1);
        file.set_len(keep as u64)
            .map_err(|e| RunError::io(path, e))?;
    }
    file.write_all(line.as_bytes())
        .and_then(|()| file.sync_data())
        .map_err(|e| RunError::io(path, e))
}

/// Rewrites `dir/metrics.jsonl` with exactly `metrics`, and the TensorBoard view of them
/// ([`crate::tensorboard`]).
pub fn write_metrics<M: MetricsLine>(dir: &Path, metrics: &[M]) -> Result<(), RunError> {
    let path = dir.join(METRICS);
    let mut text = String::new();
    for m in metrics {
        text += &serde_json::to_string(m).map_err(|e| RunError::io(&path, e))?;
        text.push('\n');
    }
    write_atomic(&path, text.as_bytes())?;
    write_events(dir, metrics)
}

/// Raises the budget of the run in `dir` to `env_steps` environment steps and records it in its
/// config; the run continues with `seads train --resume`. A budget below the current one is a
/// configuration error.
pub fn raise_budget(dir: &Path, env_steps: u64) -> Result<(), RunError> {
    let mut config = load_config(dir)?;
    if env_steps < config.env_steps {
        return Err(RunError::Config(format!(
            "--env-steps {env_steps} is below the run's budget of {}; a budget can only be raised",
            config.env_steps
        )));
    }
    if env_steps > config.env_steps {
        config.env_steps = env_steps;
        // Checked before it is written: a run never holds a config it cannot read.
        config.validate_values()?;
        write_atomic(&dir.join(CONFIG), config.to_toml().as_bytes())?;
    }
    Ok(())
}

/// Reads and validates `dir/config.toml`.
pub fn load_config(dir: &Path) -> Result<TrainConfig, RunError> {
    let path = dir.join(CONFIG);
    let text = fs::read_to_string(&path).map_err(|e| RunError::io(&path, e))?;
    TrainConfig::from_user_toml(&text, None, None)
        .map_err(|e| RunError::Config(format!("{}: {e}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checkpoint_names_round_trip_and_others_are_not_checkpoints() {
        assert_eq!(checkpoint_name(20), "epoch-000020");
        assert_eq!(checkpoint_epoch("epoch-000020"), Some(20));
        assert_eq!(checkpoint_epoch("epoch-1234567"), Some(1_234_567));
        for name in [
            "epoch-",
            "epoch-12a",
            "epoch--1",
            ".epoch-000020.tmp",
            "latest",
            "epoch-+3",
        ] {
            assert_eq!(checkpoint_epoch(name), None, "{name}");
        }
    }

    /// A torn last line is left out when read and cut off by the next append; a bad whole line
    /// is an error naming its number.
    #[test]
    fn json_lines_survive_a_torn_tail() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log.jsonl");
        append_json_line(&path, &1).unwrap();
        append_json_line(&path, &2).unwrap();
        fs::write(&path, "1\n2\n{\"cut").unwrap();
        assert_eq!(read_json_lines::<u32>(&path).unwrap(), (vec![1, 2], true));
        append_json_line(&path, &3).unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "1\n2\n3\n");
        assert_eq!(
            read_json_lines::<u32>(&path).unwrap(),
            (vec![1, 2, 3], false)
        );
        fs::write(&path, "1\nx\n").unwrap();
        let err = read_json_lines::<u32>(&path).unwrap_err().to_string();
        assert!(err.contains("log.jsonl:2"), "{err}");
    }

    #[test]
    fn write_atomic_replaces_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        write_atomic(&path, b"one").unwrap();
        write_atomic(&path, b"two").unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "two");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn commit_dir_replaces_a_folder_and_cleaning_removes_leftovers() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("epoch-000010");
        for content in ["old", "new"] {
            let tmp = hidden_sibling(&dest, "tmp");
            fs::create_dir_all(&tmp).unwrap();
            fs::write(tmp.join("f"), content).unwrap();
            commit_dir(&tmp, &dest).unwrap();
        }
        assert_eq!(fs::read_to_string(dest.join("f")).unwrap(), "new");
        fs::create_dir(hidden_sibling(&dest, "tmp")).unwrap();
        fs::write(dir.path().join(".latest.x1y2"), "").unwrap();
        let mut removed = clean_leftovers(dir.path()).unwrap();
        removed.sort();
        assert_eq!(removed, [".epoch-000010.tmp", ".latest.x1y2"]);
        assert!(dest.is_dir());
    }
}
