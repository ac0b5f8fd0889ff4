//! Task success of a robot run (`seads uarm train` and `seads uarm evaluate`): the agent solves
//! LightsOut 5×5 boards with re-planning on the arm or its twin.

use std::collections::BTreeMap;
use std::path::Path;

use seads_embodiment::Environment as _;
use seads_games::BoardGame;
use seads_planner::{DepthResult, EvaluationRecord, Protocol, SolveConfig, solve};
use seads_rl::Agent;
use seads_uarm::UarmEnv;

use crate::Result;
use crate::evaluation::{checkpoint_of, save_evaluation};

/// Evaluates the robot run in `run` at `checkpoint` with re-planning on the tasks of depth 1–5
/// with `boards` boards per depth and each search bounded by `limits`, calling `each` after every
/// task.
/// Where the board can be set (`settable`: the twin), it is set to each task's board, the boards
/// a Cursor evaluation plays; the real tablet's boards are whatever the app shows. Results are
/// keyed by the board's solution depth and saved as `evaluation-replan.json` (or
/// `evaluation-replan-epoch-<EPOCH>.json` for an earlier checkpoint).
pub fn evaluate_robot(
    run: &Path,
    checkpoint: &Path,
    mut env: UarmEnv,
    settable: bool,
    boards: usize,
    limits: seads_planner::SearchLimits,
    mut each: impl FnMut(),
) -> Result<EvaluationRecord> {
    // The robot's agent runs on the CPU, wherever it trained.
    let config = seads_rl::TrainConfig {
        device: seads_rl::ComputeDevice::Cpu,
        ..seads_rl::load_config(run)?
    };
    let mut agent = Agent::load_for(config, env.spec().clone(), checkpoint)?;
    let (policy, model) = agent.parts()?;
    let game = seads_uarm::game();
    let protocol = Protocol::planning(true, boards, limits);
    let solve_config = SolveConfig {
        replan: true,
        planner: limits.planner(),
        ..SolveConfig::default()
    };
    let mut results: BTreeMap<usize, DepthResult> = BTreeMap::new();
    // A failure of the arm or the tablet is the run's, not the user's input.
    let env_error = |e| crate::StudyError::Run(seads_rl::RlError::Env(e));
    let seeds = protocol.tasks.seeds();
    for &depth in &protocol.tasks.depths {
        for &seed in &seeds {
            if settable {
                let board = protocol
                    .tasks
                    .board(game.kind(), game.size(), depth, seed)
                    .map_err(env_error)?;
                env.set_board(board).map_err(env_error)?;
            }
            let d = game
                .solution_depth(env.board())
                .and_then(Result::ok)
                .unwrap_or(0);
            let outcome =
                solve(&mut env, policy, model, game.goal(), &solve_config).map_err(env_error)?;
            results
                .entry(d)
                .or_insert_with(|| DepthResult::new(d))
                .record(&outcome);
            each();
        }
    }
    let (id, named) = checkpoint_of(run, checkpoint)?;
    let record = EvaluationRecord {
        checkpoint: Some(id),
        protocol: Some(protocol),
        results: results.into_values().collect(),
    };
    save_evaluation(run, &record, named, None)?;
    Ok(record)
}
