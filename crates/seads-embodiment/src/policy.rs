//! `SkillPolicy`: what executes a skill, seen from the environments' side (the planner runs
//! plans through it without knowing how the policy is implemented).

use crate::{EnvError, Environment, StepOutcome};

/// A skill-conditioned low-level policy π(a | s, k).
pub trait SkillPolicy {
    /// Number of skills K.
    fn num_skills(&self) -> usize;
    /// Deterministic actions (the evaluation mode) for a batch: row i of `observations` executes
    /// skill `skills[i]`; the actions are written row-wise into `actions`.
    fn act(&self, observations: &[f32], skills: &[usize], actions: &mut [f32]);
}

/// What one skill execution did.
#[derive(Debug, Clone, PartialEq)]
pub struct SkillRun {
    /// Steps taken.
    pub steps: usize,
    /// The last step's outcome (a move, a miss or a time-out).
    pub outcome: StepOutcome,
    /// End-effector positions (board coordinates) before the first step and after every step;
    /// after the step of a move, where the move was made (a Jaco re-initialises its arm within
    /// that step, and the path ends where it touched the board: [`Environment::move_point`]).
    pub path: Vec<[f64; 2]>,
    /// Steps at which a push happened (a move or a miss), as indices into `path`.
    pub pushes: Vec<usize>,
}

/// Runs skill `skill` deterministically on `env` from where it stands until the skill ends
/// (a move or the step limit, which must be set). The step counter is reset first, the
/// environment is not.
pub fn execute_skill(
    env: &mut dyn Environment,
    policy: &dyn SkillPolicy,
    skill: usize,
) -> Result<SkillRun, EnvError> {
    env.reset_step_counter();
    let spec = env.spec().clone();
    let mut obs = env.observation();
    let mut action = vec![0.0; spec.action_dim];
    let mut run = SkillRun {
        steps: 0,
        outcome: StepOutcome::default(),
        path: vec![env.end_effector()],
        pushes: Vec::new(),
    };
    let Some(limit) = spec.step_limit else {
        return Err(EnvError::InvalidConfig(
            "executing a skill needs a step limit".into(),
        ));
    };
    while run.steps < limit {
        policy.act(&obs, &[skill], &mut action);
        run.outcome = env.step(&action)?;
        run.steps += 1;
        env.observe(&mut obs);
        // A Jaco re-initialises its arm within the step of a move: the path ends at the push.
        run.path
            .push(env.move_point().unwrap_or_else(|| env.end_effector()));
        if run.outcome.push != crate::Push::None {
            run.pushes.push(run.steps);
        }
        if run.outcome.done() {
            break;
        }
    }
    Ok(run)
}
