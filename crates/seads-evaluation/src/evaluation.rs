//! Running an evaluation of a trained agent (planning with its skills and forward model) or of
//! a baseline's policy alone, and saving it into the run directory
//! ([`seads_study::evaluation`] names and reads the files).

use std::collections::BTreeMap;
use std::path::Path;

use seads_planner::{
    DepthResult, Evaluation, EvaluationKind, EvaluationRecord, PlanModel, Protocol, SolveConfig,
    TaskRecord, TaskSet, TaskSummary, evaluate_resuming,
};
use seads_rl::{Agent, TrainConfig};
use seads_skillmodel::ForwardModel;
use seads_study::evaluation::journal::Place;
use seads_study::evaluation::{checkpoint_of, keep_another_protocols, save_evaluation, task_line};
use seads_study::{Context as _, Resumed, StudyError};

use crate::Result;

/// Evaluates the agent with `protocol` (a planning kind), calling `each` with every task as it
/// ends (for progress). An evaluation the agent's environment cannot play is
/// [`StudyError::Invalid`].
///
/// It plans with the agent's own forward model; a protocol of a model fitted afterwards needs
/// the run directory that holds it ([`run_evaluation`]) and is [`StudyError::Invalid`] here.
pub fn evaluate_agent(
    agent: &mut Agent,
    protocol: &Protocol,
    each: impl FnMut(&TaskRecord<'_>),
) -> Result<Vec<DepthResult>> {
    if protocol.model == PlanModel::Fitted {
        return Err(StudyError::invalid(
            "planning with a fitted model evaluates a run directory, which holds the model",
        )
        .into());
    }
    evaluate_agent_resuming(agent, protocol, None, |_, _| None, each)
}

/// The model `protocol` plans with where it is not the agent's own: the one fitted to the
/// skills of the agent's checkpoint in `run`.
fn fitted_model(agent: &Agent, run: &Path, protocol: &Protocol) -> Result<Option<ForwardModel>> {
    Ok(match protocol.model {
        PlanModel::Own => None,
        PlanModel::Fitted => Some(agent.fitted_model(run)?.0),
    })
}

/// [`evaluate_agent`] with `fitted`'s model where it is given, counting the tasks `finished`
/// knows (by depth and seed) as they ended before instead of solving them again.
fn evaluate_agent_resuming(
    agent: &mut Agent,
    protocol: &Protocol,
    fitted: Option<ForwardModel>,
    finished: impl FnMut(usize, u64) -> Option<TaskSummary>,
    mut each: impl FnMut(&TaskRecord<'_>),
) -> Result<Vec<DepthResult>> {
    let limits = protocol
        .limits
        .ok_or_else(|| StudyError::failed("a planning evaluation needs search limits"))?;
    let evaluation = Evaluation {
        env: agent.config.env.clone(),
        env_config: agent.config.env_config.clone(),
        tasks: protocol.tasks.clone(),
        solve: SolveConfig {
            replan: protocol.kind == EvaluationKind::Replan,
            planner: limits.planner(),
            ..SolveConfig::default()
        },
        action_noise: protocol.action_noise,
    };
    let mut fitted = fitted;
    let (policy, model): (_, &mut dyn seads_games::Successor) = match fitted.as_mut() {
        Some(model) => (&agent.policy, model),
        None => agent.parts()?,
    };
    evaluate_resuming(&evaluation, policy, model, finished, |task| each(task))
        .map_err(|e| StudyError::Environment(e).into())
}

/// Evaluates the agent with `protocol` and saves the record and one line per task into the run
/// directory (`evaluation-replan.json` and `evaluation-replan-tasks.jsonl` for the standard
/// depths of the latest checkpoint), calling `each` with every task solved now.
///
/// It resumes: each task's line is appended, as the task ends, to the tasks file's `.partial`
/// beside it, headed by the protocol and the checkpoint (`journal.rs`). An evaluation of the
/// same protocol and checkpoint that finds it counts the tasks written there as they ended and
/// solves only the others (a task depends on nothing but its seed, so the results are those of
/// one whole run); the `.partial` file is removed once the record is saved.
pub fn run_evaluation(
    agent: &mut Agent,
    run: &Path,
    protocol: &Protocol,
    mut each: impl FnMut(&TaskRecord<'_>),
) -> Result<EvaluationRecord> {
    let game = seads_study::run_game(&agent.config)?;
    let fitted = fitted_model(agent, run, protocol)?;
    let (checkpoint, named) = checkpoint_of(run, &agent.checkpoint)?;
    // Before any work: an evaluation of another protocol in the way is moved to its own name,
    // or the evaluation is refused with nothing solved.
    keep_another_protocols(run, protocol, named)?;
    let mut journal = Place::new(run, protocol, &checkpoint, named, &[]).open()?;
    let mut now = BTreeMap::new();
    let finished = journal.summaries();
    let results = evaluate_agent_resuming(
        agent,
        protocol,
        fitted,
        |depth, seed| finished.get(&(depth, seed)).cloned(),
        |task| {
            let line = task_line(game.as_ref(), task);
            // The search time is kept for the resumed record only: the tasks file holds what
            // repeats on any machine.
            journal.append(&line, task.outcome.planning_s);
            now.insert((task.depth, task.seed), line);
            each(task);
        },
    )?;
    let mut lines = String::new();
    let seeds = protocol.tasks.seeds();
    for &depth in &protocol.tasks.depths {
        for &seed in &seeds {
            let line = now
                .get(&(depth, seed))
                .or_else(|| journal.earlier(depth, seed).map(|(_, line)| line))
                .ok_or_else(|| StudyError::failed(format!("task {depth}/{seed} has no line")))?;
            lines += &line.to_string();
            lines.push('\n');
        }
    }
    let record = EvaluationRecord {
        checkpoint: Some(checkpoint),
        protocol: Some(protocol.clone()),
        evaluated_by: journal.evaluated_by(),
        results,
    };
    journal.finish(|| save_evaluation(run, &record, named, Some(&lines)))?;
    Ok(record)
}

/// What a stopped evaluation of `protocol` of the agent's checkpoint in `run` left: the tasks it
/// finished, which [`run_evaluation`] counts instead of solving them again, and its damaged
/// journal lines, whose tasks it solves again.
pub fn finished_before(agent: &Agent, run: &Path, protocol: &Protocol) -> Result<Resumed> {
    let (checkpoint, named) = checkpoint_of(run, &agent.checkpoint)?;
    Ok(Place::new(run, protocol, &checkpoint, named, &[]).finished_before()?)
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
        .doing(|| format!("loading the policy of run {}", run.display()))?;
    let game = seads_study::run_game(config)?;
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
            action_noise: None,
            model: seads_planner::PlanModel::Own,
        }),
        evaluated_by: seads_study::provenance::this_binary()
            .into_iter()
            .cloned()
            .collect(),
        results,
    };
    save_evaluation(run, &record, named, Some(&lines))?;
    Ok(record)
}
