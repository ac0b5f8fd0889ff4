//! The progress bars of evaluations: each function here shows the work of the function of
//! `seads-evaluation` it names (which runs an evaluation and saves it through
//! [`seads_study::evaluation`]; what an evaluation is, is `seads_planner`'s protocol module).

use std::path::Path;

use anyhow::Result;
use seads_evaluation::over_training::{self, Progress, Selection};
use seads_planner::{EvaluationRecord, Protocol, SearchLimits, TaskSet};
use seads_rl::Agent;

/// [`seads_evaluation::evaluation::run_evaluation`] with a progress bar unless `quiet`: evaluates
/// the agent with `protocol` and saves the record and one line per task into the run directory.
pub fn evaluate_with_bar(
    agent: &mut Agent,
    run: &Path,
    protocol: &Protocol,
    quiet: bool,
) -> Result<EvaluationRecord> {
    let bar = crate::progress_bar(
        protocol.tasks.len() as u64,
        quiet,
        "{wide_bar} {pos}/{len} {msg}",
    );
    // A resumed evaluation starts from the tasks its stopped run finished.
    let before = seads_evaluation::evaluation::finished_before(agent, run, protocol)
        .map_err(crate::eval_error)?;
    if before.finished > 0 {
        eprintln!(
            "seads: {}: resuming an evaluation: {} of {} tasks finished before",
            run.display(),
            before.finished,
            protocol.tasks.len()
        );
    }
    crate::plan::warn_damaged_journal(run, before.damaged);
    bar.set_position(before.finished as u64);
    let record = seads_evaluation::evaluation::run_evaluation(agent, run, protocol, |task| {
        bar.set_message(format!("depth {}", task.depth));
        bar.inc(1);
    })
    .map_err(crate::eval_error)?;
    bar.finish_and_clear();
    Ok(record)
}

/// Evaluates the selected checkpoints of `run` over training
/// ([`seads_evaluation::over_training::evaluate_checkpoints`]), with a progress bar unless `quiet`;
/// returns the number of lines appended.
pub fn evaluate_checkpoints_with_bar(
    run: &Path,
    selection: Selection,
    tasks: &TaskSet,
    limits: SearchLimits,
    quiet: bool,
    device: seads_rl::ComputeDevice,
) -> Result<usize> {
    let config = seads_rl::load_config(run)?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    let template = "{elapsed_precise} [{bar:30}] {pos}/{len} tasks {prefix} {msg}";
    let bar = crate::progress_bar(0, quiet, template);
    let added =
        over_training::evaluate_checkpoints(run, selection, tasks, limits, device, |p| match p {
            Progress::Planned { tasks } => bar.set_length(tasks as u64),
            Progress::Checkpoint { epoch } => bar.set_prefix(format!("epoch {epoch}")),
            Progress::Task { depth } => {
                bar.set_message(format!("depth {depth}"));
                bar.inc(1);
            }
        })
        .map_err(crate::eval_error)?;
    bar.finish_and_clear();
    Ok(added)
}
