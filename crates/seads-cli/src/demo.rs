//! `seads run`: the whole mission in one command on embedded defaults — train a small agent,
//! evaluate it on test boards with and without re-planning, and write the figures.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use seads_planner::summarise;
use seads_rl::{Run, TrainConfig, Trainer};

use crate::BadInput;
use crate::plan::evaluate_with_bar;
use seads_planner::Protocol;

/// Arguments of `seads run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Run directory. An existing one is resumed and re-evaluated: --env and --seed, if given,
    /// must then be the run's, and --env-steps raises its budget.
    #[arg(long, default_value = "runs/demo")]
    out: PathBuf,
    /// Environment (its preset supplies every other setting) [default: lightsout-cursor].
    #[arg(long)]
    env: Option<String>,
    /// Training budget in environment steps (the paper's Cursor budget is 500000). With the
    /// default, seed 1 ends at epoch 1699 with skill coverage 24.80/25 (portable numerics, an
    /// AMD EPYC), and coverage wobbles by about a skill between evaluations (docs/results/demo)
    /// [default: 157252].
    #[arg(long)]
    env_steps: Option<u64>,
    /// Seed of the run [default: 1].
    #[arg(long)]
    seed: Option<u64>,
    /// Boards per solution depth (1–5) in the evaluation.
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// The search limits of the evaluation.
    #[command(flatten)]
    search: crate::plan::SearchArgs,
}

/// The demo's environment, budget and seed where the command line gives none.
const DEFAULT_ENV: &str = "lightsout-cursor";
const DEFAULT_ENV_STEPS: u64 = 157_252;
const DEFAULT_SEED: u64 = 1;

/// An existing run is resumed as it is: an environment or seed given on the command line that is
/// not the run's is bad input, never silently ignored (the run's budget may be raised).
fn agrees_with_run(args: &RunArgs, config: &TrainConfig) -> Result<()> {
    let other = |what: &str, given: String, run: String| {
        Err(BadInput(anyhow::anyhow!(
            "{} is a run of {what} {run}, not {given}: leave --{what} out to resume it, or choose \
             another --out",
            args.out.display()
        ))
        .into())
    };
    if let Some(env) = args.env.as_ref().filter(|e| **e != config.env) {
        return other("env", env.clone(), config.env.clone());
    }
    if let Some(seed) = args.seed.filter(|s| *s != config.seed) {
        return other("seed", seed.to_string(), config.seed.to_string());
    }
    Ok(())
}

/// `seads run`.
pub fn run(args: RunArgs) -> Result<()> {
    crate::plan::check_boards(args.boards)?;
    let (mut run, _lock) = if args.out.join("config.toml").exists() {
        let lock = crate::lock_run(&args.out)?;
        let config = crate::run_config(&args.out)?;
        agrees_with_run(&args, &config)?;
        if !config.is::<seads_rl::SeadsConfig>() {
            return Err(BadInput(anyhow::anyhow!(
                "{} is a run of {}, not SEADS: resume it with seads train --resume",
                args.out.display(),
                config.algorithm()
            ))
            .into());
        }
        if let Some(steps) = args.env_steps {
            seads_rl::raise_budget(&args.out, steps).map_err(|e| match e {
                seads_run::RunError::Config(_) => BadInput(e.into()).into(),
                other => anyhow::Error::from(other),
            })?;
        }
        outln!("resuming the run in {}", args.out.display());
        crate::kernels::use_kernels(config.portable_numerics)?;
        let run = crate::train::resume(&args.out, Run::<Trainer>::resume(&args.out))?;
        (run, lock)
    } else {
        let env = args.env.as_deref().unwrap_or(DEFAULT_ENV);
        let mut config = TrainConfig::preset(env).map_err(|e| BadInput(e.into()))?;
        config.env_steps = args.env_steps.unwrap_or(DEFAULT_ENV_STEPS);
        config.seed = args.seed.unwrap_or(DEFAULT_SEED);
        config.validate().map_err(|e| BadInput(e.into()))?;
        // Portable kernels: the same numbers on every machine of a kind (docs/RESULTS.md).
        config.portable_numerics = true;
        crate::kernels::use_kernels(true)?;
        outln!(
            "training SEADS on {} for {} environment steps into {}",
            config.env,
            config.env_steps,
            args.out.display()
        );
        let lock = crate::lock_new_run(&args.out)?;
        let run = Run::create(&args.out, config).map_err(|e| match e {
            seads_rl::RlError::Run(seads_run::RunError::Config(_)) => {
                anyhow::Error::from(BadInput(e.into()))
            }
            other => anyhow::Error::from(other),
        })?;
        (run, lock)
    };
    crate::train::drive(&mut run, false)?;
    drop(run);

    let mut agent = crate::plan::load_agent(&args.out, None, seads_rl::ComputeDevice::Cpu)?;
    outln!(
        "\nsolving {} test boards per depth 1–5 by planning with the learned forward model:",
        args.boards
    );
    outln!(" depth   with re-planning   plan once   median steps (re-planning)");
    let protocol = |replan| Protocol::planning(replan, args.boards, args.search.limits());
    let replan = evaluate_with_bar(&mut agent, &args.out, &protocol(true), false)?.results;
    let once = evaluate_with_bar(&mut agent, &args.out, &protocol(false), false)?.results;
    let (a, b) = (summarise(&replan), summarise(&once));
    for r in &replan {
        let key = r.depth;
        let steps = a.solution_steps[&key].map_or("-".to_owned(), |s| format!("{s:.0}"));
        outln!(
            "{:>6}   {:>15.0}%   {:>8.0}%   {:>10}",
            r.depth,
            a.success_rate[&key] * 100.0,
            b.success_rate[&key] * 100.0,
            steps
        );
    }
    let figures = args.out.join("figures");
    let written = crate::plot::write_figures(
        &args.out,
        &figures,
        None,
        args.boards,
        args.search.limits(),
        true,
    )?;
    outln!("\nfigures ({}): {}", written.len(), figures.display());
    outln!(
        "next: seads solve --run {} --board \"…\" --replan   (see seads --help)",
        args.out.display()
    );
    Ok(())
}
