//! `seads solve`: one board, planned with the agent's forward model and executed with its skills.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use seads_planner::{SolveConfig, solve};
use serde::Serialize;

use super::load_agent;
use crate::BadInput;
use crate::envs::build_env;

/// Arguments of `seads solve`.
#[derive(Debug, Args)]
pub struct SolveArgs {
    /// Run directory of a trained agent (from `seads train`).
    #[arg(long)]
    run: PathBuf,
    /// The board to solve, comma-separated field values (see `seads games solve --help`).
    #[arg(long)]
    board: String,
    /// Re-plan when the board deviates from the prediction (Algorithm 2); otherwise plan once.
    #[arg(long)]
    replan: bool,
    /// Use the checkpoint of this epoch instead of the latest.
    #[arg(long)]
    checkpoint: Option<u64>,
    /// Seed of the manipulator's initial state.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    #[command(flatten)]
    search: super::SearchArgs,
    /// Draw the board and the executed skills' paths into this image (.png or .svg).
    #[arg(long)]
    render: Option<PathBuf>,
    /// Where the networks run: cpu, cuda (the first GPU) or cuda:N.
    #[arg(long, default_value = "cpu")]
    device: seads_rl::ComputeDevice,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// `seads solve`.
pub fn solve_board(args: SolveArgs) -> Result<()> {
    // The planner's parts run on rayon's threads, each on one libtorch thread.
    seads_rl::set_threads(1);
    let mut agent = load_agent(&args.run, args.checkpoint, args.device)?;
    let mut env = build_env(&agent.config.env, &agent.config.env_config)?;
    let game = env.spec().game.build(env.spec().board_size)?;
    let board = game.parse(&args.board).map_err(|e| BadInput(e.into()))?;
    env.seed(args.seed);
    env.reset()?;
    env.set_board(board).map_err(|e| BadInput(e.into()))?;
    let before = env.scene();
    let config = SolveConfig {
        replan: args.replan,
        planner: args.search.limits().planner(),
        ..SolveConfig::default()
    };
    let (policy, model) = agent.parts()?;
    let outcome = solve(env.as_mut(), policy, model, game.goal(), &config)?;
    if let Some(out) = &args.render {
        let status = if outcome.solved {
            "solved"
        } else {
            "not solved"
        };
        let title = format!(
            "{}: {} in {} steps",
            agent.config.env, status, outcome.manipulator_steps
        );
        seads_study::draw::render_solution(&before, &outcome.runs, &title, out)?;
    }
    if args.json {
        #[derive(Serialize)]
        struct Report<'a> {
            board: String,
            checkpoint: String,
            #[serde(flatten)]
            outcome: &'a seads_planner::SolveOutcome,
        }
        let report = Report {
            board: game.format(board),
            checkpoint: agent.checkpoint.display().to_string(),
            outcome: &outcome,
        };
        outln!("{}", serde_json::to_string(&report)?);
    } else {
        let list = |v: &[usize]| {
            v.iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        if outcome.plan_found {
            outln!(
                "plan ({} skills): {}   search {:.3} s over {} plan(s)",
                outcome.first_plan.len(),
                list(&outcome.first_plan),
                outcome.planning_s,
                outcome.plans
            );
        }
        outln!(
            "executed skills: {}   manipulator steps per skill: {}",
            list(&outcome.executed),
            list(&outcome.skill_steps)
        );
        match &outcome.failure {
            None if outcome.executed.is_empty() => outln!("the board is already solved"),
            None => outln!("solved in {} manipulator steps", outcome.manipulator_steps),
            Some(why) => outln!("not solved: {why}"),
        }
    }
    Ok(())
}
