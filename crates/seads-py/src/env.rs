//! One environment: the Rust core shared by [`Env`] and the vector environment, in either of
//! two modes. Skill mode is what SEADS's skills see: an episode ends with the first game move
//! (terminated) or at the skill's step limit (truncated), and the reward is 0 (the environments
//! are reward-free). Task mode is the flat baselines' setting: a board of solution depth S,
//! reward 1 on the step that solves it, at most T_max·S steps.

use numpy::{PyArray1, PyArray3, PyReadonlyArray1};
use pyo3::prelude::*;
use seads_embodiment::{EnvConfig, EnvError, EnvSpec, Environment, TaskEnv, make_env};
use seads_games::BoardGame;

use crate::value_error;

/// An environment in skill or task mode.
pub(crate) enum Core {
    /// Skill mode.
    Skill(Box<dyn Environment>),
    /// Task mode.
    Task(Box<TaskEnv>),
}

/// What one step did, as Gymnasium reports it.
#[derive(Clone, Copy, Default)]
pub(crate) struct Stepped {
    pub reward: f32,
    pub terminated: bool,
    pub truncated: bool,
    /// The game move made, −1 for none.
    pub game_move: i64,
}

/// The environment options from their JSON text (`EnvConfig`'s fields; unknown ones are an
/// error naming them).
pub(crate) fn parse_options(options: Option<&str>) -> PyResult<EnvConfig> {
    let config: EnvConfig = match options {
        None => EnvConfig::default(),
        Some(text) => {
            serde_json::from_str(text).map_err(|e| value_error(format!("options: {e}")))?
        }
    };
    config.validate().map_err(value_error)?;
    Ok(config)
}

impl Core {
    /// Builds `name` with `config`, in task mode when `task` is set.
    pub fn new(name: &str, config: &EnvConfig, task: bool) -> Result<Self, EnvError> {
        let env = make_env(name, config)?;
        Ok(if task {
            Core::Task(Box::new(TaskEnv::new(env, config.max_solution_depth)?))
        } else {
            Core::Skill(env)
        })
    }

    /// The wrapped environment.
    pub fn env(&self) -> &dyn Environment {
        match self {
            Core::Skill(env) => env.as_ref(),
            Core::Task(task) => task.env(),
        }
    }

    /// Its specification.
    pub fn spec(&self) -> &EnvSpec {
        self.env().spec()
    }

    /// Re-seeds its random streams.
    pub fn seed(&mut self, seed: u64) {
        match self {
            Core::Skill(env) => env.seed(seed),
            Core::Task(task) => task.seed(seed),
        }
    }

    /// Starts an episode.
    pub fn reset(&mut self) -> Result<(), EnvError> {
        match self {
            Core::Skill(env) => env.reset(),
            Core::Task(task) => task.reset().map(|_| ()),
        }
    }

    /// One step with an action of `spec().action_dim` finite values.
    pub fn step(&mut self, action: &[f32]) -> Result<Stepped, EnvError> {
        Ok(match self {
            Core::Skill(env) => {
                let outcome = env.step(action)?;
                Stepped {
                    reward: 0.0,
                    terminated: outcome.moved(),
                    truncated: outcome.truncated && !outcome.moved(),
                    game_move: outcome.game_move().map_or(-1, |m| m as i64),
                }
            }
            Core::Task(task) => {
                let step = task.step(action)?;
                Stepped {
                    reward: step.reward,
                    terminated: step.solved,
                    truncated: step.done && !step.solved,
                    game_move: step.game_move.map_or(-1, |m| m as i64),
                }
            }
        })
    }

    /// Writes the observation.
    pub fn observe(&self, out: &mut [f32]) {
        self.env().observe(out);
    }

    /// Its board game.
    pub fn game(&self) -> Result<Box<dyn BoardGame>, seads_games::GameError> {
        let spec = self.spec();
        spec.game.build(spec.board_size)
    }

    /// The task's solution depth S (task mode only).
    pub fn depth(&self) -> Option<usize> {
        match self {
            Core::Skill(_) => None,
            Core::Task(task) => Some(task.depth()),
        }
    }
}

/// One environment, the core of `seads.SeadsEnv` (use that: it is a Gymnasium environment).
#[pyclass(module = "seads._seads")]
pub struct Env {
    core: Core,
    /// The options it was built with.
    config: EnvConfig,
    /// The board game, for the board's values (built once, not per step).
    game: Box<dyn BoardGame>,
}

impl Env {
    /// The options the environment was built with.
    pub(crate) fn config(&self) -> &EnvConfig {
        &self.config
    }

