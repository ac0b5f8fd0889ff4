//! Task success over training (the paper's Fig. 3): [`evaluate_checkpoints`] (`seads evaluate
//! --checkpoints all|N`) evaluates kept checkpoints with and without re-planning and appends one line per checkpoint
//! and mode to `evaluation-over-training.jsonl`, keyed by environment steps. Checkpoints already
//! in the file are skipped, so the command resumes where it stopped.

use std::path::Path;

use seads_planner::{Protocol, SearchLimits, TaskSet};
use seads_rl::{Agent, ComputeDevice};

use seads_study::evaluation::{
    CheckpointEvaluation, OVER_TRAINING, over_training_protocol, read_over_training,
};

use crate::evaluation::evaluate_agent;
use seads_study::{Context as _, StudyError};

use crate::Result;

/// What [`evaluate_checkpoints`] is doing, for a progress display.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// This many tasks are to be evaluated in all.
    Planned {
        /// Tasks.
        tasks: usize,
    },
    /// The evaluations of this checkpoint begin.
    Checkpoint {
        /// Its epoch.
        epoch: u64,
    },
    /// A task of this depth ended.
    Task {
        /// Its depth.
        depth: usize,
    },
}

/// Which checkpoints: `all`, every N-th kept one (the last always), or the listed epochs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Selection {
    /// Every kept checkpoint.
    All,
    /// Every N-th, counted from the first, and the last.
    Every(usize),
    /// The checkpoints of these epochs (each must be kept).
    Epochs(Vec<u64>),
}

impl Selection {
    /// The chosen checkpoints among the `kept` ones (epoch, folder), in their order; for listed
    /// epochs, the error names those that were not kept.
    pub fn choose<T: Clone>(&self, kept: &[(u64, T)]) -> Result<Vec<(u64, T)>, String> {
        Ok(match self {
            Selection::All => kept.to_vec(),
            Selection::Every(n) => kept
                .iter()
                .enumerate()
                .filter(|(i, _)| i % n == 0 || *i + 1 == kept.len())
                .map(|(_, c)| c.clone())
                .collect(),
            Selection::Epochs(epochs) => {
                let missing: Vec<String> = epochs
                    .iter()
                    .filter(|e| !kept.iter().any(|(k, _)| k == *e))
                    .map(u64::to_string)
                    .collect();
                if !missing.is_empty() {
                    return Err(missing.join(", "));
                }
                kept.iter()
                    .filter(|(k, _)| epochs.contains(k))
                    .cloned()
                    .collect()
            }
        })
    }
}

impl std::str::FromStr for Selection {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "--checkpoints takes `all`, a number N ≥ 1 (every N-th), or epochs separated by \
                 commas (`100,300,1000`; one epoch: `500,`), got {text:?}"
            )
        };
        if text == "all" {
            return Ok(Self::All);
        }
        if text.contains(',') {
            // `500,` lists the one epoch 500 (a bare number is every N-th).
            // Epochs are listed, not ranged: few of a range's epochs have a checkpoint.
            let listed = text.trim_end().trim_end_matches(',');
            if listed.contains('-') {
                return Err(bad());
            }
            let mut epochs = listed
                .split(',')
                .map(|e| e.trim().parse::<u64>())
                .collect::<Result<Vec<u64>, _>>()
                .map_err(|_| bad())?;
            epochs.sort_unstable();
            epochs.dedup();
            return Ok(Self::Epochs(epochs));
        }
        match text.parse::<usize>() {
            Ok(n) if n > 0 => Ok(Self::Every(n)),
            _ => Err(bad()),
        }
    }
}

