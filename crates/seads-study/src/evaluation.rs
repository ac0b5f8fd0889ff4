//! The files an evaluation writes into a run directory: the end-of-training records, named by
//! their protocol and checkpoint ([`seads_planner::EvaluationKind`] names them), and the
//! evaluations over training (the paper's Fig. 3), one line per checkpoint and mode in
//! [`OVER_TRAINING`].

use std::path::Path;

use seads_planner::{
    CheckpointId, DepthResult, EvaluationKind, EvaluationRecord, Protocol, SearchLimits, TaskSet,
};
use serde::{Deserialize, Serialize};

use crate::{Context as _, Result, StudyError};

/// Which checkpoint `agent` is, and `None` where it is the run's latest (whose evaluation takes
/// the plain file names) or `Some(epoch)` for an earlier one.
pub fn checkpoint_of(run: &Path, checkpoint: &Path) -> Result<(CheckpointId, Option<u64>)> {
    let id = seads_rl::checkpoint_id(run, checkpoint)?;
    let latest = seads_rl::latest_checkpoint(run)?;
    let named = (latest.as_deref() != Some(checkpoint)).then_some(id.epoch);
    Ok((id, named))
}

/// Writes an evaluation's record (and its tasks' lines, if any) into the run directory, under
/// the names its protocol and checkpoint give.
pub fn save_evaluation(
    run: &Path,
    record: &EvaluationRecord,
    named_epoch: Option<u64>,
    task_lines: Option<&str>,
) -> Result<()> {
    let protocol = record
        .protocol
        .as_ref()
        .ok_or_else(|| StudyError::failed("an evaluation is saved with its protocol"))?;
    let (kind, depths) = (protocol.kind, &protocol.tasks.depths);
    seads_rl::write_atomic(
        &run.join(kind.results_file(depths, named_epoch)),
        record.to_json().as_bytes(),
    )?;
    if let Some(lines) = task_lines {
        seads_rl::write_atomic(
            &run.join(kind.tasks_file(depths, named_epoch)),
            lines.as_bytes(),
        )?;
    }
    Ok(())
}

/// Reads an evaluation file, `None` if there is none; an unreadable one is an error naming it.
pub fn read_evaluation(path: &Path) -> Result<Option<EvaluationRecord>> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e).doing(|| format!("reading {}", path.display())),
    };
    EvaluationRecord::from_json(&text).map(Some).map_err(|e| {
        StudyError::invalid(format!("{}: not an evaluation file: {e}", path.display()))
    })
}

/// The file, in the run directory.
pub const OVER_TRAINING: &str = "evaluation-over-training.jsonl";

/// One line: a checkpoint evaluated in one mode.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CheckpointEvaluation {
    /// Epoch of the checkpoint.
    pub epoch: u64,
    /// Environment steps of training at the checkpoint.
    pub env_steps: u64,
    /// With re-planning.
    pub replan: bool,
    /// Boards per depth.
    pub boards: usize,
    /// Seconds per search.
    pub timeout_s: f64,
    /// States expanded per search, if bounded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_expanded: Option<usize>,
    /// Per depth.
    pub results: Vec<DepthResult>,
}

impl CheckpointEvaluation {
    /// The protocol the line was evaluated with: test boards, the protocol's seeds, its
    /// depths those of its results.
    pub fn protocol(&self) -> Protocol {
        Protocol {
            kind: EvaluationKind::planning(self.replan),
            tasks: TaskSet {
                depths: self.results.iter().map(|r| r.depth).collect(),
                ..TaskSet::standard(self.boards)
            },
            limits: Some(SearchLimits {
                timeout_s: self.timeout_s,
                max_expanded: self.max_expanded,
            }),
        }
    }
}

/// Reads the lines of `run`'s file (none if it does not exist; a torn last line is ignored).
pub fn read_over_training(run: &Path) -> Result<Vec<CheckpointEvaluation>> {
    let path = run.join(OVER_TRAINING);
    if !path.exists() {
        return Ok(Vec::new());
    }
    Ok(seads_rl::read_json_lines(&path)?.0)
}

/// The protocol of over-training evaluations of `tasks` with `limits`, with or without
/// re-planning.
pub fn over_training_protocol(tasks: &TaskSet, limits: SearchLimits, replan: bool) -> Protocol {
    Protocol {
        kind: EvaluationKind::planning(replan),
        tasks: tasks.clone(),
        limits: Some(limits),
    }
}
