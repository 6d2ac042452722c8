//! The loader thread of a live session: watches the folders of every file the scenario is built
//! from (a watch on the file itself dies when an editor saves by writing a temporary file and
//! renaming it over the original), and on a change parses, validates and compiles the new
//! version, dry-runs it on a copy of the live world, and hands it to the simulation thread — or
//! rejects it with located diagnostics while the last good version keeps running.

use super::files::{self, watch_key, Attempt, FileEntry};
use super::hub::Hub;
use super::record::Recorder;
use super::sim::{Command, Swap};
use super::{LiveEvent, Rejected};
use crate::events::Event;
use crate::scenario::{Run, Scenario};
use notify::{EventKind, RecursiveMode};
use notify_debouncer_full::{new_debouncer, DebounceEventResult, Debouncer, RecommendedCache};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

/// Most diagnostics of one rejected edit shown.
const MAX_DIAGNOSTICS: usize = 8;

/// What the loader thread receives.
pub(crate) enum LoaderMsg {
    Fs(DebounceEventResult),
    Stop,
}

pub(crate) struct Loader {
    pub scenario_file: PathBuf,
    pub min_interval: Duration,
    pub sim: Sender<Command>,
    pub hub: Arc<Hub>,
    pub events: Sender<LiveEvent>,
    pub record: Option<Arc<Mutex<Recorder>>>,
    /// Files of the last version sent to the simulation.
    pub good: Vec<FileEntry>,
    /// Version number of that version.
    pub version: u32,
    /// The behaviors folder, watched recursively (imports may live in sub-folders).
    pub behaviors_dir: PathBuf,
    /// Files of the last attempt that failed (those to watch while in error), if in error.
    pub failed: Option<Vec<PathBuf>>,
    pub debouncer: Debouncer<notify::RecommendedWatcher, RecommendedCache>,
    pub watched: BTreeMap<PathBuf, RecursiveMode>,
    pub pool: rayon::ThreadPool,
    /// How long the last dry run took (the next one is expected to take about as long).
    pub last_dry_run: Duration,
}

/// Whether `p` can be a file of a scenario (not an editor's swap, backup or probe file).
fn is_source(p: &Path) -> bool {
    let name = p
        .file_name()
        .map(|n| n.to_string_lossy())
        .unwrap_or_default();
    !name.starts_with('.')
        && !name.starts_with('#')
        && p.extension().is_some_and(|e| e == "ron" || e == "rhai")
}

/// Starts a debouncer that sends its batches to `tx`.
pub(crate) fn debouncer(
    debounce: Duration,
    tx: Sender<LoaderMsg>,
) -> notify::Result<Debouncer<notify::RecommendedWatcher, RecommendedCache>> {
    new_debouncer(debounce, None, move |r: DebounceEventResult| {
        let _ = tx.send(LoaderMsg::Fs(r));
    })
}

/// Runs `new` for one tick on `run` (a copy of the live run) with every agent's scripts due:
/// returns the diagnostics of the first script failures, or of the swap itself.
pub(crate) fn dry_run(mut run: Run, new: Scenario) -> Result<(), Vec<String>> {
    let attempt = std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || {
        run.reload(new).map_err(|d| vec![d.to_string()])?;
        run.pipeline.scripts_every_tick = true;
        run.step();
        let mut errors: Vec<String> = Vec::new();
        for e in &run.pipeline.events {
            if let Event::ScriptError { message, .. } = e {
                if !errors.contains(message) && errors.len() < MAX_DIAGNOSTICS {
                    errors.push(message.clone());
                }
            }
        }
        if errors.is_empty() {
            Ok(())
        } else {
            Err(errors)
        }
    }));
    attempt.unwrap_or_else(|_| {
        Err(vec![
            "the new version failed its dry run (internal error)".into()
        ])
    })
}

impl Loader {
    fn relevant(&self) -> BTreeSet<PathBuf> {
        let mut set: BTreeSet<PathBuf> = self.good.iter().map(|f| watch_key(&f.path)).collect();
        set.insert(watch_key(&self.scenario_file));
        if let Some(f) = &self.failed {
            set.extend(f.iter().map(|p| watch_key(p)));
        }
        set
    }

    /// Folders to watch: the behaviors folder (recursively) and the folder of every file in use.
    pub fn update_watches(&mut self) {
        let mut want: BTreeMap<PathBuf, RecursiveMode> = BTreeMap::new();
        let beh = std::fs::canonicalize(&self.behaviors_dir).ok();
        if let Some(b) = &beh {
            want.insert(b.clone(), RecursiveMode::Recursive);
        }
        for f in self.relevant() {
            if let Some(dir) = f.parent() {
                let inside = beh.as_ref().is_some_and(|b| dir.starts_with(b));
                if !inside && dir.is_dir() {
                    want.insert(dir.to_path_buf(), RecursiveMode::NonRecursive);
                }
            }
        }
        let stale: Vec<PathBuf> = self
            .watched
            .iter()
            .filter(|(p, m)| want.get(*p) != Some(m))
            .map(|(p, _)| p.clone())
            .collect();
        for p in stale {
            let _ = self.debouncer.unwatch(&p);
            self.watched.remove(&p);
        }
        for (p, m) in want {
            if self.watched.contains_key(&p) {
                continue;
            }
            match self.debouncer.watch(&p, m) {
                Ok(()) => {
                    self.watched.insert(p, m);
                }
                Err(e) => {
                    let _ = self.events.send(LiveEvent::WatchError {
                        time: SystemTime::now(),
                        message: format!("cannot watch {}: {e}", p.display()),
                    });
                }
            }
        }
    }

