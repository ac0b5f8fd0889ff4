//! A trained SEADS agent from its run directory (`seads-infer`, no libtorch): actions,
//! the forward model's successors, plans, and solving a board in an environment.

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, Push, make_env};
use seads_games::{BoardGame, Successor, SymbolicState};
use seads_planner::{PlanChoice, PlannerConfig, Search, SolveConfig, find_plan};

use crate::env::Env;
use crate::value_error;

/// A trained agent: its skill policy and forward model.
#[pyclass(module = "seads._seads")]
pub struct Agent {
    inner: seads_infer::Agent,
    game: Box<dyn BoardGame + Send + Sync>,
    obs_dim: usize,
    action_dim: usize,
}

/// The planner's settings from the Python arguments.
fn planner(
    max_depth: usize,
    max_expanded: Option<usize>,
    search: &str,
    choice: &str,
) -> PyResult<PlannerConfig> {
    let search: Search = search
        .parse()
        .map_err(|e| value_error(format!("search {e}")))?;
    let plan: PlanChoice = choice
        .parse()
        .map_err(|e| value_error(format!("choice {e}")))?;
    Ok(PlannerConfig {
        max_layers: max_depth,
        max_expanded,
        search,
        plan,
        ..PlannerConfig::default()
    })
}

impl Agent {
    fn board(&self, values: &[u8]) -> PyResult<SymbolicState> {
        if values.len() != self.game.symbolic_len() {
            return Err(value_error(format!(
                "a board of {} values; this agent's game has {}",
                values.len(),
                self.game.symbolic_len()
            )));
        }
        self.game.board_from_values(values).map_err(value_error)
    }
}

#[pymethods]
impl Agent {
    /// `Agent.load(run_dir, checkpoint=None)`: the agent of a run directory, at its latest
    /// checkpoint or the one of epoch `checkpoint`.
    #[staticmethod]
    #[pyo3(signature = (run_dir, checkpoint=None))]
    fn load(py: Python<'_>, run_dir: PathBuf, checkpoint: Option<u64>) -> PyResult<Self> {
        let inner = py
            .detach(|| seads_infer::Agent::load(&run_dir, checkpoint))
            .map_err(value_error)?;
        let env = make_env(&inner.env, &EnvConfig::default()).map_err(value_error)?;
        let spec = env.spec();
        let game = spec.game.build(spec.board_size).map_err(value_error)?;
        Ok(Self {
            obs_dim: spec.obs_dim,
            action_dim: spec.action_dim,
            inner,
            game,
        })
    }

    /// The environment the agent was trained on.
    #[getter]
    fn env(&self) -> String {
        self.inner.env.clone()
    }

    /// The checkpoint's epoch.
    #[getter]
    fn epoch(&self) -> u64 {
        self.inner.epoch
    }

    /// The number of skills K.
    #[getter]
    fn num_skills(&self) -> usize {
        self.inner.model.num_skills()
    }

