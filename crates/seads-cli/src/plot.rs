//! `seads plot`: the figures of a run — skill coverage over training, task success per depth
//! with and without re-planning, skill trajectories (seed Fig. S.2–S.4) and push points per
//! skill (Fig. S.1).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use seads_embodiment::{EnvConfig, Environment as _};
use seads_games::Split;
use seads_planner::DepthResult;
use seads_rl::{Agent, find_checkpoint, read_metrics};

use crate::envs::build_env;
use crate::plan::{load_agent, run_evaluation};
use seads_planner::{EvaluationKind, Protocol, STANDARD_DEPTHS};
use seads_study::evaluation::read_evaluation;
use seads_study::figures::{coverage_figure, skill_figures, success_figure};

/// Arguments of `seads plot`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// Run directory of a trained agent.
    #[arg(long)]
    run: PathBuf,
    /// Folder for the figures (PNG and SVG of each).
    #[arg(long, required_unless_present = "animate")]
    out: Option<PathBuf>,
    /// Instead of the figures, write an animation (.gif) of every skill: one short clip per skill
    /// from each of `--starts` initialisations (the first of the coverage evaluation's).
    #[arg(long, value_name = "GIF")]
    animate: Option<PathBuf>,
    /// Initialisations per skill in `--animate`'s clips.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u64).range(1..=20))]
    starts: u64,
    /// Use the checkpoint of this epoch instead of the latest (its evaluation is saved as
    /// `evaluation-replan-epoch-NNNNNN.json` and reused; the figures of it name the epoch).
    #[arg(long)]
    checkpoint: Option<u64>,
    /// Boards per depth when an evaluation must be run first (saved evaluations are reused).
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// The search limits of such an evaluation.
    #[command(flatten)]
    search: crate::plan::SearchArgs,
}

/// `seads plot`: writes every figure of the run into `out`; returns the files written.
pub fn plot(args: PlotArgs) -> Result<()> {
    crate::plan::check_boards(args.boards)?;
    if let Some(gif) = &args.animate {
        return animate(&args.run, args.checkpoint, args.starts, gif);
    }
    let out = args
        .out
        .as_ref()
        .expect("clap requires --out without --animate");
    // Plotting may evaluate the run and save that evaluation into it.
    crate::run_config(&args.run)?;
    let _lock = crate::lock_run(&args.run)?;
    let written = write_figures(
        &args.run,
        out,
        args.checkpoint,
        args.boards,
        args.search.limits(),
        false,
    )?;
    for path in written {
        outln!("wrote {}", path.display());
    }
    Ok(())
}

/// `seads plot --animate GIF`: a clip per skill, from `starts` coverage initialisations.
fn animate(run: &Path, checkpoint: Option<u64>, starts: u64, gif: &Path) -> Result<()> {
    if !gif
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gif"))
    {
        return Err(crate::BadInput(anyhow::anyhow!(
            "--animate {}: the animation is a .gif file",
            gif.display()
        ))
        .into());
    }
    let config = seads_rl::load_config(run)?;
    let (env, agent) = match crate::uarm::twin_for_figures(run, &config)? {
        Some(twin) => {
            let spec = twin.spec().clone();
            let on_cpu = seads_rl::TrainConfig {
                device: seads_rl::ComputeDevice::Cpu,
                ..config
            };
            let agent = Agent::load_for(on_cpu, spec, &find_checkpoint(run, checkpoint)?)?;
            (twin.box_clone(), agent)
        }
        None => {
            let agent = load_agent(run, checkpoint, seads_rl::ComputeDevice::Cpu)?;
            let env = build_env(
                &agent.config.env,
                &EnvConfig {
                    reset_split: Split::Test,
                    ..agent.config.env_config.clone()
                },
            )?;
            (env, agent)
        }
    };
    let frames =
        seads_study::animation::skill_clips(env, &agent.policy, starts, seads_rl::COVERAGE_SEED)?;
    seads_study::animation::write_gif(&frames, 150, 150, gif)?;
    outln!("wrote {} ({} frames)", gif.display(), frames.len());
    Ok(())
}

