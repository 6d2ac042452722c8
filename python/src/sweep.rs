//! Sweeps from Python (`shoal.sweep`): plan, run one entry, collect, over `shoal::sweep`.

use pyo3::prelude::*;

/// Adds the sweep functions to the module.
pub fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
