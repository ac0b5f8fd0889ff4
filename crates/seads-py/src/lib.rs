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

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

mod agent;
mod env;
mod games;
mod render;
mod vector;

/// Any error of the Rust libraries as a Python `ValueError` with its message.
fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The names of the registered environments (`lightsout-cursor`, …), as `seads envs` lists
/// them.
#[pyfunction]
fn env_names() -> Vec<&'static str> {
    seads_embodiment::env_names()
}

/// The Python module.
#[pymodule]
fn _seads(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(env_names, m)?)?;
    m.add_class::<env::Env>()?;
    m.add_class::<vector::VecEnv>()?;
    m.add_class::<games::Game>()?;
    m.add_class::<agent::Agent>()?;
    m.add_function(wrap_pyfunction!(games::plan, m)?)?;
    Ok(())
}
