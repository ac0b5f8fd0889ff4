//! The task evaluation protocol of the paper (SPEC §4.4): boards of exact solution depths from
//! the test split, 20 environment seeds per depth, success with and without re-planning.

use std::collections::BTreeMap;

use seads_embodiment::{EnvConfig, EnvError, SkillPolicy, make_env};
use seads_games::{Successor, SymbolicState};
use serde::{Deserialize, Serialize};

use crate::{Memo, Protocol, SolveConfig, SolveOutcome, TaskSet, solve};

/// One task of an evaluation, as it ended.
#[derive(Debug, Clone, Copy)]
pub struct TaskRecord<'a> {
    /// Its solution depth.
    pub depth: usize,
    /// The environment seed that drew its board.
    pub seed: u64,
    /// The board it started from.
    pub board: SymbolicState,
    /// Tasks of this depth done so far, this one included.
    pub done: usize,
    /// What solving it did.
    pub outcome: &'a SolveOutcome,
}

/// The results of one solution depth.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DepthResult {
    /// Solution depth of the boards.
    pub depth: usize,
    /// Tasks attempted.
    pub tasks: usize,
    /// Tasks solved.
    pub solved: usize,
    /// Tasks whose first search found a plan.
    pub plan_found: usize,
    /// Seconds of search per task.
    pub planning_s: Vec<f64>,
    /// Tasks where a search stopped at the time limit: their outcome depends on the machine.
    #[serde(default)]
    pub timeouts: usize,
    /// Manipulator steps of each solved task.
    pub solution_steps: Vec<usize>,
    /// Manipulator steps of every skill executed in solved tasks.
    pub skill_steps: Vec<usize>,
}

impl DepthResult {
    /// No task yet at `depth`.
    pub fn new(depth: usize) -> Self {
        Self {
            depth,
            tasks: 0,
            solved: 0,
            plan_found: 0,
            planning_s: Vec::new(),
            timeouts: 0,
            solution_steps: Vec::new(),
            skill_steps: Vec::new(),
        }
    }

    /// The share of this depth's tasks that were solved (0 before any task).
    pub fn success_rate(&self) -> f64 {
        self.solved as f64 / self.tasks.max(1) as f64
    }

    /// Counts one more task of this depth, which ended in `outcome`.
    pub fn record(&mut self, outcome: &SolveOutcome) {
        self.count(&TaskSummary::of(outcome));
    }

    /// Counts one more task of this depth, of which `task` is what counts.
    pub fn count(&mut self, task: &TaskSummary) {
        self.tasks += 1;
        self.plan_found += task.plan_found as usize;
        self.planning_s.push(task.planning_s);
        self.timeouts += task.timed_out as usize;
        if task.solved {
            self.solved += 1;
            self.solution_steps.push(task.manipulator_steps);
            self.skill_steps.extend(&task.skill_steps);
        }
    }
}

/// What a finished task adds to its depth's [`DepthResult`]: enough to count it again when an
/// evaluation resumes, without solving it again. Its fields are [`SolveOutcome`]'s of the same
/// names, so that it reads from a task's line with its search time added (other keys are
/// ignored), as a stopped evaluation's `.partial` file holds it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskSummary {
    /// The board reached the goal.
    pub solved: bool,
    /// The first search found a plan.
    pub plan_found: bool,
    /// Seconds spent searching.
    pub planning_s: f64,
    /// A search stopped at the time limit.
    pub timed_out: bool,
    /// Total manipulator steps.
    pub manipulator_steps: usize,
    /// Manipulator steps of every executed skill.
    pub skill_steps: Vec<usize>,
}

impl TaskSummary {
    /// What `outcome` adds to its depth's result.
    pub fn of(outcome: &SolveOutcome) -> Self {
        Self {
            solved: outcome.solved,
            plan_found: outcome.plan_found,
            planning_s: outcome.planning_s,
            timed_out: outcome.timed_out,
            manipulator_steps: outcome.manipulator_steps,
            skill_steps: outcome.skill_steps.clone(),
        }
    }
}

/// What to evaluate on: an environment and the tasks of the protocol.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// Environment name.
    pub env: String,
    /// Environment options (the reset distribution is overridden per depth).
    pub env_config: EnvConfig,
    /// Depths, boards per depth and the split ([`TaskSet::seeds`] gives the boards' seeds).
    pub tasks: TaskSet,
    /// With or without re-planning, search limits.
    pub solve: SolveConfig,
    /// Standard deviation of Gaussian noise on every low-level action, drawn from each task's
    /// seed ([`seads_embodiment::ActionNoise`]); `None`: none.
    pub action_noise: Option<f64>,
}

