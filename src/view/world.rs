//! `world.json` of a run folder: bounds, obstacles, species, terrain and formation plans.
//!
//! Read into typed values so a malformed file is reported with its line, then passed to the page
//! unchanged in shape (the live server sends the same JSON).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::manifest::json_error;
use super::{read_text, ViewError};
use crate::diag::Diagnostic;

/// Axis-aligned bounds of the simulated volume.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct Bounds {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

/// A static obstacle; `removed_tick` is when a scenario took it away, if it did.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "lowercase")]
pub(crate) enum Obstacle {
    /// A ball.
    Sphere {
        id: u64,
        center: [f32; 3],
        radius: f32,
        #[serde(default)]
        removed_tick: Option<u64>,
    },
    /// An axis-aligned box.
    Box {
        id: u64,
        min: [f32; 3],
        max: [f32; 3],
        #[serde(default)]
        removed_tick: Option<u64>,
    },
    /// An upright cylinder standing on `base`.
    Cylinder {
        id: u64,
        base: [f32; 3],
        radius: f32,
        height: f32,
        #[serde(default)]
        removed_tick: Option<u64>,
    },
}

/// One species as the page needs it: name, display color, body length and its behaviors.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct SpeciesInfo {
    pub name: String,
    #[serde(default = "default_color")]
    pub color: String,
    #[serde(default = "default_length")]
    pub length: f32,
    #[serde(default)]
    pub behaviors: Vec<String>,
    /// How the page draws the species; recordings from before looks were written have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub look: Option<LookInfo>,
    /// Per behavior: priority, interrupt flag, condition texts and source location (passed to
    /// the page's state-machine graph as written; absent in older runs).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub behavior_info: Vec<serde_json::Value>,
}

/// A species' look as `world.json` carries it (see `species::def::look::Look`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct LookInfo {
    pub shape: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outline: Vec<[f32; 2]>,
    #[serde(default = "default_length")]
    pub length: f32,
    #[serde(default = "default_color")]
    pub color: String,
    #[serde(default)]
    pub behavior_colors: std::collections::BTreeMap<String, String>,
}

fn default_color() -> String {
    "#c0c0c0".to_string()
}

fn default_length() -> f32 {
    1.0
}

/// A height field over the XZ plane; row 0 is the smallest z.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct Terrain {
    pub origin: [f32; 2],
    pub cell: f32,
    pub cols: usize,
    pub rows: usize,
    pub heights: Vec<f32>,
    #[serde(default)]
    pub blocked: Vec<u8>,
}

/// A formation change along a plan.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct PlanTransition {
    pub at: [f32; 3],
    pub formation: String,
}

/// A leader's planned route with its formation slots.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct Plan {
    pub agent: u64,
    #[serde(default)]
    pub path: Vec<[f32; 3]>,
    #[serde(default)]
    pub key_points: Vec<[f32; 3]>,
    #[serde(default)]
    pub transitions: Vec<PlanTransition>,
    #[serde(default)]
    pub slots: Vec<Vec<[f32; 3]>>,
}

/// The parsed `world.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct World {
    pub bounds: Bounds,
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    #[serde(default)]
    pub species: Vec<SpeciesInfo>,
    #[serde(default)]
    pub terrain: Option<Terrain>,
    #[serde(default)]
    pub plans: Vec<Plan>,
}

impl World {
    /// Reads and checks `path`.
    pub(crate) fn read(path: &Path) -> Result<World, ViewError> {
        let text = read_text(path)?;
        let w: World = serde_json::from_str(&text).map_err(|e| json_error(path, &text, &e))?;
        if let Some(t) = &w.terrain {
            let cells = t.cols * t.rows;
            if t.heights.len() != cells {
                return Err(Diagnostic::file(
                    path,
                    format!(
                        "terrain has {} heights, expected cols * rows = {cells}",
                        t.heights.len()
                    ),
                )
                .into());
            }
            if !t.blocked.is_empty() && t.blocked.len() != cells {
                return Err(Diagnostic::file(
                    path,
                    format!(
                        "terrain has {} blocked flags, expected cols * rows = {cells}",
                        t.blocked.len()
                    ),
                )
                .into());
            }
        }
        Ok(w)
    }
}
