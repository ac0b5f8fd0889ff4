//! The evaluation protocol shared by `seads evaluate`, sweeps, plots and the demo: the tasks
//! (test boards per depth, the authors' seeds), the search limits, and the files an evaluation
//! leaves in a run directory.

use std::path::Path;

use anyhow::Result;
use indicatif::ProgressBar;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_games::{BoardGame, Split};
use seads_planner::{
    DepthResult, EVALUATION_SEEDS, Evaluation, PlannerConfig, SolveConfig, TaskRecord, evaluate,
};
use seads_rl::Agent;

use crate::BadInput;

/// Environment seeds of the tasks: the authors' 20 by default, else drawn from `seed`.
pub fn task_seeds(boards: usize, seed: Option<u64>) -> Vec<u64> {
    match seed {
        None if boards <= EVALUATION_SEEDS.len() => EVALUATION_SEEDS[..boards].to_vec(),
        _ => {
            let mut rng = ChaCha8Rng::seed_from_u64(seed.unwrap_or(4343));
            (0..boards)
                .map(|_| rng.random_range(0..100_000_000))
                .collect()
        }
    }
}

/// How an evaluation acts, as its files in the run directory name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EvaluationKind {
    /// Plan, and plan again after every skill that deviated from the forward model.
    Replan,
    /// Plan once and execute the whole plan.
    PlanOnce,
    /// A baseline's policy acting alone, no planning.
    Policy,
}

impl EvaluationKind {
    /// The planning evaluation, with or without re-planning.
    pub fn planning(replan: bool) -> Self {
        if replan { Self::Replan } else { Self::PlanOnce }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Replan => "replan",
            Self::PlanOnce => "plan-once",
            Self::Policy => "policy",
        }
    }

    /// The stem of this evaluation's files for these depths: `evaluation-replan` for the
    /// standard depths 1–5, which plots and reports read; `evaluation-replan-depths-6-12` for
    /// another range and `evaluation-replan-depths-1_3_5` for a list with gaps, kept beside them
    /// (a list never takes the name of the range it lies in).
    pub fn stem(self, depths: &[usize]) -> String {
        let contiguous = depths.windows(2).all(|w| w[1] == w[0] + 1);
        match (depths.first(), depths.last()) {
            _ if depths == [1, 2, 3, 4, 5] => format!("evaluation-{}", self.name()),
            (Some(a), Some(b)) if contiguous => {
                format!("evaluation-{}-depths-{a}-{b}", self.name())
            }
            _ => {
                let list: Vec<String> = depths.iter().map(usize::to_string).collect();
                format!("evaluation-{}-depths-{}", self.name(), list.join("_"))
            }
        }
    }

    /// The per-depth results of the standard evaluation (`evaluation-replan.json`).
    pub fn results_file(self) -> String {
        format!("evaluation-{}.json", self.name())
    }

    /// Every task of the standard evaluation, one JSON line each
    /// (`evaluation-replan-tasks.jsonl`).
    pub fn tasks_file(self) -> String {
        format!("evaluation-{}-tasks.jsonl", self.name())
    }
}

/// Limits of each search of an evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchLimits {
    /// Seconds per search.
    pub timeout: f64,
    /// States expanded per search (`None`: no bound).
    pub max_expanded: Option<usize>,
}

/// The tasks of an evaluation.
pub struct Tasks {
    /// Solution depths.
    pub depths: Vec<usize>,
    /// Environment seeds (one task per seed and depth).
    pub seeds: Vec<u64>,
    /// Board split.
    pub split: Split,
    /// Re-plan on deviations.
    pub replan: bool,
    /// Limits of each search.
    pub limits: SearchLimits,
}

/// Evaluates the agent on `tasks`, advancing `bar` by one per task.
pub fn evaluate_agent(
    agent: &mut Agent,
    tasks: &Tasks,
    bar: &ProgressBar,
) -> Result<Vec<DepthResult>> {
    evaluate_agent_with(agent, tasks, bar, |_| {})
}

/// [`evaluate_agent`], calling `each` with every task as it ends.
fn evaluate_agent_with(
    agent: &mut Agent,
    tasks: &Tasks,
    bar: &ProgressBar,
    mut each: impl FnMut(&TaskRecord<'_>),
) -> Result<Vec<DepthResult>> {
    let evaluation = Evaluation {
        env: agent.config.env.clone(),
        env_config: agent.config.env_config.clone(),
        depths: tasks.depths.clone(),
        seeds: tasks.seeds.clone(),
        split: tasks.split,
        solve: SolveConfig {
            replan: tasks.replan,
            planner: PlannerConfig {
                timeout_s: Some(tasks.limits.timeout),
                max_expanded: tasks.limits.max_expanded,
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

/// Evaluates the agent and saves the per-depth results into the run directory
/// (`evaluation-replan.json` or `evaluation-plan-once.json`).
pub fn run_evaluation(
    agent: &mut Agent,
    run: &Path,
    tasks: Tasks,
    quiet: bool,
) -> Result<Vec<DepthResult>> {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new((tasks.depths.len() * tasks.seeds.len()) as u64)
    };
    let spec = seads_embodiment::make_env(&agent.config.env, &agent.config.env_config)?
        .spec()
        .clone();
    let game = spec.game.build(spec.board_size)?;
    let mut lines = String::new();
    let results = evaluate_agent_with(agent, &tasks, &bar, |task| {
        lines += &task_line(game.as_ref(), task).to_string();
        lines.push('\n');
    })?;
    bar.finish_and_clear();
    let stem = EvaluationKind::planning(tasks.replan).stem(&tasks.depths);
    seads_rl::write_atomic(
        &run.join(format!("{stem}.json")),
        serde_json::to_string_pretty(&results)?.as_bytes(),
    )?;
    seads_rl::write_atomic(&run.join(format!("{stem}-tasks.jsonl")), lines.as_bytes())?;
    Ok(results)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evaluation_files_name_the_standard_depths_plainly_and_other_studies_by_their_depths() {
        let replan = EvaluationKind::planning(true);
        assert_eq!(replan.stem(&[1, 2, 3, 4, 5]), "evaluation-replan");
        assert_eq!(
            EvaluationKind::planning(false).stem(&[6, 7, 8, 9, 10, 11, 12]),
            "evaluation-plan-once-depths-6-12"
        );
        assert_eq!(
            EvaluationKind::Policy.stem(&[1, 2, 3]),
            "evaluation-policy-depths-1-3"
        );
        assert_eq!(
            replan.stem(&[1, 3, 5]),
            "evaluation-replan-depths-1_3_5",
            "a list with gaps must not overwrite the files of its range"
        );
        assert_eq!(replan.stem(&[7]), "evaluation-replan-depths-7-7");
        assert_eq!(replan.results_file(), "evaluation-replan.json");
        assert_eq!(replan.tasks_file(), "evaluation-replan-tasks.jsonl");
        assert_eq!(
            EvaluationKind::Policy.results_file(),
            "evaluation-policy.json"
        );
    }
}
