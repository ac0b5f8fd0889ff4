//! Executing plans with the skill policy: Algorithm 1 (plan once) and Algorithm 2 (re-plan
//! when the observed symbolic state differs from the prediction), SPEC §4.3.

use std::time::Instant;

use seads_embodiment::{EnvError, Environment, SkillPolicy, SkillRun, execute_skill};
use seads_games::{Successor, SymbolicState};
use serde::{Deserialize, Serialize};

use crate::{PlanChoice, PlanError, PlannerConfig, find_plan};

/// How a task is solved. `Default` = with re-planning, at most 10 plans (the reference).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolveConfig {
    /// Re-plan when the board deviates from the prediction (Algorithm 2).
    pub replan: bool,
    /// Most plans (searches) per task with re-planning.
    pub max_plans: usize,
    /// Search limits.
    pub planner: PlannerConfig,
}

impl Default for SolveConfig {
    fn default() -> Self {
        Self {
            replan: true,
            max_plans: 10,
            planner: PlannerConfig::default(),
        }
    }
}

/// What happened while solving one task.
#[derive(Debug, Clone, Serialize)]
pub struct SolveOutcome {
    /// The board reached the goal.
    pub solved: bool,
    /// The first search found a plan.
    pub plan_found: bool,
    /// The first plan.
    pub first_plan: Vec<usize>,
    /// Searches run.
    pub plans: usize,
    /// Skills executed, in order.
    pub executed: Vec<usize>,
    /// Manipulator steps of every executed skill.
    pub skill_steps: Vec<usize>,
    /// Total manipulator steps.
    pub manipulator_steps: usize,
    /// Seconds spent searching.
    pub planning_s: f64,
    /// A search stopped at the time limit (the outcome may differ on a faster machine).
    pub timed_out: bool,
    /// Why the task failed, if it did.
    pub failure: Option<String>,
    /// Every executed skill that left another board than the forward model predicted.
    pub deviations: Vec<Deviation>,
    /// What each executed skill did (manipulator path and pushes), for figures.
    #[serde(skip)]
    pub runs: Vec<SkillRun>,
}

/// An executed skill whose board differs from the plan's prediction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Deviation {
    /// Its index among the executed skills.
    pub step: usize,
    /// The skill.
    pub skill: usize,
    /// The board before it ran.
    pub before: SymbolicState,
    /// The board the plan predicted after it.
    pub predicted: SymbolicState,
    /// The board it left.
    pub reached: SymbolicState,
}

/// Solves the task in `env` (its current board towards `goal`) with `policy`, planning with
/// `successor`. Raising `config.planner.interrupt` stops it: a search at its next check, the
/// execution before the next skill (the outcome then says why).
pub fn solve(
    env: &mut dyn Environment,
    policy: &dyn SkillPolicy,
    successor: &mut dyn Successor,
    goal: SymbolicState,
    config: &SolveConfig,
) -> Result<SolveOutcome, EnvError> {
    let mut outcome = SolveOutcome {
        solved: false,
        plan_found: false,
        first_plan: Vec::new(),
        plans: 0,
        executed: Vec::new(),
        skill_steps: Vec::new(),
        manipulator_steps: 0,
        planning_s: 0.0,
        timed_out: false,
        failure: None,
        deviations: Vec::new(),
        runs: Vec::new(),
    };
    // A solved board needs no skill (the search tests the goal on the boards it generates, so it
    // would plan at least one).
    if env.board() == goal {
        outcome.solved = true;
        outcome.plan_found = true;
        return Ok(outcome);
    }
    let mut plan = match search(env.board(), successor, goal, config, &mut outcome) {
        Ok(plan) => plan,
        Err(e) => {
            outcome.failure = Some(e.to_string());
            return Ok(outcome);
        }
    };
    outcome.plan_found = true;
    outcome.first_plan = plan.skills.clone();
    if !config.replan {
        // Algorithm 1: execute the whole plan; only the final board counts.
        for (&skill, &predicted) in plan.skills.iter().zip(&plan.predicted) {
            if interrupted(config, &mut outcome) {
                return Ok(outcome);
            }
            run(env, policy, skill, predicted, &mut outcome)?;
        }
        outcome.solved = env.board() == goal;
        if !outcome.solved {
            outcome.failure = Some("the board differs from the goal after the plan".into());
        }
        return Ok(outcome);
    }
    // Algorithm 2: execute skill by skill, re-planning on a deviation from the prediction.
    let mut step = 0;
    loop {
        if interrupted(config, &mut outcome) {
            return Ok(outcome);
        }
        run(
            env,
            policy,
            plan.skills[step],
            plan.predicted[step],
            &mut outcome,
        )?;
        let board = env.board();
        if board == goal {
            outcome.solved = true;
            return Ok(outcome);
        }
        step += 1;
        if board != plan.predicted[step - 1] || step == plan.skills.len() {
            if outcome.plans >= config.max_plans {
                outcome.failure = Some(format!("not solved after {} plans", outcome.plans));
                return Ok(outcome);
            }
            plan = match search(board, successor, goal, config, &mut outcome) {
                Ok(plan) => plan,
                Err(e) => {
                    outcome.failure = Some(e.to_string());
                    return Ok(outcome);
                }
            };
            step = 0;
        }
    }
}

