//! The run's health report (`health.json`, written by `shoal run`) as the page's compact `health`
//! section: the headline figures per species with their bounds, and the warnings with a tick and an
//! agent to jump to.

use std::path::Path;

use serde_json::{json, Value};

use crate::health::{self, Health, SpeciesHealth};

/// One column of the page's health table.
struct Column {
    key: &'static str,
    label: &'static str,
    /// How the page formats it: `share` (percent), `count`, `rate` (2 decimals), `ratio` (×).
    kind: &'static str,
    bound: Option<f64>,
    value: fn(&SpeciesHealth) -> Option<f64>,
    /// The figure whose bound may not apply to a species (see [`SpeciesHealth::judged`]);
    /// `None`: always judged.
    figure: Option<health::Figure>,
}

const COLUMNS: [Column; 9] = [
    Column {
        key: "stopped_share",
        label: "stopped",
        kind: "share",
        bound: Some(health::MAX_STOPPED_SHARE),
        value: |s| Some(s.stopped_share),
        figure: None,
    },
    Column {
        key: "frozen_agents",
        label: "frozen",
        kind: "count",
        bound: Some(health::MAX_FROZEN as f64),
        value: |s| Some(s.frozen_agents as f64),
        figure: None,
    },
    Column {
        key: "pitch_limit_share",
        label: "pitch limit",
        kind: "share",
        bound: Some(health::MAX_PITCH_LIMIT_SHARE),
        value: |s| Some(s.pitch_limit_share),
        // An upright species (a jellyfish's bell) rests at the limit.
        figure: Some(health::Figure::PitchLimit),
    },
    Column {
        key: "switch_rate",
        label: "switch/s",
        kind: "rate",
        bound: Some(health::MAX_SWITCH_RATE),
        value: |s| Some(s.switch_rate),
        figure: None,
    },
    Column {
        key: "short_episode_share",
        label: "short ep.",
        kind: "share",
        bound: Some(health::MAX_SHORT_EPISODE_SHARE),
        value: |s| Some(s.short_episode_share),
        figure: Some(health::Figure::ShortEpisodes),
    },
    Column {
        key: "turning_waste",
        label: "turn waste",
        kind: "ratio",
        bound: Some(health::MAX_TURNING_WASTE),
        value: |s| s.turning_waste,
        figure: None,
    },
    Column {
        key: "overlap_share",
        label: "overlap",
        kind: "share",
        bound: Some(health::MAX_OVERLAP_SHARE),
        value: |s| Some(s.overlap_share),
        figure: None,
    },
    Column {
        key: "obstacle_penetration",
        label: "obstacles",
        kind: "count",
        bound: Some(health::MAX_OBSTACLE_PENETRATION as f64),
        value: |s| Some(s.obstacle_penetration() as f64),
        figure: None,
    },
    Column {
        key: "messages_per_agent_second",
        label: "msg/s",
        kind: "rate",
        bound: None,
        value: |s| Some(s.messages_per_agent_second),
        figure: None,
    },
];

/// The `health` section for the run folder `dir`: `Value::Null` when it has no `health.json`
/// (older runs); a `health.json` that cannot be read adds a note instead of failing the page.
pub(crate) fn section(dir: &Path, notes: &mut Vec<String>) -> Value {
    let path = dir.join(health::FILE);
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Value::Null,
        Err(e) => {
            notes.push(format!("{}: not shown ({e})", health::FILE));
            return Value::Null;
        }
    };
    match serde_json::from_str::<Health>(&text) {
        Ok(h) => to_meta(&h),
        Err(e) => {
            notes.push(format!(
                "{}: not shown (line {}, column {}: {e})",
                health::FILE,
                e.line(),
                e.column()
            ));
            Value::Null
        }
    }
}

/// The compact form of a report: columns with their bounds, per species its values and which of
/// them are past their bound, and the warnings.
pub(crate) fn to_meta(h: &Health) -> Value {
    let columns: Vec<Value> = COLUMNS
        .iter()
        .map(|c| json!({ "key": c.key, "label": c.label, "kind": c.kind, "bound": c.bound }))
        .collect();
    let species: Vec<Value> = h
        .species
        .iter()
        .map(|s| {
            let values: Vec<Option<f64>> = COLUMNS.iter().map(|c| (c.value)(s)).collect();
            let over: Vec<bool> = COLUMNS
                .iter()
                .zip(&values)
                .map(|(c, v)| {
                    c.figure.is_none_or(|f| s.judged(f))
                        && matches!((v, c.bound), (Some(v), Some(b)) if *v > b)
                })
                .collect();
            // Why a figure shown is not held to its bound (null where it is).
            let unjudged: Vec<Option<String>> = COLUMNS
                .iter()
                .map(|c| c.figure.and_then(|f| s.not_judged_because(f)))
                .collect();
            json!({ "name": s.name, "agents": s.agents, "values": values, "over": over,
                    "unjudged": unjudged })
        })
        .collect();
    let warnings: Vec<Value> = h
        .warnings()
        .iter()
        .map(|w| {
            json!({
                "message": w.message,
                "tick": w.tick,
                "agent": w.agent,
                "species": w.species,
            })
        })
        .collect();
    json!({
        "ticks": h.ticks,
        "columns": columns,
        "species": species,
        "coincident": {
            "max": h.coincident.max,
            "bound": health::MAX_COINCIDENT,
            "over": h.coincident.max > health::MAX_COINCIDENT,
        },
        "warnings": warnings,
    })
}
