//! `seads._seads`, the Rust half of the Python package `seads`: the embodied environments one
//! at a time (`Env`, `env.rs`) and many stepped in parallel into NumPy arrays (`VecEnv`,
//! `vector.rs`), the board games and breadth-first planning with the true game model
//! (`games.rs`), and a top-view rasteriser for `render()` (`render.rs`). The Python half
//! (`python/seads`) wraps them as Gymnasium environments and registers them.
//!
//! A trained agent (`agent.rs`) is loaded with `seads-infer`, which reads its checkpoint and
//! evaluates its networks without libtorch.
//!
//! Architecture invariant: no libtorch, never a second one beside PyTorch's in a process.

use std::sync::{Condvar, Mutex};
use std::time::Duration;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

mod agent;
mod env;
mod games;
mod render;
mod vector;

/// Runs `work` on a helper thread with the GIL released, while this thread, where Python runs
/// its signal handlers, looks for a signal every 50 ms: on one (Ctrl-C: `KeyboardInterrupt`),
/// `stop` is called so that the work ends early, the helper is waited for, and the signal's
/// exception raised. So a long search can be stopped, and other Python threads go on meanwhile.
/// A panic of the work is a `RuntimeError`, never a crash of the interpreter.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send,
    stop: impl Fn(),
) -> PyResult<T> {
    let finished = (Mutex::new(false), Condvar::new());
    std::thread::scope(|scope| {
        let signal = &finished;
        // A thread the system cannot start (no memory for its stack) is an exception too.
        let helper = std::thread::Builder::new()
            .name("seads-work".into())
            .spawn_scoped(scope, move || {
                let out = work();
                *signal.0.lock().unwrap_or_else(|e| e.into_inner()) = true;
                signal.1.notify_all();
                out
            })
            .map_err(|e| {
                pyo3::exceptions::PyMemoryError::new_err(format!("starting a thread: {e}"))
            })?;
        let mut interrupted = None;
        loop {
            let done = py.detach(|| {
                let guard = signal.0.lock().unwrap_or_else(|e| e.into_inner());
                let (guard, _) = signal
                    .1
                    .wait_timeout_while(guard, Duration::from_millis(50), |done| !*done)
                    .unwrap_or_else(|e| e.into_inner());
                *guard
            });
            if done || helper.is_finished() {
                break;
            }
            if interrupted.is_none()
                && let Err(e) = py.check_signals()
            {
                stop();
                interrupted = Some(e);
            }
        }
        let joined = py.detach(|| helper.join());
        if let Some(e) = interrupted {
            return Err(e);
        }
        joined.map_err(panicked)
    })
}

/// Runs `work`, the body of a method Python calls: a panic in it (a defect of ours) is a
/// `RuntimeError` saying what failed, which `except Exception` catches, never pyo3's
/// `PanicException`, a `BaseException`. Every fallible method and function of the module runs
/// its body through this (or [`interruptible`]); a test lists them.
pub(crate) fn guarded<T>(work: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(work))
        .unwrap_or_else(|p| Err(panicked(p)))
}

/// A panic's payload as a `RuntimeError` with its message.
fn panicked(payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let why = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    PyRuntimeError::new_err(format!("the computation failed: {why}"))
}

/// A search that found no plan as a Python exception: `MemoryError` where the machine had no
/// memory for it, `ValueError` otherwise.
fn plan_error(e: seads_planner::PlanError) -> PyErr {
    match e {
        seads_planner::PlanError::OutOfMemory { .. } => {
            pyo3::exceptions::PyMemoryError::new_err(e.to_string())
        }
        other => value_error(other),
    }
}

/// Any error of the Rust libraries as a Python `ValueError` with its message.
fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A board's values as Python gives them: any array-like (a list, a tuple, a NumPy array of
/// integers, bools or integral floats), 1-D (row-major) or square (N × N), each value a whole
/// number 0 to 255; anything else is a `ValueError` saying what is wrong. The game then checks
/// the values themselves.
pub(crate) struct Values(pub Vec<u8>);

impl<'a, 'py> FromPyObject<'a, 'py> for Values {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let numpy = obj.py().import("numpy")?;
        let not_a_board =
            |_| value_error("a board: a sequence of its field values (whole numbers)");
        let array = numpy.call_method1("asarray", (obj,)).map_err(not_a_board)?;
        let dtype = array.getattr("dtype")?;
        let kind: String = dtype.getattr("kind")?.extract()?;
        if !matches!(kind.as_str(), "b" | "i" | "u" | "f") {
            return Err(value_error(format!(
                "a board holds whole numbers, not values of type {}",
                dtype.str()?
            )));
        }
        let shape: Vec<usize> = array.getattr("shape")?.extract()?;
        let flat = match shape.as_slice() {
            [_] => array,
            [rows, cols] if rows == cols => array.call_method0("ravel")?,
            _ => {
                return Err(value_error(format!(
                    "a board is 1-D (its values, row-major) or square (N × N), not of shape {shape:?}"
                )));
            }
        };
        let values: Vec<f64> = flat
            .call_method1("astype", ("float64",))?
            .call_method0("tolist")?
            .extract()?;
        values
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                if v.fract() == 0.0 && (0.0..=255.0).contains(&v) {
                    Ok(v as u8)
                } else {
                    Err(value_error(format!(
                        "board value {v} at field {i}: not a field value (a whole number 0 to 255)"
                    )))
                }
            })
            .collect::<PyResult<Vec<u8>>>()
            .map(Values)
    }
}

/// A move given from Python, checked against the game's `num_moves` (negative ones included).
pub(crate) fn move_arg(mv: i64, num_moves: usize) -> PyResult<usize> {
    usize::try_from(mv)
        .ok()
        .filter(|&m| m < num_moves)
        .ok_or_else(|| {
            value_error(format!(
                "move {mv}: the game has moves 0 to {}",
                num_moves.saturating_sub(1)
            ))
        })
}

/// The names of the registered environments (`lightsout-cursor`, …), as `seads envs` lists
/// them.
#[pyfunction]
fn env_names() -> Vec<&'static str> {
    seads_embodiment::env_names()
}

/// Each registered environment's name in CamelCase (`lightsout-cursor` → `LightsOutCursor`),
/// from which the Gymnasium ids are made.
#[pyfunction]
fn env_titles() -> std::collections::BTreeMap<String, String> {
    seads_embodiment::list_envs()
        .into_iter()
        .map(|e| (e.name, e.title))
        .collect()
}

/// The names of the registered games (`lightsout`, `tileswap`, `sliding`), for `Game(name)`.
#[pyfunction]
fn game_names() -> Vec<&'static str> {
    seads_games::GameKind::all().map(|g| g.name()).collect()
}

/// The Python module.
/// `_panic(message)`, for the tests only: panics with `message` inside a guarded call, as a
/// defect of ours would, so that they can show it arrives as a `RuntimeError`.
#[pyfunction]
fn _panic(message: &str) -> PyResult<()> {
    guarded(|| panic!("{message}"))
}

#[pymodule]
fn _seads(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(env_names, m)?)?;
    m.add_function(wrap_pyfunction!(env_titles, m)?)?;
    m.add_function(wrap_pyfunction!(game_names, m)?)?;
    m.add_class::<env::Env>()?;
    m.add_class::<vector::VecEnv>()?;
    m.add_class::<games::Game>()?;
    m.add_class::<agent::Agent>()?;
    m.add_function(wrap_pyfunction!(games::plan, m)?)?;
    m.add_function(wrap_pyfunction!(_panic, m)?)?;
    Ok(())
}
