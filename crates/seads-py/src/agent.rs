//! A trained SEADS agent from its run directory (`seads-infer`, no libtorch): actions,
//! the forward model's successors, plans, and solving a board in an environment.

use std::path::PathBuf;
use std::sync::Mutex;

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, EnvSpec, Environment, Filmed, Push, SkillPolicy, execute_skill};
use seads_games::{BoardGame, Successor, SymbolicState};
use seads_infer::{Model, Policy};
use seads_planner::{PlanChoice, PlannerConfig, Search, SolveConfig, find_plan};

use crate::env::Env;
use crate::{Values, value_error};

/// A trained agent: its skill policy and forward model. Every method borrows it shared, so
/// Python threads may use one agent at once; the forward model, which plans, is taken by one
/// search at a time, always with the GIL released (a thread waiting for it never holds the GIL
/// that the thread holding it needs).
#[pyclass(module = "seads._seads")]
pub struct Agent {
    /// The skill policy.
    policy: Policy,
    /// The forward model, one search at a time.
    model: Mutex<Model>,
    /// The environment the agent was trained on, its options and its dimensions.
    env: String,
    env_config: EnvConfig,
    spec: EnvSpec,
    /// The checkpoint's epoch.
    epoch: u64,
    game: Box<dyn BoardGame + Send + Sync>,
}

/// Observation rows the policy runs on at once in `act`.
const ACT_ROWS: usize = 4096;

/// The forward model, whichever thread used it last (a panic there leaves it whole: it is
/// only read and its buffers rewritten).
fn lock(model: &Mutex<Model>) -> std::sync::MutexGuard<'_, Model> {
    model
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
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

/// The `_seads.Env` of a ``seads`` Gymnasium environment (or the `Env` itself).
fn env_core<'py>(env: &Bound<'py, PyAny>) -> PyResult<Bound<'py, Env>> {
    match env.cast::<Env>() {
        Ok(core) => Ok(core.clone()),
        Err(_) => env
            .getattr("unwrapped")
            .and_then(|u| u.getattr("_core"))
            .and_then(|c| Ok(c.cast_into::<Env>()?))
            .map_err(|_| value_error("env: a seads environment (gymnasium.make(\"seads/…\"))")),
    }
}

impl Agent {
    /// The environment of `core` if it is in skill mode and of this agent's kind.
    fn own_env<'a>(&self, core: &'a mut Env) -> PyResult<&'a mut Box<dyn Environment>> {
        let options = core.config().clone();
        let environment = core.skill_env().ok_or_else(|| {
            value_error("env: an environment in task mode; the agent needs skill mode")
        })?;
        // The whole world must be the run's: its name and dimensions (a 7×7 board is no 5×5
        // one), and the options that shape it beyond them (spacing, the manipulator's).
        let spec = environment.spec();
        let trained = self;
        let differs = if spec.name != trained.env {
            Some(format!("a {} environment", spec.name))
        } else if spec != &trained.spec {
            Some(format!(
                "{} with a {n}×{n} board of {} fields and {} observations",
                spec.name,
                spec.symbolic_len,
                spec.obs_dim,
                n = spec.board_size
            ))
        } else if options.spacing != trained.env_config.spacing
            || options.manipulator != trained.env_config.manipulator
        {
            Some(format!(
                "{} with spacing {:?} and manipulator options {:?}",
                spec.name,
                options.spacing,
                serde_json::Value::Object(options.manipulator.clone()).to_string()
            ))
        } else {
            None
        };
        if let Some(differs) = differs {
            return Err(value_error(format!(
                "env: {differs}; the agent was trained on {} ({n}×{n} board, spacing {:?}, \
                 manipulator options {:?})",
                trained.env,
                trained.env_config.spacing,
                serde_json::Value::Object(trained.env_config.manipulator.clone()).to_string(),
                n = trained.spec.board_size
            )));
        }
        Ok(environment)
    }

    fn board(&self, values: &Values) -> PyResult<SymbolicState> {
        let fields = self.game.size() * self.game.size();
        if values.0.len() != fields {
            return Err(value_error(format!(
                "a board of {} values; this agent's game has {fields}",
                values.0.len(),
            )));
        }
        self.game.board_from_values(&values.0).map_err(value_error)
    }
}

