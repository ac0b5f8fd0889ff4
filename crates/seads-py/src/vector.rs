//! Many environments of one kind stepped in parallel (rayon), written straight into NumPy
//! arrays the caller owns: no Python loop and no per-environment copy. Autoreset follows
//! Gymnasium 1.x's default ("next step"): the step after an environment's episode ended resets
//! that environment instead of stepping it, and reports its first observation with reward 0 and
//! neither flag set.

use numpy::{PyReadonlyArray2, PyReadwriteArray1, PyReadwriteArray2};
use pyo3::prelude::*;
use rayon::prelude::*;
use seads_embodiment::EnvError;

use crate::env::{Core, Stepped, parse_options};
use crate::value_error;

/// One member: its environment and whether its episode ended on the last step.
struct Member {
    core: Core,
    ended: bool,
}

/// N environments, the core of `seads.SeadsVectorEnv` (use that: it is a Gymnasium vector
/// environment).
#[pyclass(module = "seads._seads")]
pub struct VecEnv {
    members: Vec<Member>,
    obs_dim: usize,
    action_dim: usize,
}

/// The arrays one step writes, as slices.
struct Out<'a> {
    obs: &'a mut [f32],
    reward: &'a mut [f32],
    terminated: &'a mut [bool],
    truncated: &'a mut [bool],
    game_move: &'a mut [i64],
}

#[pymethods]
impl VecEnv {
    /// `VecEnv(name, num_envs, options=None, task=False)`: `num_envs` copies of the environment
    /// `name` (see `Env`).
    #[new]
    #[pyo3(signature = (name, num_envs, options=None, task=false))]
    fn new(name: &str, num_envs: usize, options: Option<&str>, task: bool) -> PyResult<Self> {
        if !(1..=1 << 20).contains(&num_envs) {
            return Err(value_error(format!(
                "num_envs {num_envs}: must be 1 to {}",
                1 << 20
            )));
        }
        let config = parse_options(options)?;
        let members = (0..num_envs)
            .map(|_| {
                Ok(Member {
                    core: Core::new(name, &config, task)?,
                    ended: false,
                })
            })
            .collect::<Result<Vec<_>, EnvError>>()
            .map_err(value_error)?;
        let spec = members[0].core.spec();
        Ok(Self {
            obs_dim: spec.obs_dim,
            action_dim: spec.action_dim,
            members,
        })
    }

    /// The number of environments.
    fn __len__(&self) -> usize {
        self.members.len()
    }

