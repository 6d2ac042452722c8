//! A scenario run in-process for `shoal.run`: the same loop as `shoal run` (timed events, the
//! tick, expectations judged along the way, the health monitor after every tick), recording
//! into typed columns instead of a run folder. Nothing here touches Python: `lib.rs` calls it
//! with the interpreter released, so runs in several threads go on in parallel.
//!
//! The columns are those of the run folder's files (`shoal::record::schema`, `events.jsonl`'s
//! keys), recorded on the same ticks: every agent and food item at tick 0 and every
//! `record_interval` ticks, every event with the tick that produced it.

use crate::columns::{Column, Kind};
use serde_json::{json, Value};
use shoal::events::Event;
use shoal::health::Monitor;
use shoal::record::schema::{FOOD_COLUMNS, TRAJECTORY_COLUMNS};
use shoal::scenario::expect::Tracker;
use shoal::scenario::{Overrides, Run, Scenario, Setting};
use std::collections::HashMap;
use std::path::PathBuf;
use std::time::Instant;

/// What `shoal.run` asks for.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// The scenario file.
    pub file: PathBuf,
    /// Seed (default: the scenario's).
    pub seed: Option<u64>,
    /// Duration in seconds (default: the scenario's).
    pub duration: Option<f32>,
    /// Keys overridden (`KEY=VALUE`, value as RON text).
    pub set: Vec<Setting>,
    /// Record every this many ticks (default: the scenario's).
    pub interval: Option<u32>,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
}

/// Why a run gave no result.
#[derive(Debug)]
pub enum Failure {
    /// The scenario, a species or a setting did not load: the located diagnostics, as text.
    Load(String),
    /// Anything else (the thread pool could not start).
    Other(String),
}

/// What a finished run hands back.
pub struct Output {
    /// `trajectories.csv`'s columns.
    pub trajectories: Vec<Column>,
    /// `food.csv`'s columns.
    pub food: Vec<Column>,
    /// `events.jsonl`'s keys as columns.
    pub events: Vec<Column>,
    /// The manifest's summary.
    pub summary: Value,
    /// `health.json`.
    pub health: Value,
}

/// Loads and runs the scenario `o` names.
pub fn run(o: &Options) -> Result<Output, Failure> {
    let scenario =
        Scenario::load_with(&o.file, &o.set).map_err(|d| Failure::Load(d.to_string()))?;
    let interval = o.interval.unwrap_or(scenario.def.record.interval).max(1);
    let threads = o
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Failure::Other(format!("cannot start {threads} worker threads: {e}")))?;
    let mut run = Run::new(
        scenario,
        Overrides {
            seed: o.seed,
            duration: o.duration,
            ..Overrides::default()
        },
    );
    let mut tracker = Tracker::new(&run.scenario).map_err(|d| Failure::Load(d.to_string()))?;
    let mut monitor = Monitor::new(&run.pipeline.species, run.world.dt);
    let mut rec = Recording::new(&run, interval);
    rec.events(&run, &run.pipeline.events, run.world.tick);
    rec.states(&run);
    let start = Instant::now();
    pool.install(|| {
        while !run.finished() {
            run.step();
            rec.tick(&run);
            tracker.observe_run(&run);
            monitor.observe(&run.world, &run.pipeline);
        }
    });
    let elapsed = start.elapsed().as_secs_f64();
    let mut summary = run.summary(elapsed);
    let verdicts = if tracker.is_empty() {
        Vec::new()
    } else {
        tracker.finish(&run.world, &run.pipeline)
    };
    summary["expectations"] = Value::Array(
        verdicts
            .iter()
            .map(|v| json!({"expected": v.expected, "passed": v.passed, "observed": v.observed}))
            .collect(),
    );
    let report = monitor.report();
    summary["health"] = report.headline();
    Ok(Output {
        trajectories: rec.traj,
        food: rec.food,
        events: rec.ev.columns,
        summary,
        health: report.to_json(),
    })
}

