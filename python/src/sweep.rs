//! Sweeps from Python (`shoal.sweep`): a sweep file's plan, one entry run into its folder, the
//! collected table, over `shoal::sweep` (the code `shoal sweep plan / run / collect` runs), with
//! the interpreter released while runs go on. Reads and writes only what those commands do.

use crate::columns::{self, Column, Kind};
use crate::LoadError;
use pyo3::exceptions::{PyIndexError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use shoal::sweep::table::{Cell, ColumnType};
use shoal::sweep::{EntryStatus, Plan, SweepError};
use std::path::{Path, PathBuf};

fn load(path: &Path) -> PyResult<Plan> {
    Plan::load(path).map_err(|d| LoadError::new_err(d.to_string()))
}

fn failed(e: SweepError) -> PyErr {
    PyRuntimeError::new_err(e.0)
}

/// The entries of the sweep file `path`: dicts of `index`, `point`, `replicate`, `seed`,
/// `settings` (`[(key, RON text)]`, one per axis) and `values` (the axes' values as RON text).
#[pyfunction]
fn sweep_plan(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyList>> {
    let plan = py.detach(|| load(&path))?;
    let entries = (0..plan.len())
        .map(|i| {
            let e = plan.entry(i);
            let d = PyDict::new(py);
            d.set_item("index", e.index)?;
            d.set_item("point", e.point)?;
            d.set_item("replicate", e.replicate)?;
            d.set_item("seed", e.seed)?;
            let set: Vec<(&str, &str)> = e
                .set
                .iter()
                .map(|s| (s.key.as_str(), s.value.as_str()))
                .collect();
            d.set_item("settings", set)?;
            let values: Vec<(&str, &str)> = plan
                .keys
                .iter()
                .map(String::as_str)
                .zip(e.values())
                .collect();
            d.set_item("values", values)?;
            Ok(d)
        })
        .collect::<PyResult<Vec<_>>>()?;
    PyList::new(py, entries)
}

/// Writes (or checks) the sweep manifest of `out` for the sweep file `path`, as
/// `shoal sweep run` does before its first run: done once by a driver before it hands entries to
/// workers.
#[pyfunction]
fn sweep_prepare(py: Python<'_>, path: PathBuf, out: PathBuf) -> PyResult<()> {
    py.detach(|| {
        let plan = load(&path)?;
        shoal::sweep::prepare(&plan, &out).map_err(failed)
    })
}

/// The indices of the entries whose run folder is not in `out` yet, in order.
#[pyfunction]
fn sweep_pending(py: Python<'_>, path: PathBuf, out: PathBuf) -> PyResult<Vec<usize>> {
    py.detach(|| {
        let plan = load(&path)?;
        Ok((0..plan.len())
            .filter(|&i| !shoal::sweep::exec::run_dir(&out, i).exists())
            .collect())
    })
}

/// Runs entry `index` of the sweep file `path` into `out` (`shoal sweep run --index`):
/// `"done"`, `"skipped"` (its folder was there) or `"failed"` (recorded in its folder).
#[pyfunction]
fn sweep_run_entry(
    py: Python<'_>,
    path: PathBuf,
    index: usize,
    out: PathBuf,
    threads: usize,
) -> PyResult<&'static str> {
    py.detach(|| {
        let plan = load(&path)?;
        if index >= plan.len() {
            return Err(PyIndexError::new_err(format!(
                "no run {index}: the sweep has {} (0-{})",
                plan.len(),
                plan.len().saturating_sub(1)
            )));
        }
        let status = shoal::sweep::run_entry(&plan, index, &out, threads.max(1)).map_err(failed)?;
        Ok(match status {
            EntryStatus::Done => "done",
            EntryStatus::Skipped => "skipped",
            EntryStatus::Failed(_) => "failed",
        })
    })
}

/// The collected table of `out` (`shoal sweep collect`) as columns: whole numbers as `int64`,
/// decimals as `float64`, booleans as `bool`, text as `string`; null where a run has no value.
#[pyfunction]
#[pyo3(signature = (out, partial=false))]
fn sweep_collect(py: Python<'_>, out: PathBuf, partial: bool) -> PyResult<Bound<'_, PyList>> {
    let columns = py.detach(|| -> PyResult<Vec<Column>> {
        let t = if partial {
            shoal::sweep::collect_partial(&out)
        } else {
            shoal::sweep::collect(&out)
        }
        .map_err(failed)?;
        Ok(t.names
            .iter()
            .enumerate()
            .map(|(c, name)| {
                let kind = match t.types[c] {
                    ColumnType::Bool => Kind::Bool,
                    ColumnType::Int => Kind::I64,
                    ColumnType::Float => Kind::F64,
                    ColumnType::Text => Kind::Str,
                };
                let mut col = Column::named(name.clone(), kind);
                for r in 0..t.rows.len() {
                    match t.get(r, c) {
                        None => col.null(),
                        Some(Cell::Bool(b)) => col.bool(b),
                        Some(Cell::Int(i)) => col.i64(i),
                        Some(Cell::Float(x)) => col.f64(x),
                        Some(Cell::Text(s)) => col.str(&s),
                    }
                }
                col
            })
            .collect())
    })?;
    columns::into_py(py, columns)
}

/// Adds the sweep functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sweep_plan, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_prepare, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_pending, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_run_entry, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_collect, m)?)?;
    Ok(())
}