/// Evaluates `policy` and `successor`: for each depth, boards of exactly that depth from the
/// split, one per seed (seed, reset once, solve). `each` is called with every task as it ends.
pub fn evaluate(
    evaluation: &Evaluation,
    policy: &dyn SkillPolicy,
    successor: &mut dyn Successor,
    each: impl FnMut(&TaskRecord<'_>),
) -> Result<Vec<DepthResult>, EnvError> {
    evaluate_resuming(evaluation, policy, successor, |_, _| None, each)
}

/// [`evaluate`], taking the tasks that `finished` knows (by depth and seed) as they ended
/// before instead of solving them again: an evaluation that was stopped resumes where it
/// stopped, with the same results (each task depends on nothing but its seed). `each` is called
/// with the tasks solved now. The tasks' searches share a [`Memo`] of the successors computed.
pub fn evaluate_resuming(
    evaluation: &Evaluation,
    policy: &dyn SkillPolicy,
    successor: &mut dyn Successor,
    mut finished: impl FnMut(usize, u64) -> Option<TaskSummary>,
    mut each: impl FnMut(&TaskRecord<'_>),
) -> Result<Vec<DepthResult>, EnvError> {
    let mut successor = Memo::new(successor, evaluation.solve.planner.memo_bytes());
    let mut results = Vec::new();
    let seeds = evaluation.tasks.seeds();
    for &depth in &evaluation.tasks.depths {
        let env_config = EnvConfig {
            reset_split: evaluation.tasks.split,
            max_solution_depth: depth,
            random_solution_depth: false,
            ..evaluation.env_config.clone()
        };
        let mut env = make_env(&evaluation.env, &env_config)?;
        if let Some(std) = evaluation.action_noise {
            env = Box::new(seads_embodiment::ActionNoise::new(env, std)?);
        }
        let game = env.spec().game.build(env.spec().board_size)?;
        let goal = game.goal();
        let mut result = DepthResult::new(depth);
        for &seed in &seeds {
            if let Some(task) = finished(depth, seed) {
                result.count(&task);
                continue;
            }
            env.seed(seed);
            env.reset()?;
            let board = env.board();
            let outcome = solve(
                env.as_mut(),
                policy,
                &mut successor,
                goal,
                &evaluation.solve,
            )?;
            result.record(&outcome);
            each(&TaskRecord {
                depth,
                seed,
                board,
                done: result.tasks,
                outcome: &outcome,
            });
        }
        results.push(result);
    }
    Ok(results)
}

/// The machine-readable summary: per depth, success rate, plan-found rate, mean planning
/// seconds, median solution steps and median skill steps (solved tasks only). Keyed by depth as a
/// number, so that depth 10 follows depth 9 (JSON writes the keys as strings, in that order).
#[derive(Debug, Clone, Serialize)]
pub struct EvaluationSummary {
    /// Fraction of tasks solved.
    pub success_rate: BTreeMap<usize, f64>,
    /// Fraction of tasks whose first search found a plan.
    pub plan_found: BTreeMap<usize, f64>,
    /// Mean seconds of search per task.
    pub planning_s: BTreeMap<usize, f64>,
    /// Median manipulator steps of solved tasks.
    pub solution_steps: BTreeMap<usize, Option<f64>>,
    /// Median manipulator steps per skill in solved tasks.
    pub skill_steps: BTreeMap<usize, Option<f64>>,
}

impl EvaluationSummary {
    /// One line per depth under a header: success, plan found, search seconds and the median
    /// steps, as `seads evaluate` prints them.
    pub fn table(&self) -> String {
        let fmt = |v: Option<f64>| v.map_or("-".to_owned(), |x| format!("{x:.1}"));
        let mut out =
            String::from(" depth  success  plan found  search s  median steps  median skill steps");
        for (depth, success) in &self.success_rate {
            out += &format!(
                "\n{depth:>6}  {:>6.0}%  {:>9.0}%  {:>8.3}  {:>12}  {:>18}",
                success * 100.0,
                self.plan_found[depth] * 100.0,
                self.planning_s[depth],
                fmt(self.solution_steps[depth]),
                fmt(self.skill_steps[depth])
            );
        }
        out
    }
}

fn median<T: Copy + Into<f64>>(values: &[T]) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().map(|&x| x.into()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    })
}

/// Summarises per-depth results.
///
/// ```
/// use seads_planner::{DepthResult, summarise};
/// let mut depth2 = DepthResult::new(2);
/// (depth2.tasks, depth2.solved, depth2.plan_found) = (4, 3, 4);
/// depth2.planning_s = vec![0.5, 0.5, 1.0, 2.0];
/// depth2.solution_steps = vec![6, 8, 7];
/// let summary = summarise(&[depth2]);
/// assert_eq!(summary.success_rate[&2], 0.75);
/// assert_eq!(summary.planning_s[&2], 1.0);
/// assert_eq!(summary.solution_steps[&2], Some(7.0), "the median");
/// ```
pub fn summarise(results: &[DepthResult]) -> EvaluationSummary {
    let key = |r: &DepthResult| r.depth;
    let rate = |n: usize, r: &DepthResult| n as f64 / r.tasks.max(1) as f64;
    let to_f64 = |v: &[usize]| v.iter().map(|&x| x as u32).collect::<Vec<u32>>();
    EvaluationSummary {
        success_rate: results
            .iter()
            .map(|r| (key(r), rate(r.solved, r)))
            .collect(),
        plan_found: results
            .iter()
            .map(|r| (key(r), rate(r.plan_found, r)))
            .collect(),
        planning_s: results
            .iter()
            .map(|r| {
                (
                    key(r),
                    r.planning_s.iter().sum::<f64>() / r.tasks.max(1) as f64,
                )
            })
            .collect(),
        solution_steps: results
            .iter()
            .map(|r| (key(r), median(&to_f64(&r.solution_steps))))
            .collect(),
        skill_steps: results
            .iter()
            .map(|r| (key(r), median(&to_f64(&r.skill_steps))))
            .collect(),
    }
}

