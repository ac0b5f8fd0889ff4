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
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::{EpochStats, RlError, Timings, TrainConfig, Trainer};

/// Files of a checkpoint that only resuming needs; dropped from older checkpoints.
const RESUME_ONLY: &[&str] = &[
    "sac_critic.safetensors",
    "sac_target.safetensors",
    "sac_actor_adam.safetensors",
    "sac_critic_adam.safetensors",
    "forward_model_adam.safetensors",
    "discriminator_adam.safetensors",
    "episodes.safetensors",
    crate::trainer::PREPARED_FILE,
];

/// One line of `metrics.jsonl`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Metrics {
    /// Epochs completed.
    pub epoch: u64,
    /// Environment steps so far.
    pub env_steps: u64,
    /// Mean number of distinct game moves made by the skills (SPEC §4.5).
    pub skill_coverage: f64,
    /// Wall-clock seconds since the run started (across resumes).
    pub wall_s: f64,
    /// Mean final reward of the last SAC batch.
    pub mean_reward: f32,
    /// Fraction of the last epoch's new episodes that changed the board.
    pub changed: f32,
    /// Last skill-model loss.
    pub skill_model_loss: f32,
    /// Last critic loss.
    pub critic_loss: f32,
    /// Last actor loss.
    pub actor_loss: f32,
    /// Environment steps per wall-clock second since the start of the run.
    pub steps_per_s: f64,
    /// Seconds per phase since the start of the run.
    pub timings: Timings,
}

/// What a call to [`Run::step`] did.
#[derive(Debug, Clone)]
pub struct RunEvent {
    /// The epoch's statistics.
    pub stats: EpochStats,
    /// The evaluation written to `metrics.jsonl`, if one was due.
    pub metrics: Option<Metrics>,
    /// The checkpoint written, if one was due.
    pub checkpoint: Option<PathBuf>,
}

/// A training run writing into a directory.
pub struct Run {
    dir: PathBuf,
    trainer: Trainer,
    started: Instant,
    wall_before: f64,
}

fn atomic_write(path: &Path, text: &str) -> Result<(), RlError> {
    let tmp = path.with_extension("tmp");
    fs::write(&tmp, text).map_err(|e| RlError::io(&tmp, e))?;
    fs::rename(&tmp, path).map_err(|e| RlError::io(path, e))
}

impl Run {
    /// Starts a run in `dir` (created; it must not already hold a run).
    pub fn create(dir: &Path, config: TrainConfig) -> Result<Self, RlError> {
        Self::check_free(dir)?;
        Self::with_trainer(dir, Trainer::new(config)?)
    }

    fn check_free(dir: &Path) -> Result<(), RlError> {
        if dir.join("config.toml").exists() {
            return Err(RlError::Config(format!(
                "{} already holds a run; resume it with --resume or choose another directory",
                dir.display()
            )));
        }
        Ok(())
    }

