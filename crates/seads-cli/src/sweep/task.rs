//! `seads sweep task`: one run of a sweep, start to finish — claim it, train it (resuming what
//! a killed or re-queued task left), evaluate it, record the outcome. A Slurm array task and a
//! worker of `seads sweep run` both come here, so the two behave alike.

use std::path::Path;
use std::time::Duration;

use anyhow::{Context, Result};
use seads_rl::store::MetricsLine as _;
use seads_rl::{ComputeDevice, Learner, Members, Population, Run, SeadsConfig, WithLearner};

use seads_rl::InWords;

use super::index::Sweep;
use crate::BadInput;
use crate::plan::evaluate_checkpoints_with_bar;
use crate::plan::{evaluate_with_bar, load_agent};
use crate::sweep::train::member_config;
use seads_evaluation::evaluation::run_policy_evaluation;
use seads_evaluation::over_training::Selection;
use seads_planner::{EvaluationKind, PlanModel, Protocol, TaskSet};
use seads_study::sweep::{Task, Work};

/// Runs the task of the runs `indices` of the sweep in `dir` with `cores` cores and the networks
/// on `device`: one run trains alone, several train as one population (see
/// [`seads_rl::Population`]), then each is evaluated. Waits up to `patience` for another task
/// that holds a run. Runs already done are left as they are. Errors are recorded in the runs'
/// `task.json` before they are returned.
pub fn run_task(
    dir: &Path,
    indices: &[usize],
    cores: usize,
    device: ComputeDevice,
    patience: Duration,
) -> Result<()> {
    // Every run is claimed and checked before anything is written.
    let tasks = Task::claim_population(dir, indices, patience).map_err(crate::study_error)?;
    let mut work = Vec::new();
    for task in tasks {
        let run = task.run.display();
        if task.replanned {
            outln!("{run}: was deleted; planned again from the manifest");
        }
        match &task.work {
            Work::Nothing => outln!("{run}: already done"),
            Work::Redo(name) => {
                outln!("{run}: {name} is gone; finishing the run again");
                work.push(task);
            }
            Work::Run => work.push(task),
        }
    }
    for task in &work {
        task.start()?;
    }
    let runs: Vec<&Path> = work.iter().map(|t| t.run.as_path()).collect();
    let trained = match runs.len() {
        0 => return Ok(()),
        1 => train(runs[0], cores, device),
        _ => train_population(&runs, cores, device),
    };
    let mut first_error = None;
    for task in work {
        let result = match &trained {
            Ok(()) => evaluate(&task.sweep, &task.run, device),
            Err(e) => Err(anyhow::anyhow!("{e:#}")),
        };
        task.finish(&result)?;
        if let Err(e) = result {
            first_error.get_or_insert(e);
        }
    }
    match (trained, first_error) {
        (Err(e), _) | (Ok(()), Some(e)) => Err(e),
        (Ok(()), None) => Ok(()),
    }
}

/// Trains (or resumes) one run to its budget with `cores` cores: SEADS on two training threads,
/// a baseline on one ([`seads_rl::TrainConfig::use_cores`]).
fn train(run: &Path, cores: usize, device: ComputeDevice) -> Result<()> {
    let config =
        seads_rl::load_config(run).with_context(|| format!("loading {}", run.display()))?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    seads_rl::with_learner(config.algorithm(), TrainOne { run, cores, device })?
}

/// [`train`]'s work with the run's learner.
struct TrainOne<'a> {
    run: &'a Path,
    cores: usize,
    device: ComputeDevice,
}

impl WithLearner for TrainOne<'_> {
    type Output = Result<()>;
    fn run<L: InWords + Send>(self) -> Result<()> {
        train_one::<L>(self.run, self.cores, self.device)
    }
}

fn train_one<L: InWords>(run: &Path, cores: usize, device: ComputeDevice) -> Result<()> {
    let mut training = crate::train::resume(
        run,
        Run::resume_with(run, |mut c| {
            c.use_cores(cores);
            c.device = device;
            L::build(c)
        }),
    )?;
    if !training.finished() {
        let config = training.trainer().config();
        outln!(
            "{}: training from epoch {} with {} libtorch thread(s) per training thread ({})",
            run.display(),
            training.trainer().epoch(),
            config.threads,
            config.algorithm()
        );
        crate::train::drive(&mut training, true)?;
    }
    Ok(())
}

/// Trains the runs `runs` (checked to fit one population) together to their budgets: their
/// epochs side by side on `cores` threads, each member's networks on one libtorch thread. On a
/// GPU, SEADS members' SAC agents are stacked there ([`seads_rl::StackedPopulation`]) and the
/// rest of their work stays on the CPU.
fn train_population(runs: &[&Path], cores: usize, device: ComputeDevice) -> Result<()> {
    let config = seads_rl::load_config(runs[0])?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    let cpu = ComputeDevice::Cpu;
    if config.is::<SeadsConfig>() && device != cpu {
        return train_members(runs, cpu, |members| {
            seads_rl::StackedPopulation::new(members, cores, device)
        });
    }
    seads_rl::with_learner(
        config.algorithm(),
        TrainPopulation {
            runs,
            cores,
            device,
        },
    )?
}

