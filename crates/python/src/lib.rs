//! The Python package `piezocontact`: a thin layer over the typed library core (`problem`) and
//! the scene files, mesh files and outputs of the `files` crate. No method logic lives here: a
//! `Scene` (module `scene`) is the scene file's TOML tree and the typed scene it validates to,
//! `run` (module `run`) calls the same solve as the command line, and a `Result` (module
//! `result`) lends the solution's arrays to NumPy without copies.
//!
//! Built with maturin (`pip install ./crates/python`); tested by pytest (`crates/python/tests`).
//! The type stubs are `piezocontact.pyi`.

mod arrays;
mod errors;
mod result;
mod run;
mod scene;
mod values;

use pyo3::prelude::*;

/// Static frictional contact of piezoelectric bodies with a rigid foundation: scenes in, NumPy
/// arrays out.
#[pymodule]
fn piezocontact(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<result::RunResult>()?;
    m.add_class::<result::Contact>()?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::capacitance, m)?)?;
    m.add("STICK", result::STICK)?;
    m.add("SLIP", result::SLIP)?;
    m.add("SEPARATED", result::SEPARATED)?;
    errors::register(m)?;
    Ok(())
}
