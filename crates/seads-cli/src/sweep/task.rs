//! `seads sweep task`: one run of a sweep, start to finish — claim it, train it (resuming what
//! a killed or re-queued task left), evaluate it, record the outcome. A Slurm array task and a
//! worker of `seads sweep run` both come here, so the two behave alike.

use std::path::Path;
use std::time::Duration;

use anyhow::{Context, Result};
use seads_rl::{Algorithm, ComputeDevice, Hac, Run, TaskSac, Trainer};

use seads_rl::InWords;
use seads_skillmodel::SkillModelKind;

use super::index::Sweep;
use crate::plan::evaluate_checkpoints;
use crate::plan::{load_agent, run_evaluation};
use seads_planner::{EvaluationKind, Protocol, TaskSet};
use seads_study::evaluation::run_policy_evaluation;
use seads_study::over_training::Selection;
use seads_study::sweep::{Task, Work};

/// Runs task `index` of the sweep in `dir` with `cores` cores and its networks on `device`, waiting up to `patience` for
/// another task that holds the run. A run already done is left as it is. Errors are recorded in
/// the run's `task.json` before they are returned.
pub fn run_task(
    dir: &Path,
    index: usize,
    cores: usize,
    device: ComputeDevice,
    patience: Duration,
) -> Result<()> {
    let task = Task::claim(dir, index, patience).map_err(crate::study_error)?;
    let run = task.run.display();
    if task.replanned {
        outln!("{run}: was deleted; planned again from the manifest");
    }
    match &task.work {
        Work::Nothing => {
            outln!("{run}: already done");
            return Ok(());
        }
        Work::Redo(name) => outln!("{run}: {name} is gone; finishing the run again"),
        Work::Run => {}
    }
    task.start()?;
    let result = train_and_evaluate(&task.sweep, &task.run, cores, device);
    task.finish(&result)?;
    result
}

fn train_and_evaluate(
    sweep: &Sweep,
    run: &Path,
    cores: usize,
    device: ComputeDevice,
) -> Result<()> {
    let config =
        seads_rl::load_config(run).with_context(|| format!("loading {}", run.display()))?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    match config.algorithm {
        Algorithm::Sac => {
            return train_and_evaluate_baseline::<TaskSac>(sweep, run, cores, device);
        }
        Algorithm::Hac => return train_and_evaluate_baseline::<Hac>(sweep, run, cores, device),
        Algorithm::Seads => {}
    }
    let mut training = crate::train::resume(
        run,
        Run::resume_with(run, |mut c| {
            c.use_cores(cores);
            c.device = device;
            Trainer::new(c)
        }),
    )?;
    if !training.finished() {
        outln!(
            "{}: training from epoch {} with {} libtorch thread(s) per training thread",
            run.display(),
            training.trainer().epoch(),
            training.trainer().config().threads
        );
        crate::train::drive(&mut training, true)?;
    }
    drop(training);
    let plan = &sweep.evaluation;
    if config.skill_model.kind == SkillModelKind::Vic {
        outln!(
            "{}: a VIC agent cannot plan; no task evaluation",
            run.display()
        );
        return Ok(());
    }
    // The planner's parts and bookkeeping run on the task's rayon pool (`cores` threads), each
    // part's network on one libtorch thread.
    seads_rl::set_threads(1);
    if plan.every > 0 {
        let added = evaluate_checkpoints(
            run,
            Selection::Every(plan.every),
            &TaskSet::standard(plan.boards),
            plan.limits(),
            true,
            device,
        )?;
        outln!(
            "{}: {added} checkpoint evaluation(s) over training",
            run.display()
        );
    }
    if plan.last {
        let mut agent = load_agent(run, None, device)?;
        for replan in [true, false] {
            let protocol = Protocol {
                kind: EvaluationKind::planning(replan),
                tasks: TaskSet::standard(plan.boards),
                limits: Some(plan.limits()),
                action_noise: None,
            };
            let results = run_evaluation(&mut agent, run, &protocol, true)?.results;
            let solved: usize = results.iter().map(|r| r.solved).sum();
            let tasks: usize = results.iter().map(|r| r.tasks).sum();
            outln!(
                "{}: {} {solved}/{tasks} solved",
                run.display(),
                if replan {
                    "with re-planning"
                } else {
                    "plan once"
                }
            );
        }
    }
    Ok(())
}

/// A baseline run: training on all of the task's cores (one training thread), then task success
/// of the final policy on the study's boards per depth (`evaluation-policy.json`).
fn train_and_evaluate_baseline<L: InWords>(
    sweep: &Sweep,
    run: &Path,
    cores: usize,
    device: ComputeDevice,
) -> Result<()> {
    let mut training = crate::train::resume(
        run,
        Run::resume_with(run, |mut c| {
            c.threads = cores.max(1);
            c.sac_threads_alone = 0;
            c.device = device;
            L::build(c)
        }),
    )?;
    let config = training.trainer().config().clone();
    if !training.finished() {
        outln!(
            "{}: training the {} baseline from epoch {} with {} libtorch thread(s)",
            run.display(),
            config.algorithm.name().to_uppercase(),
            training.trainer().epoch(),
            cores.max(1)
        );
        crate::train::drive(&mut training, true)?;
    }
    drop(training);
    if sweep.evaluation.last {
        // The final checkpoint holds the trained policy.
        let checkpoint = seads_rl::store::latest_checkpoint(run)?
            .with_context(|| format!("{} has no checkpoint", run.display()))?;
        let results = run_policy_evaluation(
            &config,
            run,
            &checkpoint,
            TaskSet::standard(sweep.evaluation.boards),
        )?
        .results;
        let solved: usize = results.iter().map(|r| r.solved).sum();
        let tasks: usize = results.iter().map(|r| r.tasks).sum();
        outln!("{}: policy {solved}/{tasks} solved", run.display());
    }
    Ok(())
}