/// The checkpoint an evaluation evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckpointId {
    /// Its epoch.
    pub epoch: u64,
    /// Environment steps of training when it was written (`None` where the run does not say).
    pub env_steps: Option<u64>,
}

/// A binary that evaluated: the seads version, the commit it was built from, and whether that
/// working tree had uncommitted changes. It decides nothing of the results (the protocol does),
/// so it is recorded beside them, never compared.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Evaluator {
    /// The seads version.
    pub seads: String,
    /// The git commit.
    pub commit: String,
    /// Whether tracked files differed from that commit.
    pub dirty: bool,
}

/// An evaluation file: what was evaluated, how, by which binaries, and the results per depth.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvaluationRecord {
    /// The checkpoint (`None` in files of versions that did not record it).
    pub checkpoint: Option<CheckpointId>,
    /// The protocol (`None` in files of versions that did not record it).
    pub protocol: Option<Protocol>,
    /// The binaries that solved its tasks, in the order they began (more than one where a
    /// stopped evaluation was resumed by another); empty in files written before evaluations
    /// recorded them, or by a library caller that names none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub evaluated_by: Vec<Evaluator>,
    /// Per depth.
    pub results: Vec<DepthResult>,
}

impl EvaluationRecord {
    /// Parses an evaluation file (today's shape only: `seads migrate` rewrites the bare lists of
    /// per-depth results that older versions wrote).
    pub fn from_json(text: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// The file's text (pretty JSON).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("an evaluation record serialises")
    }

    /// The record says it was made with `protocol` (older files say nothing, so never).
    pub fn made_with(&self, protocol: &Protocol) -> bool {
        self.protocol.as_ref() == Some(protocol)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EvaluationKind, SearchLimits};

    #[test]
    fn a_record_round_trips_and_old_bare_lists_still_read() {
        let record = EvaluationRecord {
            checkpoint: Some(CheckpointId {
                epoch: 100,
                env_steps: Some(4_496),
            }),
            protocol: Some(Protocol {
                kind: EvaluationKind::Replan,
                tasks: TaskSet::standard(20),
                limits: Some(SearchLimits {
                    timeout_s: Some(10.0),
                    max_expanded: None,
                    plan: crate::PlanChoice::FirstFound,
                    search: crate::Search::Breadth,
                    memory_limit_mib: None,
                }),
                action_noise: None,
                model: crate::PlanModel::Own,
            }),
            evaluated_by: vec![Evaluator {
                seads: "0.1.0".into(),
                commit: "abc".into(),
                dirty: false,
            }],
            results: vec![DepthResult::new(1)],
        };
        let noisy = Protocol {
            action_noise: Some(0.05),
            ..record.protocol.clone().unwrap()
        };
        // Named by how the protocol departs from the standard one (no state bound, a clock,
        // the first plan found), then the noise and the checkpoint.
        assert_eq!(
            record.protocol.as_ref().unwrap().results_file(Some(7)),
            "evaluation-replan-unbounded-timeout-10s-first-found-epoch-000007.json"
        );
        assert_eq!(
            noisy.results_file(Some(7)),
            "evaluation-replan-unbounded-timeout-10s-first-found-noise-0.05-epoch-000007.json"
        );
        assert_eq!(
            noisy.tasks_file(None),
            "evaluation-replan-unbounded-timeout-10s-first-found-noise-0.05-tasks.jsonl"
        );
        assert!(!record.made_with(&noisy));
        let back = EvaluationRecord::from_json(&record.to_json()).unwrap();
        assert_eq!(back.checkpoint, record.checkpoint);
        assert_eq!(back.evaluated_by, record.evaluated_by);
        assert!(back.made_with(record.protocol.as_ref().unwrap()));
        let other = Protocol {
            tasks: TaskSet::standard(10),
            ..record.protocol.clone().unwrap()
        };
        assert!(!back.made_with(&other));
        // The older bare list is read no more.
        let old = serde_json::to_string(&vec![DepthResult::new(2)]).unwrap();
        assert!(EvaluationRecord::from_json(&old).is_err());
        assert!(EvaluationRecord::from_json("{\"results\": 3}").is_err());
    }
}
