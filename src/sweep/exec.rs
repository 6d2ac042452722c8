//! Running one entry of a sweep into `OUT/runs/NNNNN/`: the run is made in a temporary folder
//! beside it and renamed into place when its row is written, so a folder that exists is whole (a
//! killed run leaves only a `.tmp-…` folder, which nothing reads) and a sweep resumes by skipping
//! the folders there. What a row holds: the entry, the counters, health figures, expectations,
//! behavior shares and the Rhai reduction the sweep keeps, never a wall-clock time. The output
//! folder's manifest (`sweep.json`) records the engine version and the inputs' hashes; adding to
//! a folder made from other inputs is refused.

use super::table::{row_json, Cell, Row};
use super::{Entry, Plan};
use crate::health::Monitor;
use crate::load::{Diagnostic, Diagnostics};
use crate::scenario::{Overrides, Run, Scenario};
use rhai::{Dynamic, Map};
use std::path::{Path, PathBuf};

/// A sweep that cannot go on: a folder that cannot be written or read, changed inputs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SweepError(pub String);

impl std::fmt::Display for SweepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SweepError {}

/// What [`run_entry`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EntryStatus {
    /// The run finished; its row is written.
    Done,
    /// Its folder was already there (a finished run, kept).
    Skipped,
    /// The run failed (its scenario did not load, or the reduction failed); the error is in
    /// its row and folder.
    Failed(String),
}

/// The folder of run `i`.
pub fn run_dir(out: &Path, i: usize) -> PathBuf {
    out.join("runs").join(format!("{i:05}"))
}

fn io(p: &Path) -> impl Fn(std::io::Error) -> SweepError + '_ {
    move |e| SweepError(format!("{}: {e}", p.display()))
}

/// `a-b` ranges of sorted indices, comma-separated (`3,5,8-11`).
pub fn ranges(v: &[usize]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < v.len() {
        let mut j = i;
        while j + 1 < v.len() && v[j + 1] == v[j] + 1 {
            j += 1;
        }
        out.push(if i == j {
            v[i].to_string()
        } else {
            format!("{}-{}", v[i], v[j])
        });
        i = j + 1;
    }
    out.join(",")
}

/// The sweep manifest of `out`.
pub fn read_manifest(out: &Path) -> Result<serde_json::Value, SweepError> {
    let f = out.join("sweep.json");
    let t = std::fs::read_to_string(&f).map_err(|e| {
        SweepError(format!(
            "{}: {e} (not a sweep output folder: `shoal sweep run` writes it)",
            f.display()
        ))
    })?;
    serde_json::from_str(&t).map_err(|e| SweepError(format!("{}: {e}", f.display())))
}

/// Writes `out/sweep.json` for `plan`, or checks the one there was made from the same inputs
/// (naming each file that changed).
pub fn prepare(plan: &Plan, out: &Path) -> Result<(), SweepError> {
    std::fs::create_dir_all(out.join("runs")).map_err(io(out))?;
    let inputs: serde_json::Map<String, serde_json::Value> = plan
        .inputs
        .iter()
        .map(|(n, h)| (n.clone(), serde_json::json!(h)))
        .collect();
    if out.join("sweep.json").is_file() {
        let m = read_manifest(out)?;
        if m["inputs_hash"] == serde_json::json!(plan.inputs_hash()) {
            return Ok(());
        }
        let before = m["inputs"].as_object().cloned().unwrap_or_default();
        let mut changed: Vec<String> = Vec::new();
        for (n, h) in &inputs {
            match before.get(n) {
                Some(b) if b == h => {}
                Some(_) => changed.push(format!("{n} changed")),
                None => changed.push(format!("{n} is new")),
            }
        }
        for n in before.keys().filter(|n| !inputs.contains_key(*n)) {
            changed.push(format!("{n} is no longer an input"));
        }
        if changed.is_empty() {
            changed.push("the engine version or the plan changed".to_string());
        }
        return Err(SweepError(format!(
            "{} holds runs of other inputs: {}; run into another folder (or delete this one)",
            out.display(),
            changed.join(", ")
        )));
    }
    let m = serde_json::json!({
        "format": 1,
        "engine": env!("CARGO_PKG_VERSION"),
        "sweep_file": plan.file.display().to_string(),
        "runs": plan.len(),
        "points": plan.points(),
        "seeds": plan.def.seeds,
        "keys": plan.keys,
        "inputs": inputs,
        "inputs_hash": plan.inputs_hash(),
    });
    let text = serde_json::to_string_pretty(&m).map_err(|e| SweepError(e.to_string()))?;
    crate::record::write_atomic(&out.join("sweep.json"), text.as_bytes()).map_err(io(out))
}