/// [`train_population`]'s work with the runs' learner, on the CPU or one device.
struct TrainPopulation<'a> {
    runs: &'a [&'a Path],
    cores: usize,
    device: ComputeDevice,
}

impl WithLearner for TrainPopulation<'_> {
    type Output = Result<()>;
    fn run<L: InWords + Send>(self) -> Result<()> {
        let cores = self.cores;
        train_members(self.runs, self.device, |m| Population::<L>::new(m, cores))
    }
}

fn train_members<P: Members>(
    runs: &[&Path],
    device: ComputeDevice,
    population: impl FnOnce(Vec<Run<P::Learner>>) -> Result<P, seads_rl::RlError>,
) -> Result<()>
where
    P::Learner: InWords,
{
    let members = runs
        .iter()
        .map(|run| {
            let build = |c| P::Learner::build(member_config(c, device));
            crate::train::resume(run, Run::resume_with(run, build))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut population = population(members).map_err(|e| BadInput(e.into()))?;
    let names: Vec<String> = runs.iter().map(|r| r.display().to_string()).collect();
    outln!(
        "training {} runs as one population: {}",
        runs.len(),
        names.join(", ")
    );
    let hook = crate::train::crash_hook()?;
    let show = |run: &Run<P::Learner>, m: &<P::Learner as Learner>::Metrics| -> Result<()> {
        let (epoch, steps) = (m.epoch(), m.env_steps());
        let headline = run.trainer().headline(m);
        outln!(
            "{}: epoch {epoch:>6}  steps {steps:>9}  {headline}",
            run.dir().display()
        );
        Ok(())
    };
    let build = crate::build();
    crate::sweep::train::train_population(&mut population, &build, hook, |run, m| {
        show(run, m).map_err(Into::into)
    })
    .context("training the population")
}

/// Evaluates a trained run as its sweep asks.
fn evaluate(sweep: &Sweep, run: &Path, device: ComputeDevice) -> Result<()> {
    let config =
        seads_rl::load_config(run).with_context(|| format!("loading {}", run.display()))?;
    if config.baseline_training().is_ok() {
        return evaluate_baseline(sweep, run, &config);
    }
    let plan = &sweep.evaluation;
    // The planner's parts and bookkeeping run on the task's rayon pool (`cores` threads), each
    // part's network on one libtorch thread.
    seads_rl::set_threads(1);
    let own_model = config.seads().is_ok_and(|s| s.skill_model.kind.plans());
    if !own_model && !plan.fitted_model {
        outln!(
            "{}: a {} run learned no forward model to plan with; no task evaluation (its skill \
             coverage is in metrics.jsonl; a study plans with its skills by `fitted_model = true` \
             in its [evaluation])",
            run.display(),
            config.algorithm()
        );
        return Ok(());
    }
    if own_model && plan.every > 0 {
        let added = evaluate_checkpoints_with_bar(
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
    if !plan.last {
        return Ok(());
    }
    let mut agent = load_agent(run, None, device)?;
    let mut models = Vec::new();
    if own_model {
        models.push(PlanModel::Own);
    }
    if plan.fitted_model {
        fit_unless_fitted(&agent, run)?;
        models.push(PlanModel::Fitted);
    }
    for model in models {
        for replan in [true, false] {
            let protocol = Protocol {
                kind: EvaluationKind::planning(replan),
                tasks: TaskSet::standard(plan.boards),
                limits: Some(plan.limits()),
                action_noise: None,
                model,
            };
            let results = evaluate_with_bar(&mut agent, run, &protocol, true)?.results;
            let solved: usize = results.iter().map(|r| r.solved).sum();
            let tasks: usize = results.iter().map(|r| r.tasks).sum();
            outln!(
                "{}: {}{} {solved}/{tasks} solved",
                run.display(),
                if replan {
                    "with re-planning"
                } else {
                    "plan once"
                },
                match model {
                    PlanModel::Own => "",
                    PlanModel::Fitted => " with the fitted model",
                }
            );
        }
    }
    Ok(())
}

/// Fits a forward model to the final skills of the run in `run` (the standard settings, the
/// run's seed), unless one fitted to them is there (a task re-queued after fitting).
fn fit_unless_fitted(agent: &seads_rl::Agent, run: &Path) -> Result<()> {
    let fitted = seads_run::fitted::read_fit_record(run)?;
    if fitted.is_some_and(|r| r.checkpoint.epoch == agent.epoch) {
        return Ok(());
    }
    let settings = seads_run::fitted::FitSettings::standard(agent.config.seed);
    let record = crate::plan::fit_naming_this_binary(agent, run, &settings, |_| {})?;
    outln!(
        "{}: a forward model fitted to its skills: the most likely successor right {:.1} % of \
         {} held-out executions",
        run.display(),
        100.0 * record.quality.mode_accuracy,
        record.quality.held_out
    );
    Ok(())
}

/// Task success of a baseline's final policy on the study's boards per depth
/// (`evaluation-policy.json`).
fn evaluate_baseline(sweep: &Sweep, run: &Path, config: &seads_rl::TrainConfig) -> Result<()> {
    if sweep.evaluation.last {
        // The final checkpoint holds the trained policy.
        let checkpoint = seads_rl::store::latest_checkpoint(run)?
            .with_context(|| format!("{} has no checkpoint", run.display()))?;
        let results = run_policy_evaluation(
            config,
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
