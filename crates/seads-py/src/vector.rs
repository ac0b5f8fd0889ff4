//! Many environments of one kind stepped in parallel (rayon), written straight into NumPy
//! arrays the caller owns: no Python loop and no per-environment copy. The step after an
//! environment's episode ended follows one of Gymnasium 1.x's autoreset modes: "next step" (the
//! default: that step resets the environment instead of stepping it and reports its first
//! observation with reward 0 and neither flag set), "same step" (the ending step resets at once
//! and keeps the last observation and board apart) or "disabled" (the caller resets ended
//! environments through a reset mask).

use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray1, PyReadwriteArray2};
use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;
use rayon::prelude::*;
use seads_embodiment::EnvError;
use seads_games::BoardGame;

use crate::env::{Core, Stepped, parse_options};
use crate::value_error;

/// What the step after an episode's end does (Gymnasium's `AutoresetMode`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Autoreset {
    NextStep,
    SameStep,
    Disabled,
}

impl Autoreset {
    fn parse(name: &str) -> PyResult<Self> {
        match name {
            "next_step" | "NextStep" => Ok(Autoreset::NextStep),
            "same_step" | "SameStep" => Ok(Autoreset::SameStep),
            "disabled" | "Disabled" => Ok(Autoreset::Disabled),
            other => Err(value_error(format!(
                "autoreset_mode {other:?}: next_step, same_step or disabled"
            ))),
        }
    }
}

/// One member: its environment and whether its episode ended on the last step.
struct Member {
    core: Core,
    ended: bool,
}

/// The most environments one vector holds.
const MAX_ENVS: usize = 1 << 20;

/// Free memory that must remain possible to reserve while the environments are built, checked
/// before every [`PROBE_EVERY`] of them: a vector too large for the memory it may use stops with
/// a `MemoryError` instead of the allocator aborting the interpreter.
const HEADROOM: usize = 256 << 20;
/// Environments built between two memory checks.
const PROBE_EVERY: usize = 64;

/// N environments, the core of `seads.SeadsVectorEnv` (use that: it is a Gymnasium vector
/// environment).
#[pyclass(module = "seads._seads")]
pub struct VecEnv {
    members: Vec<Member>,
    game: Box<dyn BoardGame>,
    obs_dim: usize,
    action_dim: usize,
    board_len: usize,
    autoreset: Autoreset,
    chunk: usize,
}

/// The per-environment arrays a step writes, as slices (one row per environment).
struct Out<'a> {
    obs: &'a mut [f32],
    reward: &'a mut [f32],
    terminated: &'a mut [bool],
    truncated: &'a mut [bool],
    game_move: &'a mut [i64],
    board: &'a mut [u8],
    depth: &'a mut [i64],
    final_obs: &'a mut [f32],
    final_board: &'a mut [u8],
    ended: &'a mut [bool],
}

#[pymethods]
impl VecEnv {
    /// `VecEnv(name, num_envs, options=None, task=False, autoreset="next_step")`: `num_envs`
    /// copies of the environment `name` (see `Env`); `autoreset` is `next_step`, `same_step` or
    /// `disabled`. A `MemoryError` if they do not fit the memory the process may use.
    #[new]
    #[pyo3(signature = (name, num_envs, options=None, task=false, autoreset="next_step"))]
    fn new(
        py: Python<'_>,
        name: &str,
        num_envs: usize,
        options: Option<&str>,
        task: bool,
        autoreset: &str,
    ) -> PyResult<Self> {
        crate::guarded(|| {
            if !(1..=MAX_ENVS).contains(&num_envs) {
                return Err(value_error(format!(
                    "num_envs {num_envs}: must be 1 to {MAX_ENVS}"
                )));
            }
            let autoreset = Autoreset::parse(autoreset)?;
            let config = parse_options(options)?;
            let first = Core::new(name, &config, task).map_err(value_error)?;
            let mut members = Vec::new();
            members
                .try_reserve_exact(num_envs)
                .map_err(|_| memory_error(name, num_envs, 0))?;
            members.push(Member {
                core: first,
                ended: false,
            });
            while members.len() < num_envs {
                if members.len() % PROBE_EVERY == 0 {
                    py.check_signals()?;
                    Vec::<u8>::new()
                        .try_reserve_exact(HEADROOM)
                        .map_err(|_| memory_error(name, num_envs, members.len()))?;
                }
                let core = Core::new(name, &config, task).map_err(value_error)?;
                members.push(Member { core, ended: false });
            }
            let spec = members[0].core.spec();
            let game = members[0].core.game().map_err(value_error)?;
            let threads = rayon::current_num_threads().max(1);
            Ok(Self {
                obs_dim: spec.obs_dim,
                action_dim: spec.action_dim,
                board_len: game.values(game.goal()).len(),
                game,
                members,
                autoreset,
                // At least four pieces of work per thread, so that every thread steps even a small
                // vector of slow environments (a Jaco arm's step is ~100 µs) and a busy core holds
                // back little; at most 64 environments a piece, so that a large vector is shared
                // out finely too.
                chunk: (num_envs / (4 * threads)).clamp(1, 64),
            })
        })
    }