/// Runs entry `index` of `plan` into `out/runs/NNNNN/` on `threads` worker threads, unless that
/// folder is already there. `out` must hold the plan's manifest ([`prepare`]; `shoal sweep run`
/// writes it), which is checked first.
pub fn run_entry(
    plan: &Plan,
    index: usize,
    out: &Path,
    threads: usize,
) -> Result<EntryStatus, SweepError> {
    if index >= plan.len() {
        return Err(SweepError(format!(
            "no run {index}: the sweep has {} (0-{})",
            plan.len(),
            plan.len().saturating_sub(1)
        )));
    }
    prepare(plan, out)?;
    let dest = run_dir(out, index);
    if dest.exists() {
        return Ok(EntryStatus::Skipped);
    }
    let nonce = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let tmp = out
        .join("runs")
        .join(format!(".tmp-{index:05}-{}-{nonce}", std::process::id()));
    std::fs::create_dir_all(&tmp).map_err(io(&tmp))?;
    let entry = plan.entry(index);
    let (row, status) = match execute(plan, entry, &tmp, threads) {
        Ok(row) => (row, EntryStatus::Done),
        Err(e) => {
            let mut row = head(plan, entry);
            row.push(("status".into(), Cell::Text("failed".into())));
            row.push(("error".into(), Cell::Text(e.clone())));
            (row, EntryStatus::Failed(e))
        }
    };
    if let EntryStatus::Failed(e) = &status {
        std::fs::write(tmp.join("error.txt"), e).map_err(io(&tmp))?;
    }
    std::fs::write(tmp.join("result.json"), row_json(&row)).map_err(io(&tmp))?;
    match std::fs::rename(&tmp, &dest) {
        Ok(()) => Ok(status),
        // Another process finished the same entry first: its folder is as good as this one.
        Err(_) if dest.exists() => {
            let _ = std::fs::remove_dir_all(&tmp);
            Ok(EntryStatus::Skipped)
        }
        Err(e) => Err(io(&dest)(e)),
    }
}

/// The columns every row starts with: the entry and its axis values.
fn head(plan: &Plan, e: &Entry) -> Row {
    let mut row: Row = vec![
        ("index".into(), Cell::Int(e.index as i64)),
        ("point".into(), Cell::Int(e.point as i64)),
        ("replicate".into(), Cell::Int(i64::from(e.replicate))),
        // Seeds above i64::MAX stay exact as text.
        ("seed".into(), Cell::Text(e.seed.to_string())),
    ];
    for (k, v) in plan.keys.iter().zip(e.values()) {
        let cell = if let Ok(i) = v.parse::<i64>() {
            Cell::Int(i)
        } else if let Ok(x) = v.parse::<f64>() {
            Cell::Float(x)
        } else {
            Cell::Text(v.to_string())
        };
        row.push((k.clone(), cell));
    }
    row
}