/// Writes the figures of the run in `run` into `out`.
pub fn write_figures(
    run: &Path,
    out: &Path,
    checkpoint: Option<u64>,
    boards: usize,
    limits: seads_planner::SearchLimits,
    quiet: bool,
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut written = Vec::new();
    let mut both = |name: &str, f: &dyn Fn(&Path) -> seads_study::Result<()>| -> Result<()> {
        written.extend(seads_study::draw::png_and_svg(out, name, f)?);
        Ok(())
    };
    let metrics = read_metrics(run)?;
    let config = seads_rl::load_config(run)?;
    let title = format!("{} (seed {})", config.env, config.seed);
    if let Some(mut twin) = crate::uarm::twin_for_figures(run, &config)? {
        // A robot run: its skills are shown on the twin, and its success is what `seads uarm
        // train` measured (with re-planning only).
        let spec = twin.spec().clone();
        let on_cpu = seads_rl::TrainConfig {
            device: seads_rl::ComputeDevice::Cpu,
            ..config
        };
        let agent = Agent::load_for(on_cpu, spec, &find_checkpoint(run, checkpoint)?)?;
        let k = seads_embodiment::SkillPolicy::num_skills(&agent.policy);
        let at = checkpoint_title(&agent);
        both("coverage", &|p| coverage_figure(p, &metrics, k, &title))?;
        let file = saved_evaluation(run, &agent, EvaluationKind::Replan)?;
        match read_evaluation(&file).map_err(crate::study_error)? {
            Some(record) if record.checkpoint.is_some_and(|c| c.epoch == agent.epoch) => {
                let replan = [(true, record.results)];
                both("success", &|p| success_figure(p, &replan, &at))?;
            }
            Some(_) if !quiet => eprintln!(
                "seads: {} is not an evaluation of epoch {}: no success figure \
                 (`seads uarm evaluate` makes one)",
                file.display(),
                agent.epoch
            ),
            _ => {}
        }
        if !quiet {
            eprintln!(
                "seads: {} is a robot run ({}): its skills are drawn as the twin executes them",
                run.display(),
                agent.config.env
            );
        }
        skill_figures(&mut twin, &agent.policy, &at, both)?;
        return Ok(written);
    }
    let mut agent = load_agent(run, checkpoint, seads_rl::ComputeDevice::Cpu)?;
    let k = seads_embodiment::SkillPolicy::num_skills(&agent.policy);
    let at = checkpoint_title(&agent);
    both("coverage", &|p| coverage_figure(p, &metrics, k, &title))?;
    if agent.model.is_some() {
        let evaluations = evaluations(&mut agent, run, boards, limits, quiet)?;
        both("success", &|p| success_figure(p, &evaluations, &at))?;
    } else if !quiet {
        eprintln!(
            "seads: {} is a VIC run: its skill discriminator cannot plan, so there is no task-success figure",
            run.display()
        );
    }
    let mut env = build_env(
        &agent.config.env,
        &EnvConfig {
            reset_split: Split::Test,
            ..agent.config.env_config.clone()
        },
    )?;
    skill_figures(env.as_mut(), &agent.policy, &at, both)?;
    Ok(written)
}

/// The title of the figures of one checkpoint (success, skills): the coverage figure's, with
/// the checkpoint's epoch.
fn checkpoint_title(agent: &Agent) -> String {
    let config = &agent.config;
    format!(
        "{} (seed {}, epoch {})",
        config.env, config.seed, agent.epoch
    )
}

/// Where an evaluation of `kind` on the standard depths of the agent's checkpoint is saved in
/// `run`: the final evaluation's file for the run's latest checkpoint, an epoch-named one
/// (`evaluation-replan-epoch-000500.json`) for an earlier checkpoint, as the evaluation names it.
fn saved_evaluation(run: &Path, agent: &Agent, kind: EvaluationKind) -> Result<PathBuf> {
    let (_, named) = seads_study::evaluation::checkpoint_of(run, &agent.checkpoint)
        .map_err(crate::study_error)?;
    Ok(run.join(kind.results_file(&STANDARD_DEPTHS, named)))
}

/// The run's evaluations of the agent's checkpoint with and without re-planning: the saved ones
/// where they name that checkpoint ([`saved_evaluation`]: `evaluation-replan.json` and
/// `evaluation-plan-once.json` for the latest checkpoint, `-epoch-NNNNNN` ones for an earlier
/// one), otherwise evaluated now (an evaluation of another checkpoint, or one that does not say
/// which it evaluated, is never shown for this one).
fn evaluations(
    agent: &mut Agent,
    run: &Path,
    boards: usize,
    limits: seads_planner::SearchLimits,
    quiet: bool,
) -> Result<[(bool, Vec<DepthResult>); 2]> {
    let mut load = |replan: bool| -> Result<Vec<DepthResult>> {
        let file = saved_evaluation(run, agent, EvaluationKind::planning(replan))?;
        let saved = read_evaluation(&file).map_err(crate::study_error)?;
        if let Some(record) = saved
            && record.checkpoint.is_some_and(|c| c.epoch == agent.epoch)
        {
            return Ok(record.results);
        }
        let protocol = Protocol::planning(replan, boards, limits);
        Ok(run_evaluation(agent, run, &protocol, quiet)?.results)
    };
    Ok([(true, load(true)?), (false, load(false)?)])
}
