//! The files an evaluation writes into a run directory: the end-of-training records, named by
//! their protocol and checkpoint ([`seads_planner::EvaluationKind`] names them), and the
//! evaluations over training (the paper's Fig. 3), one line per checkpoint and mode in
//! [`OVER_TRAINING`]; and the [`journal`] of an evaluation in progress. Running an evaluation is
//! `seads-evaluation`'s.

pub mod journal;

use std::path::Path;

use seads_games::BoardGame;
use seads_planner::{
    CheckpointId, DepthResult, EvaluationKind, EvaluationRecord, Evaluator, Protocol, SearchLimits,
    TaskRecord, TaskSet,
};
use serde::{Deserialize, Serialize};

use crate::{Context as _, Result, StudyError};

/// Which checkpoint `agent` is, and `None` where it is the run's latest (whose evaluation takes
/// the plain file names) or `Some(epoch)` for an earlier one.
pub fn checkpoint_of(run: &Path, checkpoint: &Path) -> Result<(CheckpointId, Option<u64>)> {
    let id = seads_run::store::checkpoint_id(run, checkpoint)?;
    let latest = seads_run::store::latest_checkpoint(run)?;
    let named = (latest.as_deref() != Some(checkpoint)).then_some(id.epoch);
    Ok((id, named))
}

/// Writes an evaluation's record (and its tasks' lines, if any) into the run directory, under
/// the names its protocol and checkpoint give. An evaluation of another protocol found under
/// these names (written by a binary that named files by fewer parts of the protocol) is first
/// moved to the names its own protocol gives, never replaced.
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
    keep_another_protocols(run, protocol, named_epoch)?;
    seads_run::store::write_atomic(
        &run.join(protocol.results_file(named_epoch)),
        record.to_json().as_bytes(),
    )?;
    if let Some(lines) = task_lines {
        seads_run::store::write_atomic(
            &run.join(protocol.tasks_file(named_epoch)),
            lines.as_bytes(),
        )?;
    }
    Ok(())
}

/// Moves an evaluation of another protocol than `protocol` out of the way of `protocol`'s files
/// (of the checkpoint `named_epoch`), to the names its own protocol gives; one whose protocol is
/// not recorded goes to `…-protocol-unknown.json`. Where those names are taken too, nothing is
/// moved and the evaluation is refused, so that no record is lost.
pub fn keep_another_protocols(
    run: &Path,
    protocol: &Protocol,
    named_epoch: Option<u64>,
) -> Result<()> {
    let results = run.join(protocol.results_file(named_epoch));
    let Ok(Some(found)) = read_evaluation(&results) else {
        // Nothing there, or not an evaluation: nothing to keep.
        return Ok(());
    };
    if found.protocol.as_ref() == Some(protocol) {
        return Ok(());
    }
    let (to_results, to_tasks) = match &found.protocol {
        Some(other) => (
            other.results_file(named_epoch),
            other.tasks_file(named_epoch),
        ),
        None => {
            let stem = protocol.stem(named_epoch);
            (
                format!("{stem}-protocol-unknown.json"),
                format!("{stem}-protocol-unknown-tasks.jsonl"),
            )
        }
    };
    let moves = [
        (results, run.join(to_results)),
        (
            run.join(protocol.tasks_file(named_epoch)),
            run.join(to_tasks),
        ),
    ];
    for (_, to) in &moves {
        if to.exists() {
            return Err(StudyError::invalid(format!(
                "{} holds an evaluation of another protocol, and {} is taken too: move one of \
                 them away first",
                moves[0].0.display(),
                to.display()
            )));
        }
    }
    for (from, to) in moves {
        if from.exists() {
            std::fs::rename(&from, &to)
                .doing(|| format!("moving {} to {}", from.display(), to.display()))?;
        }
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
        StudyError::invalid(format!(
            "{}: not an evaluation file of today's layout (`seads migrate` rewrites older ones): \
             {e}",
            path.display()
        ))
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
    /// Each search's limits and plan choice, as fields of the line itself (`timeout_s`,
    /// `max_expanded`, `plan`, `search`, `memory_limit_mib`; lines from before a field read as
    /// [`SearchLimits`] reads them: no bound, the first plan found, breadth-first).
    #[serde(flatten)]
    pub limits: SearchLimits,
    /// The binary that evaluated (lines written before evaluations recorded it: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evaluated_by: Option<Evaluator>,
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
            limits: Some(self.limits),
            action_noise: None,
            model: seads_planner::PlanModel::Own,
        }
    }
}

/// Reads the lines of `run`'s file (none if it does not exist; a torn last line is ignored).
pub fn read_over_training(run: &Path) -> Result<Vec<CheckpointEvaluation>> {
    let path = run.join(OVER_TRAINING);
    if !path.exists() {
        return Ok(Vec::new());
    }
    Ok(seads_run::store::read_json_lines(&path)?.0)
}