/// Runs `e` to its end (recording into `dir/recording` when the sweep keeps recordings) and
/// returns its row; the error is the run's, as text.
fn execute(plan: &Plan, e: &Entry, dir: &Path, threads: usize) -> Result<Row, String> {
    let keep = &plan.def.keep;
    let scenario = Scenario::load_with(&plan.scenario, &e.set).map_err(|d| d.to_string())?;
    let mut run = Run::new(
        scenario,
        Overrides {
            seed: Some(e.seed),
            duration: plan.def.duration,
            set: e.set.clone(),
        },
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| e.to_string())?;
    let mut tracker = if keep.expectations {
        Some(crate::scenario::expect::Tracker::new(&run.scenario).map_err(|d| d.to_string())?)
    } else {
        None
    };
    let mut monitor = keep
        .health
        .then(|| Monitor::new(&run.pipeline.species, run.world.dt));
    let interval = run.scenario.def.record.interval.max(1);
    let mut rec = if keep.recordings {
        let r = crate::record::Recorder::start(&dir.join("recording"), &run, interval, threads)
            .map_err(|e| e.to_string())?;
        Some(r)
    } else {
        None
    };
    if let Some(r) = rec.as_mut() {
        r.states(&run).map_err(|e| e.to_string())?;
    }
    pool.install(|| -> Result<(), String> {
        while !run.finished() {
            run.step();
            if let Some(r) = rec.as_mut() {
                r.record_tick(&run).map_err(|e| e.to_string())?;
            }
            if let Some(t) = tracker.as_mut() {
                t.observe_run(&run);
            }
            if let Some(m) = monitor.as_mut() {
                m.observe(&run.world, &run.pipeline);
            }
        }
        Ok(())
    })?;
    let mut row = head(plan, e);
    row.push(("status".into(), Cell::Text("ok".into())));
    row.push(("error".into(), Cell::Text(String::new())));
    row.push(("ticks".into(), Cell::Int(run.world.tick as i64)));
    let s = &run.pipeline.stats;
    if keep.counters {
        for (sp, n) in run.alive() {
            row.push((format!("alive.{sp}"), Cell::Int(n as i64)));
        }
        for (name, v) in [
            ("food_eaten", s.meals),
            ("catches", s.catches),
            ("matings", s.matings),
            ("transitions", s.transitions),
            ("script_errors", s.script_errors),
        ] {
            row.push((name.into(), Cell::Int(v as i64)));
        }
    }
    if keep.behaviors {
        for (i, sp) in run.scenario.species.species.iter().enumerate() {
            let counts = &s.behavior_ticks[i];
            let total: u64 = counts.iter().sum();
            for (b, n) in sp.behaviors.iter().zip(counts) {
                let share = if total > 0 {
                    *n as f64 / total as f64
                } else {
                    0.0
                };
                row.push((format!("share.{}.{}", sp.name, b.name), Cell::Float(share)));
            }
        }
    }
    if let Some(m) = monitor {
        let h = m.report().headline();
        if let Some(species) = h["species"].as_object() {
            for (sp, figs) in species {
                for (k, v) in figs.as_object().into_iter().flatten() {
                    let cell = match v {
                        serde_json::Value::Number(n) if n.is_i64() => {
                            Cell::Int(n.as_i64().unwrap_or(0))
                        }
                        serde_json::Value::Number(n) => Cell::Float(n.as_f64().unwrap_or(0.0)),
                        _ => continue,
                    };
                    row.push((format!("health.{sp}.{k}"), cell));
                }
            }
        }
        row.push((
            "health.coincident_max".into(),
            Cell::Int(h["coincident_max"].as_i64().unwrap_or(0)),
        ));
        row.push((
            "health.warnings".into(),
            Cell::Int(h["warnings"].as_array().map_or(0, |w| w.len()) as i64),
        ));
    }
    if let Some(t) = tracker.filter(|t| !t.is_empty()) {
        for (i, v) in t.finish(&run.world, &run.pipeline).iter().enumerate() {
            row.push((format!("expect.{i}.passed"), Cell::Bool(v.passed)));
            row.push((
                format!("expect.{i}.observed"),
                Cell::Text(v.observed.to_string()),
            ));
        }
    }
    if let Some((file, text)) = &plan.reduce {
        for (k, v) in reduce(file, text, &run)? {
            row.push((k, v));
        }
    }
    if let Some(r) = rec {
        let summary = serde_json::json!({ "ticks": run.world.tick });
        r.finish(&run, threads, summary)
            .map_err(|e| e.to_string())?;
    }
    Ok(row)
}

/// The engine reductions run in: the species scripts' sandbox, with room for every agent.
fn engine() -> rhai::Engine {
    let limits = crate::script::SandboxLimits {
        max_operations: 100_000_000,
        max_array_size: 10_000_000,
        max_map_size: 100_000,
        ..Default::default()
    };
    crate::script::new_engine(&limits)
}

