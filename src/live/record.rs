//! The record of a live session: every version of the scenario that ran, with the tick it took
//! effect at and a copy of its files, and every rejected edit, so that the session can be re-run
//! exactly ([`rerun`]).
//!
//! Folder layout: `live.json` (`{"seed", "dt", "scenario", "status"}`), `reloads.jsonl` (one line
//! per version or rejected edit: `{"time_ms", "status": "initial"|"accepted"|"rejected",
//! "version", "tick", "scenario", "files": {path: sha256}, "diagnostics"}`, and a last
//! `{"status": "stopped", "tick", "reason"}` when the session ends) and `versions/<n>/` (the files
//! of version `n`, laid out as they were relative to their common folder).
//!
//! Like a run folder (`crate::record`), a record is marked incomplete from the start: `live.json`
//! says `"status": "recording"` and an `INCOMPLETE` file is there while the session runs. A
//! session only ever ends by being stopped, so when it stops (Ctrl-C, SIGTERM) the status
//! becomes `"incomplete"` with the tick it stopped at and why, and `INCOMPLETE` says the same; a
//! process killed outright leaves `"recording"`, which reads as incomplete too.

use super::files::{absolute, FileEntry};
use crate::diag::{Diagnostic, Diagnostics};
use crate::scenario::{Overrides, Run, Scenario};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

/// The marker file of a record whose session is running or was stopped.
pub const INCOMPLETE: &str = "INCOMPLETE";

/// Milliseconds since the Unix epoch.
pub fn unix_ms(t: SystemTime) -> u64 {
    t.duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as u64)
}

/// Writes the record of a live session.
#[derive(Debug)]
pub struct LiveRecorder {
    dir: PathBuf,
    log: std::fs::File,
}

fn common_folder(paths: &[PathBuf]) -> PathBuf {
    let mut root: Option<PathBuf> = None;
    for p in paths {
        let dir = p.parent().unwrap_or(Path::new("/")).to_path_buf();
        root = Some(match root {
            None => dir,
            Some(r) => {
                let mut r = r;
                while !dir.starts_with(&r) {
                    if !r.pop() {
                        break;
                    }
                }
                r
            }
        });
    }
    root.unwrap_or_else(|| PathBuf::from("/"))
}

impl LiveRecorder {
    /// Creates the record folder `dir` for a run of `seed` with time step `dt`.
    pub fn create(dir: &Path, seed: u64, dt: f32) -> std::io::Result<LiveRecorder> {
        std::fs::create_dir_all(dir.join("versions"))?;
        let meta =
            serde_json::json!({ "seed": seed, "dt": dt, "scenario": null, "status": "recording" });
        std::fs::write(dir.join("live.json"), format!("{meta}\n"))?;
        std::fs::write(
            dir.join(INCOMPLETE),
            "this live session is being recorded (or its process was killed)\n",
        )?;
        let log = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(dir.join("reloads.jsonl"))?;
        Ok(LiveRecorder {
            dir: dir.to_path_buf(),
            log,
        })
    }

    fn line(&mut self, v: serde_json::Value) -> std::io::Result<()> {
        writeln!(self.log, "{v}")?;
        self.log.flush()
    }

    /// Records version `version` of the scenario `scenario` (built from `files`, with species
    /// files named only in relations in `library`), in effect from `tick` on.
    pub fn version(
        &mut self,
        time: SystemTime,
        version: u32,
        tick: u64,
        scenario: &Path,
        files: &[FileEntry],
        library: &[PathBuf],
    ) -> std::io::Result<()> {
        let mut all: Vec<PathBuf> = files.iter().map(|f| f.path.clone()).collect();
        all.extend(library.iter().cloned());
        let root = common_folder(&all);
        let vdir = self.dir.join("versions").join(version.to_string());
        let rel = |p: &Path| p.strip_prefix(&root).unwrap_or(p).to_path_buf();
        for f in files {
            let to = vdir.join(rel(&f.path));
            if let Some(parent) = to.parent() {
                std::fs::create_dir_all(parent)?;
            }
            std::fs::write(&to, &f.bytes)?;
        }
        for p in library {
            let to = vdir.join(rel(p));
            if let Some(parent) = to.parent() {
                std::fs::create_dir_all(parent)?;
            }
            // Only needs to exist; a missing one shows up when the record is re-run.
            let _ = std::fs::copy(p, &to);
        }
        let scenario_rel = Path::new("versions")
            .join(version.to_string())
            .join(rel(&absolute(scenario)));
        let hashes: serde_json::Map<String, serde_json::Value> = files
            .iter()
            .map(|f| (f.path.display().to_string(), f.sha256.clone().into()))
            .collect();
        if version == 0 {
            let meta_path = self.dir.join("live.json");
            let mut meta: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&meta_path)?)
                    .unwrap_or_else(|_| serde_json::json!({}));
            meta["scenario"] = scenario_rel.display().to_string().into();
            std::fs::write(&meta_path, format!("{meta}\n"))?;
        }
        self.line(serde_json::json!({
            "time_ms": unix_ms(time),
            "status": if version == 0 { "initial" } else { "accepted" },
            "version": version,
            "tick": tick,
            "scenario": scenario_rel.display().to_string(),
            "files": hashes,
        }))
    }

    /// Records that the session stopped after `tick` ticks, for `reason`, and marks the record
    /// incomplete with both.
    pub fn stopped(&mut self, time: SystemTime, tick: u64, reason: &str) -> std::io::Result<()> {
        self.line(serde_json::json!({
            "time_ms": unix_ms(time),
            "status": "stopped",
            "tick": tick,
            "reason": reason,
        }))?;
        let meta_path = self.dir.join("live.json");
        let mut meta: serde_json::Value = std::fs::read_to_string(&meta_path)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_else(|| serde_json::json!({}));
        meta["status"] = "incomplete".into();
        meta["ticks"] = tick.into();
        meta["stopped"] = reason.into();
        crate::record::write_atomic(&meta_path, format!("{meta}\n").as_bytes())?;
        std::fs::write(
            self.dir.join(INCOMPLETE),
            format!("this live session stopped at tick {tick}: {reason}\n"),
        )
    }

    /// Records a rejected edit while `running` ran, at `tick`.
    pub fn rejected(
        &mut self,
        time: SystemTime,
        running: u32,
        tick: u64,
        diagnostics: &[String],
    ) -> std::io::Result<()> {
        self.line(serde_json::json!({
            "time_ms": unix_ms(time),
            "status": "rejected",
            "version": running,
            "tick": tick,
            "diagnostics": diagnostics.iter().map(|d| super::hub::cap_message(d)).collect::<Vec<_>>(),
        }))
    }
}

