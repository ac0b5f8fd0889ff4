//! Running an evaluation of a trained agent and saving it in its run directory. What an
//! evaluation is (tasks, limits, file names, the record) is `seads_planner`'s protocol module.

use std::path::Path;

use anyhow::{Context, Result, anyhow};
use indicatif::ProgressBar;
use seads_games::BoardGame;
use seads_planner::{
    DepthResult, Evaluation, EvaluationKind, EvaluationRecord, PlannerConfig, Protocol,
    SolveConfig, TaskRecord, TaskSet, evaluate,
};
use seads_rl::{Agent, TrainConfig};

use crate::BadInput;
use seads_study::evaluation::{checkpoint_of, save_evaluation};

/// Evaluates the agent with `protocol` (a planning kind), advancing `bar` by one per task.
pub fn evaluate_agent(
    agent: &mut Agent,
    protocol: &Protocol,
    bar: &ProgressBar,
) -> Result<Vec<DepthResult>> {
    evaluate_agent_with(agent, protocol, bar, |_| {})
}

/// [`evaluate_agent`], calling `each` with every task as it ends.
fn evaluate_agent_with(
    agent: &mut Agent,
    protocol: &Protocol,
    bar: &ProgressBar,
    mut each: impl FnMut(&TaskRecord<'_>),
) -> Result<Vec<DepthResult>> {
    let limits = protocol
        .limits
        .ok_or_else(|| anyhow!("a planning evaluation needs search limits"))?;
    let evaluation = Evaluation {
        env: agent.config.env.clone(),
        env_config: agent.config.env_config.clone(),
        tasks: protocol.tasks.clone(),
        solve: SolveConfig {
            replan: protocol.kind == EvaluationKind::Replan,
            planner: PlannerConfig {
                timeout_s: Some(limits.timeout_s),
                max_expanded: limits.max_expanded,
                ..PlannerConfig::default()
            },
            ..SolveConfig::default()
        },
    };
    let (policy, model) = agent.parts()?;
    evaluate(&evaluation, policy, model, |task| {
        bar.set_message(format!("depth {}", task.depth));
        bar.inc(1);
        each(task);
    })
    .map_err(|e| BadInput(e.into()).into())
}

/// Evaluates the agent with `protocol` and saves the record and one line per task into the run
/// directory (`evaluation-replan.json` and `evaluation-replan-tasks.jsonl` for the standard
/// depths of the latest checkpoint).
pub fn run_evaluation(
    agent: &mut Agent,
    run: &Path,
    protocol: &Protocol,
    quiet: bool,
) -> Result<EvaluationRecord> {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(protocol.tasks.len() as u64)
    };
    let spec = seads_embodiment::make_env(&agent.config.env, &agent.config.env_config)?
        .spec()
        .clone();
    let game = spec.game.build(spec.board_size)?;
    let mut lines = String::new();
    let results = evaluate_agent_with(agent, protocol, &bar, |task| {
        lines += &task_line(game.as_ref(), task).to_string();
        lines.push('\n');
    })?;
    bar.finish_and_clear();
    let (checkpoint, named) = checkpoint_of(run, &agent.checkpoint)?;
    let record = EvaluationRecord {
        checkpoint: Some(checkpoint),
        protocol: Some(protocol.clone()),
        results,
    };
    save_evaluation(run, &record, named, Some(&lines))?;
    Ok(record)
}

/// Evaluates a baseline's policy saved in `checkpoint` alone on `tasks` and saves the record
/// and one line per task (depth, seed, board, solved) into the run directory
/// (`evaluation-policy.json` for the standard depths of the latest checkpoint).
pub fn run_policy_evaluation(
    config: &TrainConfig,
    run: &Path,
    checkpoint: &Path,
    tasks: TaskSet,
) -> Result<EvaluationRecord> {
    let mut policy = seads_rl::load_policy(config, checkpoint)
        .with_context(|| format!("loading the policy of run {}", run.display()))?;
    let game = {
        let env = seads_embodiment::make_env(&config.env, &config.env_config)?;
        env.spec().game.build(env.spec().board_size)?
    };
    let mut lines = String::new();
    let results = seads_rl::task_success(
        config,
        policy.as_mut(),
        &tasks,
        |depth, seed, board, solved| {
            let line = serde_json::json!({
                "depth": depth,
                "seed": seed,
                "board": game.format(board),
                "solved": solved,
            });
            lines += &line.to_string();
            lines.push('\n');
        },
    )?;
    let (id, named) = checkpoint_of(run, checkpoint)?;
    let record = EvaluationRecord {
        checkpoint: Some(id),
        protocol: Some(Protocol {
            kind: EvaluationKind::Policy,
            tasks,
            limits: None,
        }),
        results,
    };
    save_evaluation(run, &record, named, Some(&lines))?;
    Ok(record)
}

/// One line of `evaluation-*-tasks.jsonl`: a task, how it ended, and every skill that left
/// another board than the forward model predicted (boards as `seads solve --board` takes them).
fn task_line(game: &dyn BoardGame, task: &TaskRecord<'_>) -> serde_json::Value {
    let o = task.outcome;
    let deviations: Vec<serde_json::Value> = o
        .deviations
        .iter()
        .map(|d| {
            serde_json::json!({
                "step": d.step,
                "skill": d.skill,
                "before": game.format(d.before),
                "predicted": game.format(d.predicted),
                "reached": game.format(d.reached),
            })
        })
        .collect();
    serde_json::json!({
        "depth": task.depth,
        "seed": task.seed,
        "board": game.format(task.board),
        "solved": o.solved,
        "plan_found": o.plan_found,
        "plans": o.plans,
        "first_plan": o.first_plan,
        "executed": o.executed,
        "skill_steps": o.skill_steps,
        "timed_out": o.timed_out,
        "failure": o.failure,
        "deviations": deviations,
    })
}