/// Checks a reduction script: it compiles and defines `reduce(run)`.
pub fn check_reduce(file: &Path, text: &str) -> Result<(), Diagnostics> {
    crate::script::check_size(file, text, "reduction script")?;
    let mut engine = engine();
    crate::script::exact_power(&mut engine, text);
    let ast = engine
        .compile(text)
        .map_err(|e| Diagnostics::from(crate::script::parse_diag(file, text, &e)))?;
    if !ast
        .iter_functions()
        .any(|f| f.name == "reduce" && f.params.len() == 1)
    {
        return Err(Diagnostic::new(
            file,
            1,
            1,
            "a reduction script defines `fn reduce(run)`, returning a number or a map of numbers",
            Some(text),
        )
        .into());
    }
    Ok(())
}

/// Calls `reduce(run)` of the script on the finished run: `run.summary` (ticks, time, seed,
/// alive per species, counters) and `run.agents` (id, species, position, velocity, speed,
/// behavior). A number is the `reduce` column; a map's numbers are `reduce.<key>` columns.
fn reduce(file: &Path, text: &str, run: &Run) -> Result<Row, String> {
    crate::script::check_size(file, text, "reduction script").map_err(|d| d.to_string())?;
    let mut engine = engine();
    crate::script::exact_power(&mut engine, text);
    let ast = engine
        .compile(text)
        .map_err(|e| crate::script::parse_diag(file, text, &e).to_string())?;
    let s = &run.pipeline.stats;
    let mut summary = Map::new();
    let int = |v: u64| Dynamic::from(v as i64);
    summary.insert("ticks".into(), int(run.world.tick));
    summary.insert("time".into(), Dynamic::from(run.world.time() as f32));
    summary.insert("seed".into(), Dynamic::from(run.world.seed as i64));
    let alive: Map = run
        .alive()
        .into_iter()
        .map(|(k, v)| (k.into(), int(v as u64)))
        .collect();
    summary.insert("alive".into(), alive.into());
    summary.insert("food_eaten".into(), int(s.meals));
    summary.insert("catches".into(), int(s.catches));
    summary.insert("matings".into(), int(s.matings));
    summary.insert("transitions".into(), int(s.transitions));
    let species = &run.scenario.species.species;
    let vec3 = |v: glam::Vec3| -> Dynamic {
        vec![Dynamic::from(v.x), Dynamic::from(v.y), Dynamic::from(v.z)].into()
    };
    let agents: rhai::Array = run
        .world
        .agents
        .iter()
        .map(|a| {
            let sp = &species[a.species.0 as usize];
            let mut m = Map::new();
            m.insert("id".into(), Dynamic::from(i64::from(a.id.0)));
            m.insert("species".into(), sp.name.clone().into());
            m.insert("position".into(), vec3(a.pos));
            m.insert("velocity".into(), vec3(a.velocity()));
            m.insert("speed".into(), Dynamic::from(a.speed));
            m.insert(
                "behavior".into(),
                sp.behavior_name(a.mind.current).to_string().into(),
            );
            Dynamic::from(m)
        })
        .collect();
    let mut arg = Map::new();
    arg.insert("summary".into(), summary.into());
    arg.insert("agents".into(), agents.into());
    let out: Dynamic = engine
        .call_fn(
            &mut rhai::Scope::new(),
            &ast,
            "reduce",
            (Dynamic::from(arg),),
        )
        .map_err(|e| {
            let (l, c) = crate::script::position_of(e.position());
            format!(
                "{}:{l}:{c}: reduce: {}",
                file.display(),
                crate::script::bare_message(&e)
            )
        })?;
    let number = |v: &Dynamic| -> Option<Cell> {
        if let Ok(i) = v.as_int() {
            Some(Cell::Int(i))
        } else if let Ok(x) = v.as_float() {
            Some(Cell::Float(f64::from(x)))
        } else {
            v.as_bool().ok().map(Cell::Bool)
        }
    };
    if let Some(c) = number(&out) {
        return Ok(vec![("reduce".into(), c)]);
    }
    if let Some(m) = out.clone().try_cast::<Map>() {
        let mut keys: Vec<_> = m.keys().cloned().collect();
        keys.sort();
        let mut row = Row::new();
        for k in keys {
            let c = number(&m[&k])
                .ok_or_else(|| format!("{}: reduce: `{k}` is not a number", file.display()))?;
            row.push((format!("reduce.{k}"), c));
        }
        return Ok(row);
    }
    Err(format!(
        "{}: reduce returned {}; expected a number or a map of numbers",
        file.display(),
        out.type_name()
    ))
}
