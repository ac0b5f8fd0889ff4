//! Planning with a trained agent: `seads solve` (one board), `seads evaluate` (task success over
//! many boards), `seads fit-model` (a forward model for any learner's skills) and
//! `seads plan-bench` (the planner's speed on a fitted model).

mod bench;
mod evaluate;
mod evaluation;
mod fit;
mod solve;

use std::path::Path;

use anyhow::{Context, Result, bail};
use clap::Args;
use seads_planner::{PlanChoice, Search, SearchLimits};
use seads_rl::{Agent, ComputeDevice};

pub use bench::{PlanBenchArgs, plan_bench};
pub use evaluate::{EvaluateArgs, evaluate_run};
pub use evaluation::{evaluate_checkpoints_with_bar, evaluate_with_bar};
pub use fit::{FitModelArgs, fit_model, fit_naming_this_binary};
pub use solve::{SolveArgs, solve_board};

use crate::BadInput;

/// Says on standard error that a stopped evaluation's journal in `run` had `damaged` lines that
/// could not be read back, so that their tasks are solved again (nothing if none).
pub fn warn_damaged_journal(run: &Path, damaged: usize) {
    if damaged > 0 {
        eprintln!(
            "seads: {}: {damaged} damaged line(s) in the journal of a stopped evaluation were left \
             out; their tasks are solved again",
            run.display()
        );
    }
}

/// How far each search may go: by default 2²² expanded states and no clock, so that the same
/// agent solves the same boards on any machine, loaded or not.
#[derive(Debug, Clone, Args)]
pub struct SearchArgs {
    /// Stop each search after expanding this many states (the default, 2²² = 4194304, finds
    /// every 5×5 LightsOut board of depth ≤ 10 with a model as good as the true rules). The
    /// same on every machine.
    #[arg(
        long,
        value_name = "STATES",
        default_value_t = seads_planner::DEFAULT_MAX_EXPANDED as u64,
        value_parser = clap::value_parser!(u64).range(1..)
    )]
    max_expanded: u64,
    /// Also stop each search after this many seconds (off by default: a clock makes the outcome
    /// depend on the machine's speed and load; the authors used 60).
    #[arg(long, value_name = "SECONDS", value_parser = crate::numbers::positive_finite)]
    timeout: Option<f64>,
    /// Which of the shortest plans to take: `most-likely` (the plan the forward model gives the
    /// highest probability, each step by the skill likeliest to make it; re-planning avoids a
    /// skill that just failed from the same board), `most-likely-wary` (also avoids, from every
    /// board, a skill that failed twice in the task, while a plan without it is left) or
    /// `first-found` (the paper's search).
    #[arg(long, value_name = "CHOICE", default_value = "most-likely")]
    plan: PlanChoice,
    /// How each search goes: `breadth` (breadth-first from the board, the paper's) or
    /// `both-ends` (also backwards from the goal where the model's skills act the same on every
    /// board, as on LightsOut; every joined plan is checked with the forward model; far fewer
    /// states for deep boards, breadth-first where the skills do not allow it).
    #[arg(long, value_name = "SEARCH", default_value = "breadth")]
    search: Search,
    /// Stop each search when its structures outgrow this many GiB (default 4; the paper's
    /// deeper search stopped at about 16 GB). An evaluation also keeps up to half as much of the
    /// successors its searches computed (2 GiB by default), so that a state is computed once.
    #[arg(long, value_name = "GIB", value_parser = clap::value_parser!(u32).range(1..=4096))]
    memory_limit: Option<u32>,
}

impl SearchArgs {
    /// The limits these options set.
    pub fn limits(&self) -> SearchLimits {
        SearchLimits {
            timeout_s: self.timeout,
            max_expanded: Some(usize::try_from(self.max_expanded).unwrap_or(usize::MAX)),
            plan: self.plan,
            search: self.search,
            memory_limit_mib: self.memory_limit.map(|gib| gib as usize * 1024),
        }
    }
}

/// `--boards N` of an evaluation on the standard depths 1–5, as bad input where no evaluation
/// can have it (0 boards, or more tasks than one evaluation may have), before anything is done.
pub fn check_boards(boards: usize) -> Result<()> {
    match seads_planner::TaskSet::standard(boards).problem() {
        Some(problem) => Err(BadInput(anyhow::anyhow!("--boards {boards}: {problem}")).into()),
        None => Ok(()),
    }
}

/// Loads the agent of a run onto `device` (whichever device it trained on), turning a missing or
/// foreign directory into a clear error.
pub fn load_agent(run: &Path, checkpoint: Option<u64>, device: ComputeDevice) -> Result<Agent> {
    let mut config = crate::run_config(run)?;
    // A robot run's skills act on the arm or its twin, which only `seads uarm` builds (issue 82:
    // "unknown environment uarm-lightsout-absolute").
    if seads_uarm::ActionSpace::of_env(&config.env).is_some() {
        bail!(BadInput(anyhow::anyhow!(
            "{} is a robot run ({}): its skills act on the uArm or its twin; evaluate it with \
             `seads uarm evaluate --run {}`",
            run.display(),
            config.env,
            run.display()
        )));
    }
    config.device = crate::usable_device(device)?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    if config.baseline_training().is_ok() {
        bail!(BadInput(anyhow::anyhow!(
            "{} is a {} baseline run: it has no skills to plan with (`seads evaluate --run` \
             measures its policy's task success)",
            run.display(),
            config.algorithm()
        )));
    }
    // A checkpoint that is there but cannot be read or does not fit is a malformed input.
    seads_rl::find_checkpoint(run, checkpoint)
        .and_then(|path| Agent::load_checkpoint(config, &path))
        .map_err(|e| match e {
            seads_rl::RlError::Run(seads_run::RunError::Checkpoint { .. })
            | seads_rl::RlError::Run(seads_run::RunError::Unreadable { .. })
            | seads_rl::RlError::Run(seads_run::RunError::Config(_))
            | seads_rl::RlError::SkillModel(_) => anyhow::Error::from(BadInput(e.into())),
            other => anyhow::Error::from(other),
        })
        .with_context(|| format!("loading the agent of run {}", run.display()))
}
