//! The sweep file format (`sweeps/*.ron`): plain `*Def` types read with RON. See
//! `docs/sweeps.md`, which documents every key.

use serde::de::IgnoredAny;
use serde::Deserialize;

/// A sweep file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename = "Sweep")]
pub struct SweepDef {
    /// The base scenario, relative to the sweep file.
    pub scenario: String,
    /// Every run's duration (s); the scenario's when not given.
    #[serde(default)]
    pub duration: Option<f32>,
    /// The base seed the runs' seeds are derived from (and the samplers' draws).
    #[serde(default = "one")]
    pub seed: u64,
    /// Runs per point, each with its own seed.
    #[serde(default = "one_u32")]
    pub seeds: u32,
    /// How points are made from the axes.
    #[serde(default)]
    pub sampler: SamplerDef,
    /// The keys varied, each with its values or bounds.
    pub axes: Vec<AxisDef>,
    /// What each run keeps.
    #[serde(default)]
    pub keep: KeepDef,
}

fn one() -> u64 {
    1
}
fn one_u32() -> u32 {
    1
}

/// How the points of a sweep are made.
#[derive(Debug, Clone, Default, Deserialize)]
pub enum SamplerDef {
    /// Every combination of the axes' values (the last axis varies fastest).
    #[default]
    Grid,
    /// `n` points drawn uniformly within the axes' bounds.
    Random(u32),
    /// `n` points of a Latin hypercube over the axes' bounds.
    LatinHypercube(u32),
    /// The rows of a sample file (SALib's `sample` output: whitespace-separated numbers, one
    /// column per axis in order), relative to the sweep file.
    File(String),
}

/// One varied key.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisDef {
    /// The key (`scenario.groups[0].count`, `sardine.senses.vision_radius`).
    pub key: String,
    /// Its values, as RON (grid).
    #[serde(default)]
    pub values: Option<Vec<IgnoredAny>>,
    /// Evenly spaced numbers (grid).
    #[serde(default)]
    pub range: Option<RangeDef>,
    /// Lowest and highest value (random, Latin hypercube).
    #[serde(default)]
    pub bounds: Option<(f64, f64)>,
    /// Round the numbers made for this axis to whole numbers (for integer keys).
    #[serde(default)]
    pub integer: bool,
}

/// Evenly spaced numbers from `from` to `to` (inclusive), by `step` or `count` of them.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeDef {
    /// First value.
    pub from: f64,
    /// Last value (included when a step lands on it).
    pub to: f64,
    /// Distance between values.
    #[serde(default)]
    pub step: Option<f64>,
    /// How many values, `from` and `to` included.
    #[serde(default)]
    pub count: Option<u32>,
}

/// What each run keeps in its row (and folder).
#[derive(Debug, Clone, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KeepDef {
    /// Run-health figures per species (`health.<species>.<figure>`).
    pub health: bool,
    /// Counters: alive per species, food eaten, catches, matings, transitions, script errors.
    pub counters: bool,
    /// Each expectation of the scenario: passed and observed.
    pub expectations: bool,
    /// Behavior time shares per species (`share.<species>.<behavior>`).
    pub behaviors: bool,
    /// A Rhai script, relative to the sweep file, whose `reduce(run)` returns a number or a map
    /// of numbers (`reduce` / `reduce.<key>` columns).
    pub reduce: Option<String>,
    /// Keep each run's full recording (`runs/NNNNN/recording/`, as `shoal run` writes).
    pub recordings: bool,
}

impl Default for KeepDef {
    fn default() -> Self {
        KeepDef {
            health: true,
            counters: true,
            expectations: true,
            behaviors: true,
            reduce: None,
            recordings: false,
        }
    }
}
