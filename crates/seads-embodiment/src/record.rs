//! Recorded episodes (`docs/EPISODES.md`): JSON Lines, one episode per line, and their exact
//! replay.

use seads_games::{MoveId, SymbolicState};
use serde::{Deserialize, Serialize};

use crate::{EnvError, Environment, Push};

/// One step of a recorded episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    /// The action applied.
    pub action: Vec<f32>,
    /// The observation after the step: manipulator state, then z (no remaining-time entry).
    pub obs: Vec<f32>,
    /// The ground-truth game move of the step (SPEC §1 numbering), or null.
    #[serde(rename = "move")]
    pub game_move: Option<MoveId>,
}

/// One recorded episode (a line of the file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeRecord {
    /// Environment name.
    pub env: String,
    /// The first observation: manipulator state, then z.
    pub initial_obs: Vec<f32>,
    /// The steps, in order.
    pub steps: Vec<StepRecord>,
    /// The skill a policy executed, if the episode was recorded with a trained agent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skill: Option<usize>,
}

/// The observation without its remaining-time entry.
fn state_of(env: &dyn Environment) -> Vec<f32> {
    let mut obs = env.observation();
    obs.pop();
    obs
}

/// Records `steps` steps of `env` from a fresh reset, without step limit and without resets after
/// moves; `act(observation, action)` chooses each action. Where the environment supports it, the
/// manipulator is first put into the state its own observation describes (observations are
/// f32), so that a replay from the file starts from exactly the same state.
pub fn record_episode(
    env: &mut dyn Environment,
    steps: usize,
    mut act: impl FnMut(&[f32], &mut [f32]),
) -> Result<EpisodeRecord, EnvError> {
    env.set_step_limit(None);
    env.reset()?;
    let m = env.spec().manipulator_dim;
    let initial = env.observation();
    match env.restore_manipulator(&initial[..m]) {
        Ok(()) | Err(EnvError::Unsupported { .. }) => {}
        Err(e) => return Err(e),
    }
    let initial_obs = state_of(env);
    let mut obs = env.observation();
    let mut action = vec![0.0; env.spec().action_dim];
    // Grows as it goes: a step count too large for memory fails at the limit, not up front.
    let mut records = Vec::with_capacity(steps.min(1 << 16));
    for _ in 0..steps {
        act(&obs, &mut action);
        let outcome = env.step(&action)?;
        env.observe(&mut obs);
        records.push(StepRecord {
            action: action.clone(),
            obs: obs[..obs.len() - 1].to_vec(),
            game_move: move_of(outcome.push),
        });
    }
    Ok(EpisodeRecord {
        env: env.spec().name.clone(),
        initial_obs,
        steps: records,
        skill: None,
    })
}

fn move_of(push: Push) -> Option<MoveId> {
    match push {
        Push::Move(m) => Some(m),
        _ => None,
    }
}

/// Why a record cannot be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The record is inconsistent with the environment.
    #[error("{0}")]
    Invalid(String),
    /// The environment refused (unsupported, non-finite action, …).
    #[error(transparent)]
    Env(#[from] EnvError),
}

/// Puts `env` into the state an episode file's `initial_obs` describes (manipulator state, then
/// the board's bits, no remaining-time entry) and lifts its step limit, as a replay starts. An
/// initial observation of the wrong length or with a board entry other than 0 or 1 is
/// [`ReplayError::Invalid`]; a manipulator that cannot be restored is the environment's error.
pub fn restore_state(env: &mut dyn Environment, initial_obs: &[f32]) -> Result<(), ReplayError> {
    let spec = env.spec();
    let (m, d) = (spec.manipulator_dim, spec.symbolic_len);
    let invalid = |m: String| ReplayError::Invalid(m);
    if initial_obs.len() != m + d {
        return Err(invalid(format!(
            "initial_obs has {} values; {} has {m} manipulator values and {d} board bits",
            initial_obs.len(),
            spec.name
        )));
    }
    if let Some(i) = initial_obs[m..].iter().position(|&b| b != 0.0 && b != 1.0) {
        return Err(invalid(format!(
            "initial_obs board bit {i} is {}, not 0 or 1",
            initial_obs[m + i]
        )));
    }
    env.set_step_limit(None);
    env.restore_manipulator(&initial_obs[..m])?;
    env.set_board(SymbolicState::from_observation(&initial_obs[m..]))
        .map_err(|e| invalid(e.to_string()))
}