/// Evaluates the selected checkpoints of `run` on `device` in both modes on `tasks` (test
/// boards, the protocol's seeds), unless the file holds them evaluated with the same protocol already.
/// Returns the number of lines appended. `progress` hears of the work as it goes. A run
/// without the chosen checkpoints is [`StudyError::Invalid`].
pub fn evaluate_checkpoints(
    run: &Path,
    selection: Selection,
    tasks: &TaskSet,
    limits: SearchLimits,
    device: ComputeDevice,
    mut progress: impl FnMut(Progress),
) -> Result<usize> {
    let mut config = seads_run::load_config(run).doing(|| format!("reading {}", run.display()))?;
    config.device = device;
    let kept = seads_run::store::checkpoints(run).doing(|| format!("reading {}", run.display()))?;
    if kept.is_empty() {
        return Err(StudyError::invalid(format!(
            "{} has no checkpoint to evaluate",
            run.display()
        ))
        .into());
    }
    let chosen = selection.choose(&kept).map_err(|e| {
        StudyError::invalid(format!(
            "{} keeps no checkpoint of epoch(s) {e}",
            run.display()
        ))
    })?;
    let done: Vec<(u64, Protocol)> = read_over_training(run)?
        .iter()
        .map(|l| (l.epoch, l.protocol()))
        .collect();
    let todo: Vec<(u64, &Path, bool)> = chosen
        .iter()
        .flat_map(|(epoch, dir)| [true, false].map(|replan| (*epoch, dir.as_path(), replan)))
        .filter(|(epoch, _, replan)| {
            !done.contains(&(*epoch, over_training_protocol(tasks, limits, *replan)))
        })
        .collect();
    progress(Progress::Planned {
        tasks: tasks.len() * todo.len(),
    });
    let path = run.join(OVER_TRAINING);
    let mut loaded: Option<(u64, Agent)> = None;
    for (epoch, dir, replan) in &todo {
        if loaded.as_ref().is_none_or(|(e, _)| e != epoch) {
            loaded = Some((*epoch, Agent::load_checkpoint(config.clone(), dir)?));
        }
        let agent = &mut loaded.as_mut().expect("just loaded").1;
        progress(Progress::Checkpoint { epoch: *epoch });
        let results = evaluate_agent(
            agent,
            &over_training_protocol(tasks, limits, *replan),
            |t| {
                progress(Progress::Task { depth: t.depth });
            },
        )?;
        let env_steps = seads_run::store::checkpoint_id(run, dir)?
            .env_steps
            .ok_or_else(|| {
                StudyError::failed(format!(
                    "{}: no metrics line at epoch {epoch} and no progress file to tell its \
                 environment steps",
                    run.display()
                ))
            })?;
        let line = CheckpointEvaluation {
            epoch: *epoch,
            env_steps,
            replan: *replan,
            boards: tasks.boards,
            limits,
            evaluated_by: seads_study::provenance::this_binary().cloned(),
            results,
        };
        seads_run::store::append_json_line(&path, &line)?;
    }
    Ok(todo.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checkpoints_are_chosen_all_every_nth_with_the_last_or_by_epoch() {
        let kept: Vec<(u64, ())> = [100, 200, 300, 400, 500].map(|e| (e, ())).to_vec();
        let epochs = |s: &Selection| -> Vec<u64> {
            s.choose(&kept)
                .unwrap()
                .into_iter()
                .map(|(e, _)| e)
                .collect()
        };
        assert_eq!(epochs(&"all".parse().unwrap()), [100, 200, 300, 400, 500]);
        assert_eq!(epochs(&"2".parse().unwrap()), [100, 300, 500]);
        assert_eq!(epochs(&"3".parse().unwrap()), [100, 400, 500]);
        assert_eq!(epochs(&"500, 200".parse().unwrap()), [200, 500]);
        assert_eq!(epochs(&"300,".parse().unwrap()), [300]);
        let missing = "100,250,600".parse::<Selection>().unwrap().choose(&kept);
        assert_eq!(missing.unwrap_err(), "250, 600");
        for bad in ["0", "x", "1,x", "-1", ",", "1,,2", "1-3,"] {
            assert!(bad.parse::<Selection>().is_err(), "{bad}");
        }
    }
}