    /// The changed files of a batch that concern this scenario.
    fn filter(&self, batch: DebounceEventResult) -> Vec<PathBuf> {
        let events = match batch {
            Ok(ev) => ev,
            Err(errs) => {
                for e in errs {
                    let _ = self.events.send(LiveEvent::WatchError {
                        time: SystemTime::now(),
                        message: e.to_string(),
                    });
                }
                return Vec::new();
            }
        };
        let relevant = self.relevant();
        let mut out = BTreeSet::new();
        for e in events {
            if matches!(e.kind, EventKind::Access(_)) {
                continue;
            }
            if e.need_rescan() {
                out.insert(watch_key(&self.scenario_file));
            }
            for p in &e.paths {
                let k = watch_key(p);
                // While in error any source file may be the fix (e.g. a species file the broken
                // version needs that does not exist yet).
                if relevant.contains(&k) || (self.failed.is_some() && is_source(p)) {
                    out.insert(k);
                }
            }
        }
        out.into_iter().collect()
    }

    pub fn run_loop(mut self, rx: Receiver<LoaderMsg>) {
        let mut pending: BTreeSet<PathBuf> = BTreeSet::new();
        let mut first_seen: Option<Instant> = None;
        let mut last_load: Option<Instant> = None;
        loop {
            let msg = if pending.is_empty() {
                rx.recv().map_err(|_| RecvTimeoutError::Disconnected)
            } else {
                let ready_at = last_load.map_or_else(Instant::now, |t| t + self.min_interval);
                rx.recv_timeout(ready_at.saturating_duration_since(Instant::now()))
            };
            match msg {
                Ok(LoaderMsg::Stop) | Err(RecvTimeoutError::Disconnected) => return,
                Ok(LoaderMsg::Fs(batch)) => {
                    let changed = self.filter(batch);
                    if !changed.is_empty() && pending.is_empty() {
                        first_seen = Some(Instant::now());
                    }
                    pending.extend(changed);
                }
                Err(RecvTimeoutError::Timeout) => {}
            }
            // Leading edge, then at most one load per `min_interval`: a burst of saves costs a
            // few loads, and the last save is always loaded.
            let ready = last_load.is_none_or(|t| t.elapsed() >= self.min_interval);
            if !pending.is_empty() && ready {
                last_load = Some(Instant::now());
                let changed: Vec<PathBuf> = std::mem::take(&mut pending).into_iter().collect();
                let seen = first_seen.take().unwrap_or_else(Instant::now);
                self.attempt(changed, seen);
            }
        }
    }

    fn reject(&mut self, changed: Vec<PathBuf>, diagnostics: Vec<String>, watch: Vec<PathBuf>) {
        self.failed = Some(watch);
        self.hub.set_diagnostics(&diagnostics);
        let time = SystemTime::now();
        if let Some(rec) = &self.record {
            let tick = self.hub.status().tick;
            let _ = rec.lock().unwrap_or_else(|e| e.into_inner()).rejected(
                time,
                self.version,
                tick,
                &diagnostics,
            );
        }
        let _ = self.events.send(LiveEvent::Rejected(Rejected {
            time,
            at: Instant::now(),
            running: self.version,
            changed,
            diagnostics,
        }));
        self.update_watches();
    }

    fn fork(&self) -> Option<Run> {
        let (tx, rx) = std::sync::mpsc::channel();
        self.sim.send(Command::Fork(tx, self.last_dry_run)).ok()?;
        rx.recv_timeout(Duration::from_secs(30)).ok().map(|b| *b)
    }

    /// Loads the scenario after `changed` changed; swaps it in or rejects it.
    fn attempt(&mut self, changed: Vec<PathBuf>, detected_at: Instant) {
        let known: Vec<PathBuf> = match &self.failed {
            Some(f) => f.clone(),
            None => self.good.iter().map(|f| f.path.clone()).collect(),
        };
        let t0 = Instant::now();
        let loaded = match files::load(&self.scenario_file, &known) {
            Attempt::Failed { diagnostics, watch } => {
                let lines = diagnostics
                    .0
                    .iter()
                    .take(MAX_DIAGNOSTICS)
                    .map(|d| d.to_string())
                    .collect();
                self.reject(changed, lines, watch);
                return;
            }
            Attempt::Loaded(l) => *l,
        };
        let load_duration = t0.elapsed();
        if files::same_contents(&loaded.files, &self.good) {
            // Put back as it was (e.g. a broken edit undone): nothing to swap.
            if self.failed.take().is_some() {
                self.hub.set_diagnostics(&[]);
                let _ = self.events.send(LiveEvent::Restored {
                    time: SystemTime::now(),
                    version: self.version,
                });
                self.update_watches();
            }
            return;
        }
        let Some(fork) = self.fork() else {
            return;
        };
        let scenario = loaded.scenario.clone();
        let watch: Vec<PathBuf> = loaded.files.iter().map(|f| f.path.clone()).collect();
        let t1 = Instant::now();
        if let Err(lines) = self.pool.install(|| dry_run(fork, scenario)) {
            self.reject(changed, lines, watch);
            return;
        }
        let dry_run_duration = t1.elapsed();
        self.last_dry_run = dry_run_duration;
        self.version += 1;
        self.failed = None;
        self.behaviors_dir = loaded.scenario.behaviors_dir.clone();
        self.good = loaded.files.clone();
        let swap = Swap {
            version: self.version,
            scenario: loaded.scenario,
            files: loaded.files,
            library: loaded.library,
            changed,
            detected_at,
            load_duration,
            dry_run_duration,
        };
        if self.sim.send(Command::Swap(Box::new(swap))).is_err() {
            return;
        }
        self.update_watches();
    }
}
