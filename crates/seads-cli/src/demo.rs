//! `seads run`: the whole mission in one command on embedded defaults — train a small agent,
//! evaluate it on test boards with and without re-planning, and write the figures.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use seads_planner::summarise;
use seads_rl::{Run, TrainConfig, Trainer};

use crate::BadInput;
use crate::plan::run_evaluation;
use seads_planner::Protocol;

/// Arguments of `seads run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Run directory (an existing one is resumed and re-evaluated).
    #[arg(long, default_value = "runs/demo")]
    out: PathBuf,
    /// Environment (its preset supplies every other setting).
    #[arg(long, default_value = "lightsout-cursor")]
    env: String,
    /// Training budget in environment steps (the paper's Cursor budget is 500000). With the
    /// default, seed 1 ends at epoch 1699 with skill coverage 24.80/25 (portable numerics, an
    /// AMD EPYC), and coverage wobbles by about a skill between evaluations (docs/results/demo).
    #[arg(long, default_value_t = 157_252)]
    env_steps: u64,
    /// Seed of the run.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Boards per solution depth (1–5) in the evaluation.
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// The search limits of the evaluation.
    #[command(flatten)]
    search: crate::plan::SearchArgs,
}

/// `seads run`.
pub fn run(args: RunArgs) -> Result<()> {
    crate::plan::check_boards(args.boards)?;
    let (mut run, _lock) = if args.out.join("config.toml").exists() {
        outln!("resuming the run in {}", args.out.display());
        let lock = crate::lock_run(&args.out)?;
        let config = seads_rl::load_config(&args.out)?;
        crate::kernels::use_kernels(config.portable_numerics)?;
        let run = crate::train::resume(&args.out, Run::<Trainer>::resume(&args.out))?;
        (run, lock)
    } else {
        let mut config = TrainConfig::preset(&args.env).map_err(|e| BadInput(e.into()))?;
        config.env_steps = args.env_steps;
        config.seed = args.seed;
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
            seads_rl::RlError::Config(_) => anyhow::Error::from(BadInput(e.into())),
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
    let replan = run_evaluation(&mut agent, &args.out, &protocol(true), false)?.results;
    let once = run_evaluation(&mut agent, &args.out, &protocol(false), false)?.results;
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