#[pymethods]
impl Agent {
    /// `Agent.load(run_dir, checkpoint=None)`: the agent of a run directory, at its latest
    /// checkpoint or the one of epoch `checkpoint`.
    #[staticmethod]
    #[pyo3(signature = (run_dir, checkpoint=None))]
    fn load(py: Python<'_>, run_dir: PathBuf, checkpoint: Option<u64>) -> PyResult<Self> {
        crate::guarded(|| {
            let seads_infer::Agent {
                policy,
                model,
                env,
                env_config,
                spec,
                epoch,
            } = py
                .detach(|| seads_infer::Agent::load(&run_dir, checkpoint))
                .map_err(value_error)?;
            // The game of the run's own environment (its board size, from `[env_config]`).
            let game = spec.game.build(spec.board_size).map_err(value_error)?;
            Ok(Self {
                policy,
                model: Mutex::new(model),
                env,
                env_config,
                spec,
                epoch,
                game,
            })
        })
    }

    /// The environment the agent was trained on.
    #[getter]
    fn env(&self) -> String {
        self.env.clone()
    }

    /// The checkpoint's epoch.
    #[getter]
    fn epoch(&self) -> u64 {
        self.epoch
    }

    /// The number of skills K.
    #[getter]
    fn num_skills(&self) -> usize {
        self.policy.num_skills()
    }