/// The columns of a run being recorded.
struct Recording {
    interval: u64,
    traj: Vec<Column>,
    food: Vec<Column>,
    ev: Events,
    /// Per species, per behavior index: its category in the `behavior` column.
    behaviors: Vec<Vec<i32>>,
}

impl Recording {
    fn new(run: &Run, interval: u32) -> Recording {
        use shoal::record::schema::TrajColumn as T;
        let kind = |i: usize| match i {
            i if i == T::Tick as usize => Kind::U64,
            i if i == T::Time as usize => Kind::F64,
            i if i == T::Id as usize => Kind::U32,
            i if i == T::Species as usize || i == T::Behavior as usize => Kind::Dict,
            i if i == T::StackDepth as usize => Kind::U8,
            _ => Kind::F32,
        };
        let mut traj: Vec<Column> = TRAJECTORY_COLUMNS
            .iter()
            .enumerate()
            .map(|(i, name)| Column::new(name, kind(i)))
            .collect();
        let set = &run.scenario.species;
        traj[T::Species as usize].dictionary = set.species.iter().map(|s| s.name.clone()).collect();
        // One category per behavior name, shared by the species that use it.
        let mut index: HashMap<String, i32> = HashMap::new();
        let mut names = Vec::new();
        let behaviors = set
            .species
            .iter()
            .map(|s| {
                s.behaviors
                    .iter()
                    .map(|b| {
                        *index.entry(b.name.to_string()).or_insert_with(|| {
                            names.push(b.name.to_string());
                            names.len() as i32 - 1
                        })
                    })
                    .collect()
            })
            .collect();
        traj[T::Behavior as usize].dictionary = names;
        let food = FOOD_COLUMNS
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let kind = match i {
                    0 => Kind::U64,
                    1 => Kind::U32,
                    _ => Kind::F32,
                };
                Column::new(name, kind)
            })
            .collect();
        Recording {
            interval: u64::from(interval.max(1)),
            traj,
            food,
            ev: Events::new(),
            behaviors,
        }
    }

    /// What the last tick produced: its events, and the states on a recorded tick.
    fn tick(&mut self, run: &Run) {
        // Events were produced while advancing from tick − 1 to tick.
        self.events(run, &run.pipeline.events, run.world.tick.saturating_sub(1));
        if run.world.tick.is_multiple_of(self.interval) {
            self.states(run);
        }
    }

    fn events(&mut self, run: &Run, events: &[Event], tick: u64) {
        for e in events {
            let v = shoal::record::event_json(e, tick, run.world.dt, &run.scenario.species);
            self.ev.push(&v);
        }
    }

    /// Every agent's and food item's state now, in the order `trajectories.csv` has them.
    fn states(&mut self, run: &Run) {
        use shoal::record::schema::TrajColumn as T;
        let w = &run.world;
        let t = w.time();
        let n = w.agents.len();
        for c in &mut self.traj {
            c.reserve(n, 8);
        }
        let c = &mut self.traj;
        for a in &w.agents {
            let s = a.species.0 as usize;
            let f = a.forward();
            c[T::Tick as usize].u64(w.tick);
            c[T::Time as usize].f64(t);
            c[T::Id as usize].u32(a.id.0);
            c[T::Species as usize].category(s as i32);
            for (col, v) in [
                (T::X, a.pos.x),
                (T::Y, a.pos.y),
                (T::Z, a.pos.z),
                (T::Fx, f.x),
                (T::Fy, f.y),
                (T::Fz, f.z),
                (T::Speed, a.speed),
                (T::Hunger, a.drives.hunger),
                (T::Libido, a.drives.libido),
                (T::Fear, a.drives.fear),
                (T::SwimPhase, a.anim.phase),
                (
                    T::TailBend,
                    shoal::locomotion::anim::bend_of(&run.scenario.species, a),
                ),
            ] {
                c[col as usize].f32(v);
            }
            let b = a.mind.current;
            let cat = match self.behaviors[s].get(b as usize) {
                Some(&k) => k,
                // A behavior the species does not list is written as its name says ("?").
                None => {
                    let name = run.scenario.species.species[s].behavior_name(b).to_string();
                    let dict = &mut c[T::Behavior as usize].dictionary;
                    match dict.iter().position(|d| *d == name) {
                        Some(k) => k as i32,
                        None => {
                            dict.push(name);
                            dict.len() as i32 - 1
                        }
                    }
                }
            };
            c[T::Behavior as usize].category(cat);
            c[T::StackDepth as usize].u8(a.mind.depth);
        }
        for f in &w.food {
            self.food[0].u64(w.tick);
            self.food[1].u32(f.id);
            self.food[2].f32(f.pos.x);
            self.food[3].f32(f.pos.y);
            self.food[4].f32(f.pos.z);
        }
    }
}

