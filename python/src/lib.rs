//! `shoal._native`, the extension module of the Python package `shoal` (`python/shoal/`): runs a
//! scenario in-process ([`run`]) and the entries of a sweep ([`sweep`]), with the interpreter
//! released while the engine works. It hands back plain data (typed column buffers, JSON text);
//! the Python side wraps them into `pyarrow` tables and dicts. Reads scenario and sweep files
//! through the engine's loaders only.

mod columns;
mod run;
mod sweep;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use shoal::scenario::Setting;
use std::path::PathBuf;

pyo3::create_exception!(
    _native,
    LoadError,
    pyo3::exceptions::PyValueError,
    "A scenario, species, sweep file or setting did not load; the message holds the located \
     diagnostics (file:line:col)."
);

/// `(key, RON text)` pairs as settings, read as `shoal run --set KEY=VALUE` reads them.
fn settings(set: Vec<(String, String)>) -> PyResult<Vec<Setting>> {
    set.into_iter()
        .map(|(key, value)| Setting::parse(&format!("{key}={value}")).map_err(LoadError::new_err))
        .collect()
}

/// Runs `scenario` to its end in this process and returns its tables' columns and its summary
/// and health as JSON text (see `shoal.run`, which wraps it).
#[pyfunction]
#[pyo3(signature = (scenario, seed=None, duration=None, set=Vec::new(), record_interval=None, threads=None))]
fn run_scenario<'py>(
    py: Python<'py>,
    scenario: PathBuf,
    seed: Option<u64>,
    duration: Option<f32>,
    set: Vec<(String, String)>,
    record_interval: Option<u32>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = run::Options {
        file: scenario,
        seed,
        duration,
        set: settings(set)?,
        interval: record_interval,
        threads,
    };
    let out = py.detach(|| run::run(&options)).map_err(|e| match e {
        run::Failure::Load(m) => LoadError::new_err(m),
        run::Failure::Other(m) => pyo3::exceptions::PyRuntimeError::new_err(m),
    })?;
    let d = PyDict::new(py);
    d.set_item("trajectories", columns::into_py(py, out.trajectories)?)?;
    d.set_item("food", columns::into_py(py, out.food)?)?;
    d.set_item("events", columns::into_py(py, out.events)?)?;
    d.set_item("summary", out.summary.to_string())?;
    d.set_item("health", out.health.to_string())?;
    Ok(d)
}

/// The engine's version (`shoal --version`).
#[pyfunction]
fn engine_version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("LoadError", m.py().get_type::<LoadError>())?;
    m.add_function(wrap_pyfunction!(run_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(engine_version, m)?)?;
    sweep::register(m)?;
    Ok(())
}