    /// `act(obs, skill, deterministic=True, seed=None)`: actions for observations (one, or
    /// rows of a 2-D array) executing `skill` (one for all rows, or one per row): the policy's
    /// deterministic action, or a sample drawn from `seed`.
    #[pyo3(signature = (obs, skill, deterministic=true, seed=None))]
    fn act<'py>(
        &self,
        py: Python<'py>,
        obs: &Bound<'py, PyAny>,
        skill: &Bound<'py, PyAny>,
        deterministic: bool,
        seed: Option<u64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        crate::guarded(|| {
            // float32 as it is; float64 (NumPy's default) converted, where every value fits.
            let f32_obs = obs.extract::<PyReadonlyArrayDyn<'py, f32>>().ok();
            let f64_obs = match f32_obs {
                Some(_) => None,
                None => Some(obs.extract::<PyReadonlyArrayDyn<'py, f64>>().map_err(|_| {
                    value_error("observations: a NumPy array of float32 (or float64) values")
                })?),
            };
            let shape = match (&f32_obs, &f64_obs) {
                (Some(o), _) => o.shape().to_vec(),
                (_, Some(o)) => o.shape().to_vec(),
                _ => unreachable!("one of them was extracted"),
            };
            let rows = match shape[..] {
                [n] if n == self.spec.obs_dim => 1,
                [rows, n] if n == self.spec.obs_dim => rows,
                _ => {
                    return Err(value_error(format!(
                        "observations of shape {shape:?}: ({}) or (rows, {})",
                        self.spec.obs_dim, self.spec.obs_dim
                    )));
                }
            };
            // One skill for every row is never repeated into a list of all rows.
            let (one, each): (Option<usize>, Vec<usize>) = match skill.extract::<usize>() {
                Ok(k) => (Some(k), Vec::new()),
                Err(_) => (
                    None,
                    skill.extract::<Vec<usize>>().map_err(|_| {
                        value_error("skill: a non-negative whole number or one per observation row")
                    })?,
                ),
            };
            if one.is_none() && each.len() != rows {
                return Err(value_error(format!(
                    "{} skills for {rows} observation rows",
                    each.len()
                )));
            }
            let mut rng = match (deterministic, seed) {
                (true, _) => None,
                (false, Some(seed)) => Some(ChaCha8Rng::seed_from_u64(seed)),
                (false, None) => {
                    return Err(value_error(
                        "a sampled action needs a seed (act(..., deterministic=False, seed=S))",
                    ));
                }
            };
            // The actions are reserved up front, so that too many rows are a MemoryError, not an
            // abort; the policy runs on chunks of rows, so that its layers hold a chunk at a time.
            let mut actions: Vec<f32> = Vec::new();
            actions
                .try_reserve_exact(rows.saturating_mul(self.spec.action_dim))
                .map_err(|_| {
                    PyMemoryError::new_err(format!(
                        "no memory for the actions of {rows} observations"
                    ))
                })?;
            let f32_view = f32_obs.as_ref().map(|o| o.as_array());
            let f64_view = f64_obs.as_ref().map(|o| o.as_array());
            let mut f32_values = f32_view.iter().flat_map(|v| v.iter().copied());
            let mut f64_values = f64_view.iter().flat_map(|v| v.iter().copied());
            let mut chunk: Vec<f32> = Vec::with_capacity(ACT_ROWS * self.spec.obs_dim);
            // One skill for every row: a chunk's worth of it, made once.
            let repeated = one.map_or_else(Vec::new, |k| vec![k; ACT_ROWS.min(rows)]);
            for first in (0..rows).step_by(ACT_ROWS) {
                let last = (first + ACT_ROWS).min(rows);
                let n = (last - first) * self.spec.obs_dim;
                chunk.clear();
                if f32_view.is_some() {
                    chunk.extend(f32_values.by_ref().take(n));
                } else {
                    for v in f64_values.by_ref().take(n) {
                        let narrow = v as f32;
                        if v.is_finite() && narrow.is_infinite() {
                            return Err(value_error(format!(
                                "an observation of {v} lies beyond float32's range"
                            )));
                        }
                        chunk.push(narrow);
                    }
                }
                let skills = match one {
                    Some(_) => &repeated[..last - first],
                    None => &each[first..last],
                };
                let part = self
                    .policy
                    .actions(&chunk, skills, rng.as_mut())
                    .map_err(value_error)?;
                actions.extend(part);
            }
            if shape.len() == 1 {
                Ok(PyArray1::from_vec(py, actions).into_any())
            } else {
                let array = PyArray1::from_vec(py, actions);
                Ok(array.reshape([rows, self.spec.action_dim])?.into_any())
            }
        })
    }

    /// `successors(board)`: the board the forward model predicts after each skill (K rows of
    /// the board's values).
    fn successors<'py>(
        &self,
        py: Python<'py>,
        board: Values,
    ) -> PyResult<Bound<'py, PyArray2<u8>>> {
        crate::guarded(|| {
            let z = self.board(&board)?;
            let mut next = Vec::new();
            py.detach(|| lock(&self.model).successors(&[z], &mut next));
            let rows: Vec<Vec<u8>> = next.iter().map(|&b| self.game.values(b)).collect();
            PyArray2::from_vec2(py, &rows).map_err(value_error)
        })
    }

    /// `plan(board, goal=None, max_depth=20, max_expanded=4194304, search="breadth",
    /// choice="most-likely")`: the skills of a plan the forward model predicts to reach the goal
    /// (the solved board unless given); `[]` on the goal; a `ValueError` if none is found.
    #[pyo3(signature = (board, goal=None, max_depth=20, max_expanded=Some(seads_planner::DEFAULT_MAX_EXPANDED), search="breadth", choice="most-likely"))]
    #[allow(clippy::too_many_arguments)]
    fn plan(
        &self,
        py: Python<'_>,
        board: Values,
        goal: Option<Values>,
        max_depth: usize,
        max_expanded: Option<usize>,
        search: &str,
        choice: &str,
    ) -> PyResult<Vec<usize>> {
        crate::guarded(|| {
            let start = self.board(&board)?;
            let goal = match goal {
                Some(values) => self.board(&values)?,
                None => self.game.goal(),
            };
            if start == goal {
                return Ok(Vec::new());
            }
            let config = planner(max_depth, max_expanded, search, choice)?;
            crate::interruptible(
                py,
                || find_plan(&mut *lock(&self.model), start, goal, &config),
                || config.interrupt.raise(),
            )?
            .map(|plan| plan.skills)
            .map_err(crate::plan_error)
        })
    }

    /// `solve(env, board=None, replan=True, max_expanded=4194304, search="breadth",
    /// choice="most-likely")`: plans from the environment's board (or sets `board` first) and
    /// executes the plan's skills in it, re-planning after a skill that left another board than
    /// predicted. `env` is a ``seads`` Gymnasium environment (or its ``_seads.Env``) of the
    /// agent's kind, in skill mode. Returns a dict: solved, skills (executed), moves (the game
    /// move each made, −1 for none), path (the manipulator's positions), steps, plans, failure;
    /// with `render=True` also frames, the top view (`size` × `size` RGB) at the start and
    /// after every manipulator step.
    #[pyo3(signature = (env, board=None, replan=true, max_expanded=Some(seads_planner::DEFAULT_MAX_EXPANDED), search="breadth", choice="most-likely", render=false, size=256))]
    #[allow(clippy::too_many_arguments)]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        env: &Bound<'py, PyAny>,
        board: Option<Values>,
        replan: bool,
        max_expanded: Option<usize>,
        search: &str,
        choice: &str,
        render: bool,
        size: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        crate::guarded(|| {
            let core = env_core(env)?;
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
            let goal = self.game.goal();
            let environment = self.own_env(&mut core)?;
            if let Some(start) = start {
                environment.set_board(start).map_err(value_error)?;
            }
            let policy = &self.policy;
            if render {
                crate::render::check_size(size)?;
            }
            // The search and the skills run with the GIL released (other Python threads go on),
            // and Ctrl-C stops the search.
            let (outcome, scenes) = crate::interruptible(
                py,
                || {
                    let mut model = lock(&self.model);
                    if render {
                        // A copy (same state, same random streams) is filmed and then takes the
                        // environment's place: the environment ends as an unfilmed solve leaves it.
                        let mut filmed = Filmed::new(environment.box_clone());
                        let outcome =
                            seads_planner::solve(&mut filmed, policy, &mut *model, goal, &config);
                        let scenes = filmed.take_frames();
                        *environment = filmed.into_inner();
                        (outcome, scenes)
                    } else {
                        let outcome = seads_planner::solve(
                            environment.as_mut(),
                            policy,
                            &mut *model,
                            goal,
                            &config,
                        );
                        (outcome, Vec::new())
                    }
                },
                || config.planner.interrupt.raise(),
            )?;
            let outcome = outcome.map_err(value_error)?;
            let result = PyDict::new(py);
            if render {
                let frames = scenes
                    .iter()
                    .map(|scene| crate::render::frame(py, scene, size))
                    .collect::<PyResult<Vec<_>>>()?;
                result.set_item("frames", frames)?;
            }
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
        })
    }
    /// `clip(env, skill, size=256)`: executes `skill` once from where the environment stands
    /// (reset it first, e.g. ``env.reset(seed=s)``) and returns a dict: frames (the top view,
    /// `size` × `size` RGB, at the start and after every step), move (the game move the skill
    /// made, −1 for none) and steps.
    #[pyo3(signature = (env, skill, size=256))]
    fn clip<'py>(
        &self,
        py: Python<'py>,
        env: &Bound<'py, PyAny>,
        skill: i64,
        size: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        crate::guarded(|| {
            crate::render::check_size(size)?;
            let skill = usize::try_from(skill)
                .ok()
                .filter(|&k| k < self.policy.num_skills())
                .ok_or_else(|| {
                    value_error(format!(
                        "skill {skill}: the agent has skills 0 to {}",
                        self.policy.num_skills() - 1
                    ))
                })?;
            let core = env_core(env)?;
            let mut core = core.borrow_mut();
            let environment = self.own_env(&mut core)?;
            let policy = &self.policy;
            let (run, scenes) = py.detach(|| {
                let mut filmed = Filmed::new(environment.box_clone());
                let run = execute_skill(&mut filmed, policy, skill);
                let scenes = filmed.take_frames();
                *environment = filmed.into_inner();
                (run, scenes)
            });
            let run = run.map_err(value_error)?;
            let frames = scenes
                .iter()
                .map(|scene| crate::render::frame(py, scene, size))
                .collect::<PyResult<Vec<_>>>()?;
            let result = PyDict::new(py);
            result.set_item("frames", frames)?;
            result.set_item("move", run.outcome.game_move().map_or(-1, |m| m as i64))?;
            result.set_item("steps", run.steps)?;
            Ok(result)
        })
    }
}