/// The evaluations over training of the run in `run` made on `tasks` with `limits` (the file may
/// hold evaluations with other depths, boards or limits).
pub fn read_over_training_of(
    run: &Path,
    tasks: &TaskSet,
    limits: SearchLimits,
) -> Result<Vec<CheckpointEvaluation>> {
    Ok(read_over_training(run)?
        .into_iter()
        .filter(|l| l.protocol() == over_training_protocol(tasks, limits, l.replan))
        .collect())
}

/// One line per evaluation under a header: epoch, steps, mode and success per depth.
pub fn over_training_table(lines: &[CheckpointEvaluation]) -> String {
    let mut out = String::from("     epoch   env steps  mode            success per depth");
    for l in lines {
        let rates: Vec<String> = l
            .results
            .iter()
            .map(|r| format!("{:.0}%", 100.0 * r.success_rate()))
            .collect();
        out += &format!(
            "\n{:>10}  {:>10}  {:<14}  {}",
            l.epoch,
            l.env_steps,
            if l.replan { "re-planning" } else { "plan once" },
            rates.join(" ")
        );
    }
    out
}

/// The protocol of over-training evaluations of `tasks` with `limits`, with or without
/// re-planning.
pub fn over_training_protocol(tasks: &TaskSet, limits: SearchLimits, replan: bool) -> Protocol {
    Protocol {
        kind: EvaluationKind::planning(replan),
        tasks: tasks.clone(),
        limits: Some(limits),
        action_noise: None,
        model: seads_planner::PlanModel::Own,
    }
}

/// One line of `evaluation-*-tasks.jsonl`: a task, how it ended, and every skill that left
/// another board than the forward model predicted (boards as `seads solve --board` takes them).
pub fn task_line(game: &dyn BoardGame, task: &TaskRecord<'_>) -> serde_json::Value {
    let o = task.outcome;
    let deviations: Vec<serde_json::Value> = o
        .deviations
        .iter()
        .map(|d| {
            serde_json::json!({
                "step": d.step,
                "skill": d.skill,
                "before": game.format(d.before),
                "predicted": game.format(d.predicted),
                "reached": game.format(d.reached),
            })
        })
        .collect();
    serde_json::json!({
        "depth": task.depth,
        "seed": task.seed,
        "board": game.format(task.board),
        "solved": o.solved,
        "plan_found": o.plan_found,
        "plans": o.plans,
        "first_plan": o.first_plan,
        "executed": o.executed,
        "skill_steps": o.skill_steps,
        "manipulator_steps": o.manipulator_steps,
        "timed_out": o.timed_out,
        "failure": o.failure,
        "deviations": deviations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use seads_planner::PlanChoice;

    /// A line of `evaluation-over-training.jsonl` reads and writes back to the letter, its
    /// limits as the line's own fields; a line written before a field existed reads as the
    /// defaults say (no bound, the first plan found, breadth-first). The texts are written out
    /// by hand, as the files hold them.
    #[test]
    fn a_line_keeps_its_limits_as_its_own_fields() {
        let results = r#""results":[{"depth":1,"tasks":2,"solved":1,"plan_found":2,"planning_s":[0.5,1.0],"timeouts":0,"solution_steps":[7],"skill_steps":[3,4]}]"#;
        let full = format!(
            r#"{{"epoch":500,"env_steps":20000,"replan":true,"boards":20,"timeout_s":10.0,"max_expanded":4194304,"plan":"most-likely","search":"both-ends","memory_limit_mib":16384,"evaluated_by":{{"seads":"0.1.0","commit":"a634bb8","dirty":false}},{results}}}"#
        );
        let line: CheckpointEvaluation = serde_json::from_str(&full).unwrap();
        assert_eq!(serde_json::to_string(&line).unwrap(), full);
        assert_eq!(line.limits.timeout_s, Some(10.0));
        assert_eq!(line.limits.max_expanded, Some(4_194_304));
        assert_eq!(line.limits.plan, PlanChoice::MostLikely);
        assert_eq!(line.limits.search, seads_planner::Search::BothEnds);
        assert_eq!(line.limits.memory_limit_mib, Some(16384));
        // The protocol's limits are the line's.
        assert_eq!(line.protocol().limits, Some(line.limits));

        let old =
            format!(r#"{{"epoch":100,"env_steps":4218,"replan":false,"boards":20,{results}}}"#);
        let line: CheckpointEvaluation = serde_json::from_str(&old).unwrap();
        assert_eq!(
            line.limits,
            SearchLimits {
                timeout_s: None,
                max_expanded: None,
                plan: PlanChoice::FirstFound,
                search: seads_planner::Search::Breadth,
                memory_limit_mib: None,
            }
        );
        assert_eq!(
            serde_json::to_string(&line).unwrap(),
            format!(
                r#"{{"epoch":100,"env_steps":4218,"replan":false,"boards":20,"plan":"first-found",{results}}}"#
            )
        );
    }
}