    /// The number of environments.
    fn __len__(&self) -> usize {
        self.members.len()
    }

    /// Environments one parallel piece of work steps (about four pieces per thread).
    #[getter]
    fn chunk_size(&self) -> usize {
        self.chunk
    }

    /// Values of one board (25 for 5×5 LightsOut, 9 for TileSwap).
    #[getter]
    fn board_len(&self) -> usize {
        self.board_len
    }

    /// The environments' specification as a dict (see `Env.spec`).
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::guarded(|| crate::env::spec_dict(py, self.members[0].core.spec()))
    }

    /// Resets the environments (those where `mask` is true, when given; `seeds[i]` seeds
    /// environment i first, when given) and writes their observations into `obs` (num_envs ×
    /// obs_dim, float32), their boards into `board` (num_envs × board_len, uint8) and their
    /// solution depths into `depth` (int64, −1 in skill mode). Rows of environments not reset
    /// are left as they are.
    #[pyo3(signature = (obs, board, depth, seeds=None, mask=None))]
    fn reset(
        &mut self,
        py: Python<'_>,
        mut obs: PyReadwriteArray2<'_, f32>,
        mut board: PyReadwriteArray2<'_, u8>,
        mut depth: PyReadwriteArray1<'_, i64>,
        seeds: Option<Vec<u64>>,
        mask: Option<PyReadonlyArray1<'_, bool>>,
    ) -> PyResult<()> {
        crate::guarded(|| {
            let n = self.members.len();
            if let Some(seeds) = &seeds
                && seeds.len() != n
            {
                return Err(value_error(format!(
                    "{} seeds for {n} environments",
                    seeds.len()
                )));
            }
            let mask = match &mask {
                Some(mask) => Some(self.checked_ref(
                    mask.as_slice().map_err(value_error)?,
                    1,
                    "reset_mask",
                )?),
                None => None,
            };
            let obs = self.checked(
                obs.as_slice_mut().map_err(value_error)?,
                self.obs_dim,
                "obs",
            )?;
            let board = self.checked(
                board.as_slice_mut().map_err(value_error)?,
                self.board_len,
                "board",
            )?;
            let depth = self.checked(depth.as_slice_mut().map_err(value_error)?, 1, "depth")?;
            let (obs_dim, board_len, chunk, game) =
                (self.obs_dim, self.board_len, self.chunk, &*self.game);
            let members = &mut self.members;
            py.detach(|| {
                obs.par_chunks_mut(obs_dim)
                    .zip(board.par_chunks_mut(board_len))
                    .zip(depth.par_iter_mut())
                    .zip(members.par_iter_mut())
                    .enumerate()
                    .with_min_len(chunk)
                    .try_for_each(|(i, (((obs, board), depth), m))| {
                        if mask.is_some_and(|mask| !mask[i]) {
                            return Ok(());
                        }
                        if let Some(seeds) = &seeds {
                            m.core.seed(seeds[i]);
                        }
                        m.core.reset()?;
                        m.ended = false;
                        m.core.observe(obs);
                        game.write_values(m.core.env().board(), board);
                        *depth = m.core.depth().map_or(-1, |d| d as i64);
                        Ok::<_, EnvError>(())
                    })
            })
            .map_err(value_error)
        })
    }

    /// Steps every environment with its row of `actions` (num_envs × action_dim, float32) and
    /// writes observations, rewards, terminated and truncated flags, game moves (−1: none),
    /// boards and solution depths (−1 in skill mode) into the given arrays. An environment whose
    /// episode ended on the previous step is reset instead (next-step autoreset; its action is
    /// ignored). With same-step autoreset an environment whose episode ends is reset at once:
    /// `ended[i]` is set and its last observation and board go to `final_obs` and
    /// `final_board`. With autoreset disabled, stepping an environment whose episode ended is a
    /// `ValueError`. A wrong shape or a non-finite action is a `ValueError` raised before any
    /// environment steps.
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
        mut board: PyReadwriteArray2<'_, u8>,
        mut depth: PyReadwriteArray1<'_, i64>,
        mut final_obs: PyReadwriteArray2<'_, f32>,
        mut final_board: PyReadwriteArray2<'_, u8>,
        mut ended: PyReadwriteArray1<'_, bool>,
    ) -> PyResult<()> {
        crate::guarded(|| {
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
            if self.autoreset == Autoreset::Disabled
                && let Some(i) = self.members.iter().position(|m| m.ended)
            {
                return Err(value_error(format!(
                    "environment {i}'s episode has ended and autoreset is disabled: reset it first \
                 (reset(options={{\"reset_mask\": …}}))"
                )));
            }
            let (obs_dim, board_len) = (self.obs_dim, self.board_len);
            let out = Out {
                obs: self.checked(obs.as_slice_mut().map_err(value_error)?, obs_dim, "obs")?,
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
                game_move: self.checked(
                    game_move.as_slice_mut().map_err(value_error)?,
                    1,
                    "move",
                )?,
                board: self.checked(
                    board.as_slice_mut().map_err(value_error)?,
                    board_len,
                    "board",
                )?,
                depth: self.checked(depth.as_slice_mut().map_err(value_error)?, 1, "depth")?,
                final_obs: self.checked(
                    final_obs.as_slice_mut().map_err(value_error)?,
                    obs_dim,
                    "final_obs",
                )?,
                final_board: self.checked(
                    final_board.as_slice_mut().map_err(value_error)?,
                    board_len,
                    "final_board",
                )?,
                ended: self.checked(ended.as_slice_mut().map_err(value_error)?, 1, "ended")?,
            };
            let (action_dim, chunk, autoreset, game) =
                (self.action_dim, self.chunk, self.autoreset, &*self.game);
            let members = &mut self.members;
            // Pieces of `chunk` environments, each stepped in a plain loop: the arrays are cut
            // once per piece, not once per environment.
            py.detach(|| {
                out.obs
                    .par_chunks_mut(obs_dim * chunk)
                    .zip(actions.par_chunks(action_dim * chunk))
                    .zip(members.par_chunks_mut(chunk))
                    .zip(out.reward.par_chunks_mut(chunk))
                    .zip(out.terminated.par_chunks_mut(chunk))
                    .zip(out.truncated.par_chunks_mut(chunk))
                    .zip(out.game_move.par_chunks_mut(chunk))
                    .zip(out.board.par_chunks_mut(board_len * chunk))
                    .zip(out.depth.par_chunks_mut(chunk))
                    .zip(out.final_obs.par_chunks_mut(obs_dim * chunk))
                    .zip(out.final_board.par_chunks_mut(board_len * chunk))
                    .zip(out.ended.par_chunks_mut(chunk))
                    .try_for_each(
                        |(
                            (
                                (
                                    (
                                        (((((((obs, actions), members), r), te), tr), mv), board),
                                        depth,
                                    ),
                                    fo,
                                ),
                                fb,
                            ),
                            end,
                        )| {
                            for (j, m) in members.iter_mut().enumerate() {
                                let (o, b) = (j * obs_dim, j * board_len);
                                let s = if m.ended {
                                    m.core.reset()?;
                                    Stepped {
                                        game_move: -1,
                                        ..Stepped::default()
                                    }
                                } else {
                                    m.core
                                        .step(&actions[j * action_dim..(j + 1) * action_dim])?
                                };
                                m.ended = s.terminated || s.truncated;
                                end[j] = false;
                                if m.ended && autoreset == Autoreset::SameStep {
                                    m.core.observe(&mut fo[o..o + obs_dim]);
                                    game.write_values(
                                        m.core.env().board(),
                                        &mut fb[b..b + board_len],
                                    );
                                    m.core.reset()?;
                                    m.ended = false;
                                    end[j] = true;
                                }
                                m.core.observe(&mut obs[o..o + obs_dim]);
                                game.write_values(
                                    m.core.env().board(),
                                    &mut board[b..b + board_len],
                                );
                                depth[j] = m.core.depth().map_or(-1, |d| d as i64);
                                (r[j], te[j], tr[j], mv[j]) =
                                    (s.reward, s.terminated, s.truncated, s.game_move);
                            }
                            Ok::<_, EnvError>(())
                        },
                    )
            })
            .map_err(value_error)
        })
    }

    /// The boards of every environment (num_envs × board values, uint8), row-major.
    fn boards<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray2<u8>>> {
        crate::guarded(|| {
            let rows: Vec<Vec<u8>> = self
                .members
                .iter()
                .map(|m| self.game.values(m.core.env().board()))
                .collect();
            numpy::PyArray2::from_vec2(py, &rows).map_err(value_error)
        })
    }

    /// Environment i's top view as an RGB image (see `Env.render`).
    #[pyo3(signature = (index, size=256))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        index: usize,
        size: usize,
    ) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        crate::guarded(|| {
            let m = self.members.get(index).ok_or_else(|| {
                value_error(format!("environment {index} of {}", self.members.len()))
            })?;
            crate::render::image(py, m.core.env(), size)
        })
    }
}

/// The `MemoryError` of a vector that did not fit.
fn memory_error(name: &str, num_envs: usize, built: usize) -> PyErr {
    PyMemoryError::new_err(format!(
        "{num_envs} {name} environments do not fit the memory this process may use \
         (memory ran short after {built})"
    ))
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
