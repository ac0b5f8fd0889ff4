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
    /// Draw the board and the executed skills' paths into this image (.png or .svg), or an
    /// animation of the whole solution (.gif): the manipulator moving step by step, the board
    /// changing, and the skill being executed with the skills executed so far.
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
    // The output is checked before the work: never written into the run, onto a special file,
    // or into a folder that is not there after the whole solve.
    if let Some(out) = &args.render {
        crate::paths::check_output_file(out, &[&args.run], &["png", "svg", "gif"])?;
    }
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
    let animate = args
        .render
        .as_deref()
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("gif")));
    if let Some(out) = animate {
        let mut filmed = seads_embodiment::Filmed::new(env);
        let outcome = solve(&mut filmed, policy, model, game.goal(), &config)?;
        let captions = captions(&agent.config.env, &outcome, filmed.frames().len());
        let frames: Vec<_> = filmed.take_frames().into_iter().zip(captions).collect();
        let shown = seads_study::animation::write_gif(&frames, 150, 1500, out)?;
        if shown < frames.len() {
            eprintln!(
                "seads: {} holds the first {shown} of the solution's {} frames (an animation holds \
                 at most {})",
                out.display(),
                frames.len(),
                seads_study::animation::MAX_FRAMES
            );
        }
        return report(&args, &game.format(board), &agent.checkpoint, &outcome);
    }
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
    report(&args, &game.format(board), &agent.checkpoint, &outcome)
}

/// A caption per frame of a solution's animation (the start, then one per manipulator step):
/// the skill being executed and those executed before it, and at the end the outcome.
fn captions(env: &str, outcome: &seads_planner::SolveOutcome, frames: usize) -> Vec<String> {
    let mut captions = vec![format!("{env}: the board to solve")];
    for (i, (&skill, &steps)) in outcome
        .executed
        .iter()
        .zip(&outcome.skill_steps)
        .enumerate()
    {
        let done: Vec<String> = outcome.executed[..i]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let before = if done.is_empty() {
            String::new()
        } else {
            format!("{} → ", done.join(" "))
        };
        for step in 0..steps {
            captions.push(format!("skills {before}[{skill}]   step {}", step + 1));
        }
    }
    let end = match &outcome.failure {
        None => format!("solved in {} steps", outcome.manipulator_steps),
        Some(_) => "not solved".to_owned(),
    };
    let end = format!("{} skills: {end}", outcome.executed.len());
    captions.resize(frames, end.clone());
    if let Some(last) = captions.last_mut() {
        *last = end;
    }
    captions
}

/// Prints what solving did.
fn report(
    args: &SolveArgs,
    board: &str,
    checkpoint: &std::path::Path,
    outcome: &seads_planner::SolveOutcome,
) -> Result<()> {
    if args.json {
        #[derive(Serialize)]
        struct Report<'a> {
            board: String,
            checkpoint: String,
            #[serde(flatten)]
            outcome: &'a seads_planner::SolveOutcome,
        }
        let report = Report {
            board: board.to_owned(),
            checkpoint: checkpoint.display().to_string(),
            outcome,
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