    /// The environments' specification as a dict (see `Env.spec`).
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::env::spec_dict(py, self.members[0].core.spec())
    }

    /// Seeds environment i with `seeds[i]` (when given) and resets every environment, writing
    /// the observations into `obs` (num_envs × obs_dim, float32).
    #[pyo3(signature = (obs, seeds=None))]
    fn reset(
        &mut self,
        mut obs: PyReadwriteArray2<'_, f32>,
        seeds: Option<Vec<u64>>,
    ) -> PyResult<()> {
        let n = self.members.len();
        if let Some(seeds) = &seeds
            && seeds.len() != n
        {
            return Err(value_error(format!(
                "{} seeds for {n} environments",
                seeds.len()
            )));
        }
        let obs = self.checked(
            obs.as_slice_mut().map_err(value_error)?,
            self.obs_dim,
            "obs",
        )?;
        let dim = self.obs_dim;
        obs.par_chunks_mut(dim)
            .zip(self.members.par_iter_mut())
            .enumerate()
            .try_for_each(|(i, (obs, m))| {
                if let Some(seeds) = &seeds {
                    m.core.seed(seeds[i]);
                }
                m.core.reset()?;
                m.ended = false;
                m.core.observe(obs);
                Ok::<_, EnvError>(())
            })
            .map_err(value_error)
    }

    /// Steps every environment with its row of `actions` (num_envs × action_dim, float32) and
    /// writes observations, rewards, terminated and truncated flags and game moves (−1: none)
    /// into the given arrays. An environment whose episode ended on the previous step is reset
    /// instead (its action is ignored). A wrong shape or a non-finite action is a `ValueError`
    /// raised before any environment steps.
    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        py: Python<'_>,
        actions: PyReadonlyArray2<'_, f32>,
        mut obs: PyReadwriteArray2<'_, f32>,
        mut reward: PyReadwriteArray1<'_, f32>,
        mut terminated: PyReadwriteArray1<'_, bool>,
        mut truncated: PyReadwriteArray1<'_, bool>,
        mut game_move: PyReadwriteArray1<'_, i64>,
    ) -> PyResult<()> {
        let actions = self.checked_ref(
            actions.as_slice().map_err(value_error)?,
            self.action_dim,
            "actions",
        )?;
        if let Some(i) = actions.iter().position(|a| !a.is_finite()) {
            return Err(value_error(format!(
                "actions: entry {} of environment {} is {}, not a finite number",
                i % self.action_dim,
                i / self.action_dim,
                actions[i]
            )));
        }
        let out = Out {
            obs: self.checked(
                obs.as_slice_mut().map_err(value_error)?,
                self.obs_dim,
                "obs",
            )?,
            reward: self.checked(reward.as_slice_mut().map_err(value_error)?, 1, "reward")?,
            terminated: self.checked(
                terminated.as_slice_mut().map_err(value_error)?,
                1,
                "terminated",
            )?,
            truncated: self.checked(
                truncated.as_slice_mut().map_err(value_error)?,
                1,
                "truncated",
            )?,
            game_move: self.checked(game_move.as_slice_mut().map_err(value_error)?, 1, "move")?,
        };
        let (obs_dim, action_dim) = (self.obs_dim, self.action_dim);
        let members = &mut self.members;
        py.detach(|| {
            out.obs
                .par_chunks_mut(obs_dim)
                .zip(actions.par_chunks(action_dim))
                .zip(members.par_iter_mut())
                .zip(out.reward.par_iter_mut())
                .zip(out.terminated.par_iter_mut())
                .zip(out.truncated.par_iter_mut())
                .zip(out.game_move.par_iter_mut())
                .with_min_len(64)
                .try_for_each(|((((((obs, action), m), r), te), tr), mv)| {
                    let s = if m.ended {
                        m.core.reset()?;
                        Stepped {
                            game_move: -1,
                            ..Stepped::default()
                        }
                    } else {
                        m.core.step(action)?
                    };
                    m.ended = s.terminated || s.truncated;
                    m.core.observe(obs);
                    (*r, *te, *tr, *mv) = (s.reward, s.terminated, s.truncated, s.game_move);
                    Ok::<_, EnvError>(())
                })
        })
        .map_err(value_error)
    }

    /// The boards of every environment (num_envs × board values, uint8), row-major.
    fn boards<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray2<u8>>> {
        let game = self.members[0].core.game().map_err(value_error)?;
        let rows: Vec<Vec<u8>> = self
            .members
            .iter()
            .map(|m| game.values(m.core.env().board()))
            .collect();
        numpy::PyArray2::from_vec2(py, &rows).map_err(value_error)
    }

    /// Environment i's top view as an RGB image (see `Env.render`).
    #[pyo3(signature = (index, size=256))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        index: usize,
        size: usize,
    ) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        let m = self
            .members
            .get(index)
            .ok_or_else(|| value_error(format!("environment {index} of {}", self.members.len())))?;
        crate::render::image(py, m.core.env(), size)
    }
}

impl VecEnv {
    /// `slice` if it holds `per_env` values per environment (a C-contiguous array of the
    /// right shape), else a `ValueError` naming `what`.
    fn checked<'a, T>(
        &self,
        slice: &'a mut [T],
        per_env: usize,
        what: &str,
    ) -> PyResult<&'a mut [T]> {
        self.check_len(slice.len(), per_env, what)?;
        Ok(slice)
    }

    /// [`Self::checked`] for an array that is only read.
    fn checked_ref<'a, T>(&self, slice: &'a [T], per_env: usize, what: &str) -> PyResult<&'a [T]> {
        self.check_len(slice.len(), per_env, what)?;
        Ok(slice)
    }

    fn check_len(&self, len: usize, per_env: usize, what: &str) -> PyResult<()> {
        let n = self.members.len();
        if len != n * per_env {
            return Err(value_error(format!(
                "{what}: {len} values, expected {n} environments × {per_env}"
            )));
        }
        Ok(())
    }
}