    /// Starts a run in `dir` with a trainer built elsewhere (e.g. on the robot's environment).
    pub fn with_trainer(dir: &Path, trainer: Trainer) -> Result<Self, RlError> {
        Self::check_free(dir)?;
        fs::create_dir_all(dir.join("checkpoints")).map_err(|e| RlError::io(dir, e))?;
        atomic_write(&dir.join("config.toml"), &trainer.config().to_toml())?;
        fs::write(dir.join("metrics.jsonl"), "").map_err(|e| RlError::io(dir, e))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            trainer,
            started: Instant::now(),
            wall_before: 0.0,
        })
    }

    /// Continues the run in `dir` from its latest checkpoint (from scratch if it has none).
    pub fn resume(dir: &Path) -> Result<Self, RlError> {
        Self::resume_with(dir, Trainer::new)
    }

    /// Continues the run in `dir`, building its trainer with `build` from the saved config.
    pub fn resume_with(
        dir: &Path,
        build: impl FnOnce(TrainConfig) -> Result<Trainer, RlError>,
    ) -> Result<Self, RlError> {
        let config = load_config(dir)?;
        let mut trainer = build(config)?;
        let mut wall_before = 0.0;
        let mut kept = Vec::new();
        if let Some(checkpoint) = latest_checkpoint(dir)? {
            trainer.load(&checkpoint)?;
            // Drop evaluations logged after the checkpoint: they will be redone.
            let metrics = read_metrics(dir)?;
            kept = metrics
                .into_iter()
                .filter(|m| m.epoch <= trainer.epoch())
                .collect();
            wall_before = kept.last().map_or(0.0, |m| m.wall_s);
        }
        let text: String = kept
            .iter()
            .map(|m| serde_json::to_string(m).expect("metrics serialise") + "\n")
            .collect();
        atomic_write(&dir.join("metrics.jsonl"), &text)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            trainer,
            started: Instant::now(),
            wall_before,
        })
    }

    /// The trainer.
    pub fn trainer(&self) -> &Trainer {
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

    /// Evaluates skill coverage and appends a metrics line.
    pub fn evaluate(&mut self, stats: &EpochStats) -> Result<Metrics, RlError> {
        let skill_coverage = self.trainer.skill_coverage()?;
        let wall_s = self.wall_s();
        let metrics = Metrics {
            epoch: self.trainer.epoch(),
            env_steps: self.trainer.env_steps(),
            skill_coverage,
            wall_s,
            mean_reward: stats.mean_reward,
            changed: stats.changed,
            skill_model_loss: stats.skill_model_loss,
            critic_loss: stats.sac.critic,
            actor_loss: stats.sac.actor,
            steps_per_s: self.trainer.env_steps() as f64 / wall_s.max(1e-9),
            timings: self.trainer.timings(),
        };
        let path = self.dir.join("metrics.jsonl");
        let mut file = fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| RlError::io(&path, e))?;
        writeln!(
            file,
            "{}",
            serde_json::to_string(&metrics).expect("metrics serialise")
        )
        .map_err(|e| RlError::io(&path, e))?;
        Ok(metrics)
    }

    /// Writes a complete checkpoint atomically (a temporary folder renamed into place, then the
    /// `latest` pointer), then strips the resume-only files from the previous one.
    pub fn checkpoint(&self) -> Result<PathBuf, RlError> {
        let root = self.dir.join("checkpoints");
        let name = format!("epoch-{:06}", self.trainer.epoch());
        let tmp = root.join(format!(".{name}.tmp"));
        let _ = fs::remove_dir_all(&tmp);
        fs::create_dir_all(&tmp).map_err(|e| RlError::io(&tmp, e))?;
        self.trainer.save(&tmp)?;
        let dest = root.join(&name);
        let _ = fs::remove_dir_all(&dest);
        fs::rename(&tmp, &dest).map_err(|e| RlError::io(&dest, e))?;
        let previous = fs::read_to_string(root.join("latest")).ok();
        atomic_write(&root.join("latest"), &name)?;
        if let Some(previous) = previous.map(|p| p.trim().to_owned()).filter(|p| *p != name) {
            for file in RESUME_ONLY {
                let _ = fs::remove_file(root.join(&previous).join(file));
            }
        }
        Ok(dest)
    }

    /// One epoch, plus the evaluation and checkpoint that are due after it (both also before
    /// the first epoch's updates, i.e. at epoch 1, and when the budget is spent).
    pub fn step(&mut self) -> Result<RunEvent, RlError> {
        let first = self.trainer.epoch() == 0;
        let stats = self.trainer.run_epoch()?;
        let epoch = self.trainer.epoch();
        let done = self.trainer.finished();
        let config = self.trainer.config();
        let eval_due = first || epoch.is_multiple_of(config.eval_every) || done;
        let checkpoint_due = epoch.is_multiple_of(config.checkpoint_every) || done;
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

/// Reads and validates `dir/config.toml`.
pub fn load_config(dir: &Path) -> Result<TrainConfig, RlError> {
    let path = dir.join("config.toml");
    let text = fs::read_to_string(&path).map_err(|e| RlError::io(&path, e))?;
    TrainConfig::from_toml(&text).map_err(|e| RlError::Config(format!("{}: {e}", path.display())))
}

/// The latest complete checkpoint of the run in `dir`, if any.
pub fn latest_checkpoint(dir: &Path) -> Result<Option<PathBuf>, RlError> {
    let pointer = dir.join("checkpoints").join("latest");
    match fs::read_to_string(&pointer) {
        Ok(name) => {
            let path = dir.join("checkpoints").join(name.trim());
            if path.is_dir() {
                Ok(Some(path))
            } else {
                Err(RlError::Checkpoint {
                    path: path.display().to_string(),
                    reason: "the latest checkpoint is missing".into(),
                })
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(RlError::io(&pointer, e)),
    }
}

/// Every checkpoint of the run in `dir`, oldest first, as (epoch, path).
pub fn checkpoints(dir: &Path) -> Result<Vec<(u64, PathBuf)>, RlError> {
    let root = dir.join("checkpoints");
    let mut out: Vec<(u64, PathBuf)> = fs::read_dir(&root)
        .map_err(|e| RlError::io(&root, e))?
        .filter_map(|entry| {
            let entry = entry.ok()?;
            let epoch = entry
                .file_name()
                .to_str()?
                .strip_prefix("epoch-")?
                .parse()
                .ok()?;
            Some((epoch, entry.path()))
        })
        .collect();
    out.sort();
    Ok(out)
}

/// The lines of `dir/metrics.jsonl`.
pub fn read_metrics(dir: &Path) -> Result<Vec<Metrics>, RlError> {
    let path = dir.join("metrics.jsonl");
    let text = fs::read_to_string(&path).map_err(|e| RlError::io(&path, e))?;
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .enumerate()
        .map(|(i, l)| {
            serde_json::from_str(l).map_err(|e| RlError::Checkpoint {
                path: format!("{}:{}", path.display(), i + 1),
                reason: e.to_string(),
            })
        })
        .collect()
}