fn bad(dir: &Path, msg: impl Into<String>) -> Diagnostics {
    Diagnostic::file(dir, msg).into()
}

/// What a live session's record holds: the seed, how far the session ran (when it was stopped
/// rather than killed) and each version's scenario file with the tick it took effect at.
#[derive(Debug, Clone, PartialEq)]
pub struct Recorded {
    /// The session's seed.
    pub seed: u64,
    /// Ticks the session ran, if it was stopped (a killed process does not say).
    pub ticks: Option<u64>,
    /// `(tick, scenario file)` of every version swapped in, the first at tick 0.
    pub versions: Vec<(u64, PathBuf)>,
}

/// Whether `dir` looks like the record of a live session (it has a `live.json`).
pub fn is_record(dir: &Path) -> bool {
    dir.join("live.json").is_file()
}

/// Reads the record in `dir`; errors name the file at fault.
pub fn read(dir: &Path) -> Result<Recorded, Diagnostics> {
    let meta_path = dir.join("live.json");
    let meta: serde_json::Value = std::fs::read_to_string(&meta_path)
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .ok_or_else(|| {
            bad(
                &meta_path,
                "no readable live.json: not a live session record",
            )
        })?;
    let seed = meta["seed"]
        .as_u64()
        .ok_or_else(|| bad(&meta_path, "live.json has no seed"))?;
    let log_path = dir.join("reloads.jsonl");
    let log = std::fs::read_to_string(&log_path)
        .map_err(|e| bad(&log_path, format!("cannot read it: {e}")))?;
    let mut versions: Vec<(u64, PathBuf)> = Vec::new();
    let mut ticks = meta["ticks"].as_u64();
    for (i, line) in log.lines().enumerate() {
        let v: serde_json::Value = serde_json::from_str(line).map_err(|e| {
            Diagnostics::from(Diagnostic::new(
                &log_path,
                i + 1,
                e.column(),
                e.to_string(),
                Some(&log),
            ))
        })?;
        match v["status"].as_str() {
            Some("initial" | "accepted") => {
                let tick = v["tick"].as_u64().unwrap_or(0);
                let scenario = dir.join(v["scenario"].as_str().unwrap_or_default());
                versions.push((tick, scenario));
            }
            Some("stopped") => ticks = ticks.or(v["tick"].as_u64()),
            _ => {}
        }
    }
    if versions.is_empty() {
        return Err(bad(&log_path, "reloads.jsonl records no version"));
    }
    Ok(Recorded {
        seed,
        ticks,
        versions,
    })
}

/// Re-runs the live session recorded in `dir` up to tick `ticks`: the first version from tick 0,
/// each later one swapped in at the tick it took effect at. The result is bit-identical to the
/// live session at that tick.
pub fn rerun(dir: &Path, ticks: u64) -> Result<Run, Diagnostics> {
    let rec = read(dir)?;
    let versions = rec.versions;
    let first = &versions[0].1;
    let mut run = Run::new(
        Scenario::load(first)?,
        Overrides {
            seed: Some(rec.seed),
            duration: None,
            set: Vec::new(),
        },
    );
    for (tick, scenario) in versions.iter().skip(1) {
        if *tick > ticks {
            break;
        }
        while run.world.tick < *tick {
            run.step();
        }
        run.reload(Scenario::load(scenario)?)?;
    }
    while run.world.tick < ticks {
        run.step();
    }
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn common_folder_of_files() {
        let p = |s: &str| PathBuf::from(s);
        assert_eq!(
            common_folder(&[p("/a/scen/x.ron"), p("/a/beh/y.ron"), p("/a/beh/c/z.rhai")]),
            p("/a")
        );
        assert_eq!(common_folder(&[p("/a/b/x.ron")]), p("/a/b"));
    }
}
