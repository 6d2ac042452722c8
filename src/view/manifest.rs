//! `manifest.json` of a run folder: what was run, with which settings, and whether it finished.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{read_text, ViewError};
use crate::diag::Diagnostic;

/// The only run-folder format this viewer reads.
pub(crate) const FORMAT: u32 = 1;

/// Whether the recorder closed the run cleanly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum RunStatus {
    /// The run reached its last tick and every file was flushed.
    Complete,
    /// The run stopped early (crash, interrupt); the last recorded tick may be partial.
    Incomplete,
}

/// The parsed `manifest.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct Manifest {
    pub format: u32,
    pub status: RunStatus,
    #[serde(default)]
    pub scenario: String,
    #[serde(default)]
    pub seed: u64,
    pub dt: f64,
    #[serde(default)]
    pub ticks: u64,
    #[serde(default = "one")]
    pub record_interval: u64,
    #[serde(default)]
    pub threads: u32,
    #[serde(default)]
    pub files: BTreeMap<String, String>,
    #[serde(default)]
    pub summary: serde_json::Value,
}

fn one() -> u64 {
    1
}

impl Manifest {
    /// Reads and checks `path`.
    pub(crate) fn read(path: &Path) -> Result<Manifest, ViewError> {
        let text = read_text(path)?;
        let m: Manifest = serde_json::from_str(&text).map_err(|e| json_error(path, &text, &e))?;
        if m.format != FORMAT {
            return Err(Diagnostic::file(
                path,
                format!(
                    "run-folder format {} is not supported (expected \"format\": {FORMAT})",
                    m.format
                ),
            )
            .into());
        }
        if !(m.dt.is_finite() && m.dt > 0.0) {
            return Err(Diagnostic::file(path, "\"dt\" must be a positive number").into());
        }
        Ok(m)
    }
}

/// A located diagnostic for a JSON parse error in `text` read from `path`.
pub(crate) fn json_error(path: &Path, text: &str, e: &serde_json::Error) -> ViewError {
    Diagnostic::new(path, e.line(), e.column(), e.to_string(), Some(text)).into()
}
