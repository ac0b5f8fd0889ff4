//! Planning with a trained agent: `seads solve` (one board), `seads evaluate` (task success over
//! many boards) and `seads plan-bench` (the planner's speed on a fitted model).

mod bench;
mod evaluate;
mod evaluation;
mod solve;

use std::path::Path;

use anyhow::{Context, Result, bail};
use seads_rl::{Agent, ComputeDevice};

pub use bench::{PlanBenchArgs, plan_bench};
pub use evaluate::{EvaluateArgs, evaluate_run};
pub use evaluation::{evaluate_checkpoints, run_evaluation};
pub use solve::{SolveArgs, solve_board};

use crate::BadInput;

/// Loads the agent of a run onto `device` (whichever device it trained on), turning a missing or
/// foreign directory into a clear error.
pub fn load_agent(run: &Path, checkpoint: Option<u64>, device: ComputeDevice) -> Result<Agent> {
    let mut config = seads_rl::load_config(run)
        .with_context(|| format!("loading the agent of run {}", run.display()))?;
    config.device = crate::usable_device(device)?;
    crate::kernels::use_kernels(config.portable_numerics)?;
    if config.algorithm != seads_rl::Algorithm::Seads {
        bail!(BadInput(anyhow::anyhow!(
            "{} is a {} baseline run: it has no skills to plan with (`seads evaluate --run` \
             measures its policy's task success)",
            run.display(),
            config.algorithm.name()
        )));
    }
    // A checkpoint that is there but cannot be read or does not fit is a malformed input.
    seads_rl::find_checkpoint(run, checkpoint)
        .and_then(|path| Agent::load_checkpoint(config, &path))
        .map_err(|e| match e {
            seads_rl::RlError::Checkpoint { .. }
            | seads_rl::RlError::Unreadable { .. }
            | seads_rl::RlError::SkillModel(_) => anyhow::Error::from(BadInput(e.into())),
            other => anyhow::Error::from(other),
        })
        .with_context(|| format!("loading the agent of run {}", run.display()))
}