    /// `act(obs, skill, deterministic=True, seed=None)`: actions for observations (one, or
    /// rows of a 2-D array) executing `skill` (one for all rows, or one per row): the policy's
    /// deterministic action, or a sample drawn from `seed`.
    #[pyo3(signature = (obs, skill, deterministic=true, seed=None))]
    fn act<'py>(
        &self,
        py: Python<'py>,
        obs: PyReadonlyArrayDyn<'py, f32>,
        skill: &Bound<'py, PyAny>,
        deterministic: bool,
        seed: Option<u64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let shape = obs.shape().to_vec();
        let rows = match shape[..] {
            [n] if n == self.obs_dim => 1,
            [rows, n] if n == self.obs_dim => rows,
            _ => {
                return Err(value_error(format!(
                    "observations of shape {shape:?}: ({}) or (rows, {})",
                    self.obs_dim, self.obs_dim
                )));
            }
        };
        let skills: Vec<usize> = match skill.extract::<usize>() {
            Ok(k) => vec![k; rows],
            Err(_) => skill.extract::<Vec<usize>>().map_err(|_| {
                value_error("skill: a non-negative whole number or one per observation row")
            })?,
        };
        if skills.len() != rows {
            return Err(value_error(format!(
                "{} skills for {rows} observation rows",
                skills.len()
            )));
        }
        let values: Vec<f32> = obs.as_array().iter().copied().collect();
        let policy = &self.inner.policy;
        let actions = match (deterministic, seed) {
            (true, _) => policy.actions::<ChaCha8Rng>(&values, &skills, None),
            (false, Some(seed)) => {
                policy.actions(&values, &skills, Some(&mut ChaCha8Rng::seed_from_u64(seed)))
            }
            (false, None) => {
                return Err(value_error(
                    "a sampled action needs a seed (act(..., deterministic=False, seed=S))",
                ));
            }
        }
        .map_err(value_error)?;
        if shape.len() == 1 {
            Ok(PyArray1::from_vec(py, actions).into_any())
        } else {
            let array = PyArray1::from_vec(py, actions);
            Ok(array.reshape([rows, self.action_dim])?.into_any())
        }
    }

    /// `successors(board)`: the board the forward model predicts after each skill (K rows of
    /// the board's values).
    fn successors<'py>(
        &mut self,
        py: Python<'py>,
        board: Vec<u8>,
    ) -> PyResult<Bound<'py, PyArray2<u8>>> {
        let z = self.board(&board)?;
        let mut next = Vec::new();
        self.inner.model.successors(&[z], &mut next);
        let rows: Vec<Vec<u8>> = next.iter().map(|&b| self.game.values(b)).collect();
        PyArray2::from_vec2(py, &rows).map_err(value_error)
    }

    /// `plan(board, goal=None, max_depth=20, max_expanded=4194304, search="breadth",
    /// choice="most-likely")`: the skills of a plan the forward model predicts to reach the goal
    /// (the solved board unless given); `[]` on the goal; a `ValueError` if none is found.
    #[pyo3(signature = (board, goal=None, max_depth=20, max_expanded=Some(seads_planner::DEFAULT_MAX_EXPANDED), search="breadth", choice="most-likely"))]
    #[allow(clippy::too_many_arguments)]
    fn plan(
        &mut self,
        py: Python<'_>,
        board: Vec<u8>,
        goal: Option<Vec<u8>>,
        max_depth: usize,
        max_expanded: Option<usize>,
        search: &str,
        choice: &str,
    ) -> PyResult<Vec<usize>> {
        let start = self.board(&board)?;
        let goal = match goal {
            Some(values) => self.board(&values)?,
            None => self.game.goal(),
        };
        if start == goal {
            return Ok(Vec::new());
        }
        let config = planner(max_depth, max_expanded, search, choice)?;
        let model = &mut self.inner.model;
        py.detach(|| find_plan(model, start, goal, &config))
            .map(|plan| plan.skills)
            .map_err(value_error)
    }

    /// `solve(env, board=None, replan=True, max_expanded=4194304, search="breadth",
    /// choice="most-likely")`: plans from the environment's board (or sets `board` first) and
    /// executes the plan's skills in it, re-planning after a skill that left another board than
    /// predicted. `env` is a ``seads`` Gymnasium environment (or its ``_seads.Env``) of the
    /// agent's kind, in skill mode. Returns a dict: solved, skills (executed), moves (the game
    /// move each made, −1 for none), path (the manipulator's positions), steps, plans, failure.
    #[pyo3(signature = (env, board=None, replan=true, max_expanded=Some(seads_planner::DEFAULT_MAX_EXPANDED), search="breadth", choice="most-likely"))]
    #[allow(clippy::too_many_arguments)]
    fn solve<'py>(
        &mut self,
        py: Python<'py>,
        env: &Bound<'py, PyAny>,
        board: Option<Vec<u8>>,
        replan: bool,
        max_expanded: Option<usize>,
        search: &str,
        choice: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        let core = match env.cast::<Env>() {
            Ok(core) => core.clone(),
            Err(_) => env
                .getattr("unwrapped")
                .and_then(|u| u.getattr("_core"))
                .and_then(|c| Ok(c.cast_into::<Env>()?))
                .map_err(|_| {
                    value_error("env: a seads environment (gymnasium.make(\"seads/…\"))")
                })?,
        };
        let mut core = core.borrow_mut();
        let start = match board {
            Some(values) => Some(self.board(&values)?),
            None => None,
        };
        let config = SolveConfig {
            replan,
            planner: planner(20, max_expanded, search, choice)?,
            ..SolveConfig::default()
        };
        let agent_env = self.inner.env.clone();
        let goal = self.game.goal();
        let environment = core.skill_env().ok_or_else(|| {
            value_error("env: an environment in task mode; the agent needs skill mode")
        })?;
        if environment.spec().name != agent_env {
            return Err(value_error(format!(
                "env: a {} environment; the agent was trained on {agent_env}",
                environment.spec().name
            )));
        }
        if let Some(start) = start {
            environment.set_board(start).map_err(value_error)?;
        }
        let (policy, model) = (&self.inner.policy, &mut self.inner.model);
        let outcome =
            seads_planner::solve(environment, policy, model, goal, &config).map_err(value_error)?;
        let result = PyDict::new(py);
        result.set_item("solved", outcome.solved)?;
        result.set_item("skills", outcome.executed.clone())?;
        let moves: Vec<i64> = outcome
            .runs
            .iter()
            .map(|r| match r.outcome.push {
                Push::Move(m) => m as i64,
                _ => -1,
            })
            .collect();
        result.set_item("moves", moves)?;
        let path: Vec<[f64; 2]> = outcome.runs.iter().flat_map(|r| r.path.clone()).collect();
        result.set_item("path", path)?;
        result.set_item("steps", outcome.manipulator_steps)?;
        result.set_item("plans", outcome.plans)?;
        result.set_item("failure", outcome.failure.clone())?;
        Ok(result)
    }
}
