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
use crate::plan::{evaluate_with_bar, load_agent};
use seads_planner::{EvaluationRecord, Protocol};
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
    /// Boards per depth of the evaluation the success figure shows. A saved evaluation of
    /// exactly this protocol (boards and search limits) is reused; otherwise one is run and
    /// saved (a robot run's is shown only if `seads uarm` saved it).
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// The search limits of that evaluation.
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
    crate::paths::check_output_file(gif, &[run], &["gif"])?;
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
    let shown = seads_study::animation::write_gif(&frames, 150, 150, gif)?;
    if shown < frames.len() {
        // Never a cut without a word: the clips of the last skills are not in the file.
        outln!(
            "wrote {} ({shown} of {} frames: an animation holds at most {}; the last skills' \
             clips are left out, fewer --starts show every skill)",
            gif.display(),
            frames.len(),
            seads_study::animation::MAX_FRAMES
        );
    } else {
        outln!("wrote {} ({shown} frames)", gif.display());
    }
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
        let protocol = Protocol::planning(true, boards, limits);
        let file = saved_evaluation(run, &agent, &protocol)?;
        match read_evaluation(&file).map_err(crate::study_error)? {
            Some(record) if shows(&record, &agent, &protocol) => {
                let replan = [(true, record.results)];
                let at = with_protocol(&at, &protocol);
                both("success", &|p| success_figure(p, &replan, &at))?;
            }
            _ if !quiet => eprintln!(
                "seads: {} holds no evaluation of epoch {} with this protocol ({}): no success \
                 figure (`seads uarm evaluate` makes one; --boards and the search options choose \
                 the protocol)",
                file.display(),
                agent.epoch,
                protocol.label()
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
        let shown = with_protocol(&at, &Protocol::planning(true, boards, limits));
        both("success", &|p| success_figure(p, &evaluations, &shown))?;
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

/// Where an evaluation with `protocol` of the agent's checkpoint is saved in `run`: the
/// protocol's file for the run's latest checkpoint (`evaluation-replan.json` for the standard
/// protocol), an epoch-named one (`evaluation-replan-epoch-000500.json`) for an earlier
/// checkpoint, as the evaluation names it.
fn saved_evaluation(run: &Path, agent: &Agent, protocol: &Protocol) -> Result<PathBuf> {
    let (_, named) = seads_study::evaluation::checkpoint_of(run, &agent.checkpoint)
        .map_err(crate::study_error)?;
    Ok(run.join(protocol.results_file(named)))
}

/// Whether a saved evaluation is the one a figure of the agent's checkpoint under `protocol`
/// shows: of that checkpoint, and under exactly that protocol (one made with other boards or
/// limits, or one that does not say, never stands in for it).
fn shows(record: &EvaluationRecord, agent: &Agent, protocol: &Protocol) -> bool {
    record.checkpoint.is_some_and(|c| c.epoch == agent.epoch) && record.made_with(protocol)
}

/// A figure's title with the evaluation's protocol where it is not the standard one.
fn with_protocol(title: &str, protocol: &Protocol) -> String {
    if protocol.departures().is_empty() {
        title.to_owned()
    } else {
        format!("{title}; {}", protocol.label())
    }
}

/// The run's evaluations of the agent's checkpoint with and without re-planning, each with
/// `boards` boards per depth under `limits`: the saved ones where they are of that checkpoint and
/// that protocol ([`saved_evaluation`], [`shows`]), otherwise evaluated now.
fn evaluations(
    agent: &mut Agent,
    run: &Path,
    boards: usize,
    limits: seads_planner::SearchLimits,
    quiet: bool,
) -> Result<[(bool, Vec<DepthResult>); 2]> {
    let mut load = |replan: bool| -> Result<Vec<DepthResult>> {
        let protocol = Protocol::planning(replan, boards, limits);
        let file = saved_evaluation(run, agent, &protocol)?;
        let saved = read_evaluation(&file).map_err(crate::study_error)?;
        if let Some(record) = saved
            && shows(&record, agent, &protocol)
        {
            return Ok(record.results);
        }
        Ok(evaluate_with_bar(agent, run, &protocol, quiet)?.results)
    };
    Ok([(true, load(true)?), (false, load(false)?)])
}