    /// The environment in skill mode, for executing skills (`None` in task mode).
    pub(crate) fn skill_env(&mut self) -> Option<&mut Box<dyn Environment>> {
        match &mut self.core {
            Core::Skill(env) => Some(env),
            Core::Task(_) => None,
        }
    }
}

#[pymethods]
impl Env {
    /// `Env(name, options=None, task=False)`: the environment `name` (see `env_names()`),
    /// `options` the JSON text of its options (`max_solution_depth`, `reset_split`, …), in task
    /// mode when `task`.
    #[new]
    #[pyo3(signature = (name, options=None, task=false))]
    fn new(name: &str, options: Option<&str>, task: bool) -> PyResult<Self> {
        crate::guarded(|| {
            let config = parse_options(options)?;
            let core = Core::new(name, &config, task).map_err(value_error)?;
            let game = core.game().map_err(value_error)?;
            Ok(Self { core, game, config })
        })
    }

    /// The environment's specification as a dict (name, game, board_size, obs_dim, action_dim,
    /// action_low, action_high, symbolic_len, manipulator_dim, state_low, state_high (the
    /// manipulator state's bounds, ±inf where unbounded), num_moves, step_limit).
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::guarded(|| spec_dict(py, self.core.spec()))
    }

    /// Re-seeds the board's and the manipulator's random streams.
    fn seed(&mut self, seed: u64) {
        self.core.seed(seed);
    }

    /// Starts an episode; returns the observation.
    fn reset<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f32>>> {
        crate::guarded(|| {
            self.core.reset().map_err(value_error)?;
            Ok(self.observation(py))
        })
    }

    /// One step: `(observation, reward, terminated, truncated, move)`, `move` being the game
    /// move made (−1 for none). A wrong action length or a non-finite value is a `ValueError`.
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: PyReadonlyArray1<'py, f32>,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, f32, bool, bool, i64)> {
        crate::guarded(|| {
            let action = action.as_slice().map_err(value_error)?;
            let s = self.core.step(action).map_err(value_error)?;
            Ok((
                self.observation(py),
                s.reward,
                s.terminated,
                s.truncated,
                s.game_move,
            ))
        })
    }

    /// The current observation `[manipulator state, board bits, remaining time]`.
    fn observation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f32>> {
        let mut obs = vec![0.0; self.core.spec().obs_dim];
        self.core.observe(&mut obs);
        PyArray1::from_vec(py, obs)
    }

    /// The board's values (LightsOut: 0/1 per field; TileSwap: the tile on each field),
    /// row-major.
    fn board<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u8>> {
        PyArray1::from_vec(py, self.game.values(self.core.env().board()))
    }

    /// Puts the environment into the state an episode file's `initial_obs` describes
    /// (manipulator state, then the board's bits) and lifts the step limit, as `seads replay`
    /// does: the recorded actions then give the recorded observations (skill mode only).
    fn set_state(&mut self, state: PyReadonlyArray1<'_, f32>) -> PyResult<()> {
        crate::guarded(|| {
            let state = state.as_slice().map_err(value_error)?;
            let Core::Skill(env) = &mut self.core else {
                return Err(value_error("set_state is for skill mode, not task mode"));
            };
            seads_embodiment::restore_state(env.as_mut(), state).map_err(value_error)
        })
    }

    /// The task's solution depth S (`None` in skill mode).
    fn depth(&self) -> Option<usize> {
        self.core.depth()
    }

    /// A top view as an RGB image of `size` × `size` pixels.
    #[pyo3(signature = (size=256))]
    fn render<'py>(&self, py: Python<'py>, size: usize) -> PyResult<Bound<'py, PyArray3<u8>>> {
        crate::guarded(|| crate::render::image(py, self.core.env(), size))
    }
}

/// An environment's specification as a Python dict.
pub(crate) fn spec_dict<'py>(
    py: Python<'py>,
    spec: &EnvSpec,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let d = pyo3::types::PyDict::new(py);
    d.set_item("name", &spec.name)?;
    d.set_item("game", spec.game.name())?;
    d.set_item("board_size", spec.board_size)?;
    d.set_item("obs_dim", spec.obs_dim)?;
    d.set_item("action_dim", spec.action_dim)?;
    d.set_item("action_low", spec.action_low.clone())?;
    d.set_item("action_high", spec.action_high.clone())?;
    d.set_item("manipulator_dim", spec.manipulator_dim)?;
    d.set_item("state_low", spec.state_low.clone())?;
    d.set_item("state_high", spec.state_high.clone())?;
    d.set_item("symbolic_len", spec.symbolic_len)?;
    d.set_item("num_moves", spec.num_skills)?;
    d.set_item("step_limit", spec.step_limit)?;
    Ok(d)
}
