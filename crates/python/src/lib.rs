//! `raylab` for Python: render, trace and bench from a notebook, NumPy arrays in and out.
//! The native module `raylab._native`; the package `raylab` (python/raylab) re-exports it
//! with the ray-file helpers and the type stubs.

mod convert;
mod errors;
mod interrupt;
mod lab;
mod rays;
mod scene;
mod settings;
mod structure;

use pyo3::prelude::*;

/// The names `accel=` accepts, the oracle `none` first.
#[pyfunction]
fn accels() -> Vec<&'static str> {
    raylab_accel::AccelKind::ALL.iter().map(|k| k.name()).collect()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("RaylabError", m.py().get_type::<errors::RaylabError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<structure::Structure>()?;
    m.add_function(wrap_pyfunction!(scene::render, m)?)?;
    m.add_function(wrap_pyfunction!(structure::trace, m)?)?;
    m.add_function(wrap_pyfunction!(structure::build, m)?)?;
    m.add_function(wrap_pyfunction!(structure::load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(lab::bench, m)?)?;
    m.add_function(wrap_pyfunction!(lab::compare, m)?)?;
    m.add_function(wrap_pyfunction!(lab::converge, m)?)?;
    m.add_function(wrap_pyfunction!(accels, m)?)?;
    Ok(())
}
