//! `seads sweep task`: one run of a sweep, start to finish — claim it, train it (resuming what
//! a killed or re-queued task left), evaluate it, record the outcome. A Slurm array task and a
//! worker of `seads sweep run` both come here, so the two behave alike.

use std::path::Path;
use std::time::Duration;

use anyhow::{Context, Result, bail};
use seads_rl::{Algorithm, Hac, Run, TaskSac, Trainer};

use crate::train::Shown;
use seads_skillmodel::SkillModelKind;

use super::index::Sweep;
use super::state::{Claim, Missing, Outcome, Record, check_outputs};
use crate::plan::evaluate_checkpoints;
use crate::plan::{load_agent, run_evaluation};
use seads_planner::{EvaluationKind, Protocol, TaskSet};
use seads_study::evaluation::run_policy_evaluation;
use seads_study::over_training::Selection;

/// libtorch threads for a task with `cores` cores: two training threads of `cores / 2` each,
/// and all cores for SAC when the other thread waits (0 = keep: a task alone on one core).
pub fn thread_split(cores: usize) -> (usize, usize) {
    let cores = cores.max(1);
    ((cores / 2).max(1), if cores >= 2 { cores } else { 0 })
}

/// Runs task `index` of the sweep in `dir` with `cores` cores, waiting up to `patience` for
/// another task that holds the run. A run already done is left as it is. Errors are recorded in
/// the run's `task.json` before they are returned.
pub fn run_task(dir: &Path, index: usize, cores: usize, patience: Duration) -> Result<()> {
    let sweep = Sweep::load(dir).map_err(crate::bad_input)?;
    sweep.run_dir(dir, index).map_err(crate::bad_input)?;
    let (run, replanned) = sweep.ensure_run_dir(dir, index)?;
    if replanned {
        outln!(
            "{}: was deleted; planned again from the manifest",
            run.display()
        );
    }
    let claim = Claim::take(&run, patience)?;
    let previous = Record::read(&run)?;
    if let Some(done) = previous.as_ref().filter(|r| r.outcome == Outcome::Done) {
        match check_outputs(&run, done) {
            Ok(()) => {
                outln!("{}: already done", run.display());
                return Ok(());
            }
            Err(Missing::Gone(name)) => {
                outln!("{}: {name} is gone; finishing the run again", run.display());
            }
            Err(Missing::Unreadable(why)) => bail!(crate::BadInput(anyhow::anyhow!(why))),
        }
    }
    // Training it again from scratch would replace the data it holds; nothing is recorded, so
    // the run stays "copied".
    if seads_rl::is_copy_without_checkpoints(&run) {
        bail!(crate::BadInput(anyhow::anyhow!(
            "{} holds a run's data but no checkpoints folder (copied in by `seads report \
             --copy-runs`?): it is reported as it is and cannot be trained further",
            run.display()
        )));
    }
    let attempts = previous.map_or(0, |r| r.attempts) + 1;
    Record::write(&run, Outcome::Running, attempts, None)?;
    let result = train_and_evaluate(&sweep, &run, cores);
    match &result {
        Ok(()) => Record::write(&run, Outcome::Done, attempts, None)?,
        Err(e) => Record::write(&run, Outcome::Failed, attempts, Some(format!("{e:#}")))?,
    }
    drop(claim);
    result
}

fn train_and_evaluate(sweep: &Sweep, run: &Path, cores: usize) -> Result<()> {
    let config =
        seads_rl::load_config(run).with_context(|| format!("loading {}", run.display()))?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    let (threads, alone) = thread_split(cores);
    match config.algorithm {
        Algorithm::Sac => return train_and_evaluate_baseline::<TaskSac>(sweep, run, cores),
        Algorithm::Hac => return train_and_evaluate_baseline::<Hac>(sweep, run, cores),
        Algorithm::Seads => {}
    }
    let mut training = crate::train::resume(
        run,
        Run::resume_with(run, |mut c| {
            c.threads = threads;
            c.sac_threads_alone = alone;
            Trainer::new(c)
        }),
    )?;
    if !training.finished() {
        outln!(
            "{}: training from epoch {} with {threads} libtorch thread(s) per training thread",
            run.display(),
            training.trainer().epoch()
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
    seads_rl::set_threads(cores.max(1));
    if plan.every > 0 {
        let added = evaluate_checkpoints(
            run,
            Selection::Every(plan.every),
            &TaskSet::standard(plan.boards),
            plan.limits(),
            true,
        )?;
        outln!(
            "{}: {added} checkpoint evaluation(s) over training",
            run.display()
        );
    }
    if plan.last {
        let mut agent = load_agent(run, None)?;
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
fn train_and_evaluate_baseline<L: Shown>(sweep: &Sweep, run: &Path, cores: usize) -> Result<()> {
    let mut training = crate::train::resume(
        run,
        Run::resume_with(run, |mut c| {
            c.threads = cores.max(1);
            c.sac_threads_alone = 0;
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
        let checkpoint = seads_rl::latest_checkpoint(run)?
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