/// The events table: one column per key `events.jsonl` uses, null where an event has no such
/// key. Two keys change so that each column has one type: a message's sender (`from`, an agent
/// id) is in `sender`, since a transition's `from` is a behavior name; a named event's
/// `payload` (an object) is its JSON text.
struct Events {
    columns: Vec<Column>,
}

/// The events table's columns, in order.
const EVENT_COLUMNS: [(&str, Kind); 17] = [
    ("tick", Kind::U64),
    ("time", Kind::F64),
    ("kind", Kind::Str),
    ("agent", Kind::U32),
    ("species", Kind::Str),
    ("cause", Kind::Str),
    ("food", Kind::U32),
    ("prey", Kind::U32),
    ("mate", Kind::U32),
    ("from", Kind::Str),
    ("to", Kind::Str),
    ("condition", Kind::Str),
    ("stack", Kind::ListStr),
    ("sender", Kind::U32),
    ("message", Kind::Str),
    ("payload", Kind::Str),
    ("radius", Kind::F32),
];

impl Events {
    fn new() -> Events {
        Events {
            columns: EVENT_COLUMNS
                .iter()
                .map(|(n, k)| Column::new(n, *k))
                .collect(),
        }
    }

    fn push(&mut self, v: &Value) {
        let Some(o) = v.as_object() else { return };
        let value = |name: &str| -> Option<&Value> {
            match name {
                "from" => o.get("from").filter(|v| v.is_string()),
                "sender" => o.get("from").filter(|v| v.is_number()),
                _ => o.get(name),
            }
            .filter(|v| !v.is_null())
        };
        for (c, (name, kind)) in self.columns.iter_mut().zip(EVENT_COLUMNS) {
            match (value(name), kind) {
                (None, _) => c.null(),
                (Some(v), Kind::U64) => c.u64(v.as_u64().unwrap_or(0)),
                (Some(v), Kind::U32) => c.u32(v.as_u64().unwrap_or(0) as u32),
                (Some(v), Kind::F64) => c.f64(v.as_f64().unwrap_or(f64::NAN)),
                (Some(v), Kind::F32) => c.f32(v.as_f64().unwrap_or(f64::NAN) as f32),
                (Some(Value::String(s)), _) => c.str(s),
                (Some(Value::Array(items)), Kind::ListStr) => {
                    c.list(items.iter().map(|i| i.as_str().unwrap_or("")))
                }
                (Some(v), _) => c.str(&v.to_string()),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_of_every_event_has_a_column() {
        let keys = [
            "tick",
            "time",
            "kind",
            "agent",
            "species",
            "cause",
            "food",
            "prey",
            "mate",
            "from",
            "to",
            "condition",
            "stack",
            "message",
            "payload",
            "radius",
        ];
        for k in keys {
            assert!(EVENT_COLUMNS.iter().any(|c| c.0 == k), "{k}");
        }
    }
}