/// Plans from `start`. With [`PlanChoice::MostLikely`], the skills that deviated in this task
/// (`outcome.deviations`) are not taken again from the board they deviated from, unless no plan
/// is left without them; with [`PlanChoice::MostLikelyWary`], before that, the skills that
/// deviated twice are not taken from any board, unless no plan is left without them.
fn search(
    start: SymbolicState,
    successor: &mut dyn Successor,
    goal: SymbolicState,
    config: &SolveConfig,
    outcome: &mut SolveOutcome,
) -> Result<crate::Plan, PlanError> {
    let began = Instant::now();
    outcome.plans += 1;
    let plan = config.planner.plan;
    let pairs: Vec<(SymbolicState, usize)> = match plan {
        PlanChoice::MostLikely | PlanChoice::MostLikelyWary => outcome
            .deviations
            .iter()
            .map(|d| (d.before, d.skill))
            .collect(),
        PlanChoice::FirstFound => Vec::new(),
    };
    let mut skills: Vec<usize> = Vec::new();
    if plan == PlanChoice::MostLikelyWary {
        let mut failures = std::collections::BTreeMap::new();
        for d in &outcome.deviations {
            *failures.entry(d.skill).or_insert(0) += 1;
        }
        skills.extend(
            failures
                .into_iter()
                .filter(|&(_, n)| n >= 2)
                .map(|(k, _)| k),
        );
    }
    // Each try lifts one restriction: the skills failed twice, then each failed skill from its
    // board, then (below) nothing.
    let everywhere = (!skills.is_empty()).then_some((&skills[..], &pairs[..]));
    let from_boards = (!pairs.is_empty()).then_some((&[][..], &pairs[..]));
    let mut result = None;
    for (skills, failed) in everywhere.into_iter().chain(from_boards) {
        let mut avoiding = Avoiding {
            inner: &mut *successor,
            skills,
            failed,
        };
        let plan = find_plan(&mut avoiding, start, goal, &config.planner);
        outcome.timed_out |= matches!(plan, Err(PlanError::Timeout { .. }));
        if plan.is_ok() {
            result = Some(plan);
            break;
        }
    }
    let result = result.unwrap_or_else(|| {
        let plan = find_plan(successor, start, goal, &config.planner);
        outcome.timed_out |= matches!(plan, Err(PlanError::Timeout { .. }));
        plan
    });
    outcome.planning_s += began.elapsed().as_secs_f64();
    result
}

/// A successor function in which the skills that failed (`skills` from every board, `failed`
/// from one board each) lead nowhere (back to the board itself, which the search has seen), so
/// that a search takes them only where they are not avoided.
struct Avoiding<'a> {
    inner: &'a mut dyn Successor,
    skills: &'a [usize],
    failed: &'a [(SymbolicState, usize)],
}

impl Successor for Avoiding<'_> {
    fn num_skills(&self) -> usize {
        self.inner.num_skills()
    }

    fn symbolic_len(&self) -> usize {
        self.inner.symbolic_len()
    }

    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        let (base, k) = (out.len(), self.inner.num_skills());
        self.inner.successors(states, out);
        for (i, &z) in states.iter().enumerate() {
            let row = base + i * k;
            for &skill in self.skills {
                if skill < k {
                    out[row + skill] = z;
                }
            }
            for &(board, skill) in self.failed {
                if board == z && skill < k {
                    out[row + skill] = z;
                }
            }
        }
    }

    fn preferred_batch(&self) -> usize {
        self.inner.preferred_batch()
    }

    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        self.inner.log_likelihoods(steps)
    }
}

/// Whether the solve was interrupted; if so, the outcome says so.
fn interrupted(config: &SolveConfig, outcome: &mut SolveOutcome) -> bool {
    let raised = config.planner.interrupt.is_raised();
    if raised {
        outcome.failure = Some(PlanError::Interrupted.to_string());
    }
    raised
}

/// Executes `skill`, recording a deviation when the board it leaves is not `predicted`.
fn run(
    env: &mut dyn Environment,
    policy: &dyn SkillPolicy,
    skill: usize,
    predicted: SymbolicState,
    outcome: &mut SolveOutcome,
) -> Result<(), EnvError> {
    let before = env.board();
    let r = execute_skill(env, policy, skill)?;
    let reached = env.board();
    if reached != predicted {
        outcome.deviations.push(Deviation {
            step: outcome.executed.len(),
            skill,
            before,
            predicted,
            reached,
        });
    }
    outcome.executed.push(skill);
    outcome.skill_steps.push(r.steps);
    outcome.manipulator_steps += r.steps;
    outcome.runs.push(r);
    Ok(())
}