/// Puts `env` into `record.initial_obs` and applies the recorded actions in order (no step
/// limit, no reset after moves); returns the episode with observations and moves recomputed.
///
/// ```
/// use seads_embodiment::{EnvConfig, make_env, record_episode, replay_episode};
/// let mut env = make_env("lightsout-reacher", &EnvConfig::default())?;
/// env.seed(2);
/// let mut t = 0.0f32;
/// let recorded = record_episode(env.as_mut(), 30, |_, action| {
///     t += 0.1;
///     action.fill(t.sin());
/// })?;
/// // Another environment replays it step for step, bit for bit.
/// let mut other = make_env("lightsout-reacher", &EnvConfig::default())?;
/// let replayed = replay_episode(other.as_mut(), &recorded).unwrap();
/// assert_eq!(replayed, recorded);
/// # Ok::<(), seads_embodiment::EnvError>(())
/// ```
pub fn replay_episode(
    env: &mut dyn Environment,
    record: &EpisodeRecord,
) -> Result<EpisodeRecord, ReplayError> {
    let spec = env.spec().clone();
    let a = spec.action_dim;
    let invalid = |m: String| ReplayError::Invalid(m);
    if record.env != spec.name {
        return Err(invalid(format!(
            "the episode is of environment {:?}, not {:?}",
            record.env, spec.name
        )));
    }
    for (t, step) in record.steps.iter().enumerate() {
        if step.action.len() != a {
            return Err(invalid(format!(
                "step {t}: the action has {} values, {} takes {a}",
                step.action.len(),
                spec.name
            )));
        }
    }
    restore_state(env, &record.initial_obs)?;
    let mut obs = env.observation();
    let mut steps = Vec::with_capacity(record.steps.len());
    for step in &record.steps {
        let outcome = env.step(&step.action)?;
        env.observe(&mut obs);
        steps.push(StepRecord {
            action: step.action.clone(),
            obs: obs[..obs.len() - 1].to_vec(),
            game_move: move_of(outcome.push),
        });
    }
    Ok(EpisodeRecord {
        env: spec.name,
        initial_obs: record.initial_obs.clone(),
        steps,
        skill: record.skill,
    })
}

/// How a replayed episode differs from its recording.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Comparison {
    /// Largest absolute difference of a manipulator value over all steps.
    pub max_manipulator_deviation: f64,
    /// Steps whose board differs.
    pub board_mismatches: usize,
    /// Steps whose move differs.
    pub move_mismatches: usize,
    /// Steps compared (the shorter of the two episodes).
    pub steps: usize,
}

/// Compares a recorded and a replayed episode (`m` manipulator values per observation).
pub fn compare(recorded: &EpisodeRecord, replayed: &EpisodeRecord, m: usize) -> Comparison {
    let mut c = Comparison::default();
    for (a, b) in recorded.steps.iter().zip(&replayed.steps) {
        c.steps += 1;
        let dev = a.obs[..m.min(a.obs.len())]
            .iter()
            .zip(&b.obs[..m.min(b.obs.len())])
            .map(|(x, y)| (x - y).abs() as f64)
            .fold(0.0, f64::max);
        c.max_manipulator_deviation = c.max_manipulator_deviation.max(dev);
        c.board_mismatches += (a.obs.get(m..) != b.obs.get(m..)) as usize;
        c.move_mismatches += (a.game_move != b.game_move) as usize;
    }
    c
}
