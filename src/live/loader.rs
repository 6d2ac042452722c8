//! The loader of a live session: watches the folders of every file the scenario is built from
//! (a watch on the file itself dies when an editor saves by writing a temporary file and
//! renaming it over the original), and on a change has a worker thread parse, validate and
//! compile the new version and dry-run it on a copy of the live world; then hands it to the
//! simulation thread — or rejects it with located diagnostics while the last good version keeps
//! running.
//!
//! Two threads: the coordinator ([`Loader::run_loop`]) only waits on messages, so it always
//! sees new edits and the stop request; the worker does the work that can hang (a file that
//! never finishes reading, such as a named pipe; a pathological version). A reload that takes
//! longer than [`super::LiveOptions::reload_timeout`] is rejected as timed out and the worker
//! is abandoned for a fresh one: a thread cannot be killed, but it no longer holds anything up.

use super::files::{self, watch_key, Attempt, FileEntry, Loaded};
use super::hub::{cap_message, Hub};
use super::record::LiveRecorder;
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
    /// The worker's outcome of job `.0`.
    Done(u64, Box<Outcome>),
    Stop,
}

/// One load for the worker.
pub(crate) struct Job {
    id: u64,
    scenario_file: PathBuf,
    /// Files of the previous attempt (a hint for the first read).
    known: Vec<PathBuf>,
    /// Files of the running version.
    good: Vec<FileEntry>,
    /// How long the last dry run took.
    last_dry_run: Duration,
}

/// What a load came to.
pub(crate) enum Outcome {
    /// Rejected: diagnostics and the files to watch.
    Failed(Vec<String>, Vec<PathBuf>),
    /// The files are those of the running version.
    Same,
    /// The simulation is gone.
    Stopped,
    /// Ready to swap in.
    Ready {
        loaded: Box<Loaded>,
        load_duration: Duration,
        dry_run_duration: Duration,
    },
}

/// A load under way.
pub(crate) struct InFlight {
    id: u64,
    started: Instant,
    changed: Vec<PathBuf>,
    detected_at: Instant,
    known: Vec<PathBuf>,
}

pub(crate) struct Loader {
    pub scenario_file: PathBuf,
    pub min_interval: Duration,
    pub sim: Sender<Command>,
    pub hub: Arc<Hub>,
    pub events: Sender<LiveEvent>,
    pub record: Option<Arc<Mutex<LiveRecorder>>>,
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
    /// Where the worker sends its outcomes (the loader's own inbox).
    pub inbox: Sender<LoaderMsg>,
    /// Longest a load may take before it is rejected as timed out.
    pub timeout: Duration,
    /// How long the last dry run took (the next one is expected to take about as long).
    pub last_dry_run: Duration,
    /// The worker's job queue; `None` until the first load (and after a timeout).
    pub worker: Option<Sender<Job>>,
    /// The load under way.
    pub in_flight: Option<InFlight>,
    /// Number of the last job sent.
    pub next_job: u64,
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
            // Wake for the deadline of the load under way, else for the next load due.
            let wake = match &self.in_flight {
                Some(f) => Some(f.started + self.timeout),
                None if !pending.is_empty() => {
                    Some(last_load.map_or_else(Instant::now, |t| t + self.min_interval))
                }
                None => None,
            };
            let msg = match wake {
                None => rx.recv().map_err(|_| RecvTimeoutError::Disconnected),
                Some(t) => rx.recv_timeout(t.saturating_duration_since(Instant::now())),
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
                Ok(LoaderMsg::Done(id, outcome)) => {
                    // A late answer from an abandoned worker is ignored.
                    if self.in_flight.as_ref().is_some_and(|f| f.id == id) {
                        let f = self.in_flight.take().expect("checked");
                        self.finish(f, *outcome);
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
            }
            if self
                .in_flight
                .as_ref()
                .is_some_and(|f| f.started.elapsed() >= self.timeout)
            {
                let f = self.in_flight.take().expect("checked");
                self.timed_out(f);
            }
            // Leading edge, then at most one load per `min_interval`: a burst of saves costs a
            // few loads, and the last save is always loaded.
            let ready = last_load.is_none_or(|t| t.elapsed() >= self.min_interval);
            if self.in_flight.is_none() && !pending.is_empty() && ready {
                last_load = Some(Instant::now());
                let changed: Vec<PathBuf> = std::mem::take(&mut pending).into_iter().collect();
                let seen = first_seen.take().unwrap_or_else(Instant::now);
                self.start(changed, seen);
            }
        }
    }

    fn reject(&mut self, changed: Vec<PathBuf>, diagnostics: Vec<String>, watch: Vec<PathBuf>) {
        let diagnostics: Vec<String> = diagnostics.iter().map(|d| cap_message(d)).collect();
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

    /// Hands the load after `changed` changed to the worker (started if need be).
    fn start(&mut self, changed: Vec<PathBuf>, detected_at: Instant) {
        let known: Vec<PathBuf> = match &self.failed {
            Some(f) => f.clone(),
            None => self.good.iter().map(|f| f.path.clone()).collect(),
        };
        self.next_job += 1;
        let job = Job {
            id: self.next_job,
            scenario_file: self.scenario_file.clone(),
            known: known.clone(),
            good: self.good.clone(),
            last_dry_run: self.last_dry_run,
        };
        let sent = match &self.worker {
            Some(w) => w.send(job),
            None => Err(std::sync::mpsc::SendError(job)),
        };
        // No worker yet, or it died (a panic): start one and try once more.
        let sent = match sent {
            Ok(()) => Ok(()),
            Err(std::sync::mpsc::SendError(job)) => {
                match spawn_worker(self.sim.clone(), self.inbox.clone()) {
                    Ok(w) => {
                        let r = w
                            .send(job)
                            .map_err(|_| "the loader worker stopped".to_string());
                        self.worker = Some(w);
                        r
                    }
                    Err(e) => Err(format!("cannot start the loader worker: {e}")),
                }
            }
        };
        if let Err(e) = sent {
            let msg = format!("{}: {e}", self.scenario_file.display());
            self.reject(changed, vec![msg], known);
            return;
        }
        self.in_flight = Some(InFlight {
            id: self.next_job,
            started: Instant::now(),
            changed,
            detected_at,
            known,
        });
    }

    /// The load `f` took too long: reject it and leave its worker behind.
    fn timed_out(&mut self, f: InFlight) {
        self.worker = None;
        let files: Vec<String> = f.changed.iter().map(|p| p.display().to_string()).collect();
        let what = if files.is_empty() {
            self.scenario_file.display().to_string()
        } else {
            files.join(", ")
        };
        let msg = format!(
            "{what}: the reload did not finish within {:.1} s and was abandoned (a file that never finishes reading, such as a named pipe, or a version that never finishes its dry run?); version {} keeps running and the next edit is loaded afresh",
            self.timeout.as_secs_f64(),
            self.version
        );
        self.reject(f.changed, vec![msg], f.known);
    }

    /// Applies the worker's outcome of the load `f`.
    fn finish(&mut self, f: InFlight, outcome: Outcome) {
        match outcome {
            Outcome::Failed(lines, watch) => self.reject(f.changed, lines, watch),
            Outcome::Stopped => {}
            Outcome::Same => {
                // Put back as it was (e.g. a broken edit undone): nothing to swap.
                if self.failed.take().is_some() {
                    self.hub.set_diagnostics(&[]);
                    let _ = self.events.send(LiveEvent::Restored {
                        time: SystemTime::now(),
                        version: self.version,
                    });
                    self.update_watches();
                }
            }
            Outcome::Ready {
                loaded,
                load_duration,
                dry_run_duration,
            } => {
                let loaded = *loaded;
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
                    changed: f.changed,
                    detected_at: f.detected_at,
                    load_duration,
                    dry_run_duration,
                };
                if self.sim.send(Command::Swap(Box::new(swap))).is_err() {
                    return;
                }
                self.update_watches();
            }
        }
    }
}

/// Starts a worker thread that runs the jobs it is sent and reports each outcome to `out`.
fn spawn_worker(sim: Sender<Command>, out: Sender<LoaderMsg>) -> std::io::Result<Sender<Job>> {
    let (tx, rx) = std::sync::mpsc::channel::<Job>();
    std::thread::Builder::new()
        .name("shoal-loader-worker".into())
        .spawn(move || {
            // Its own pool: a dry run that never ends keeps only this worker's pool busy.
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .thread_name(|_| "shoal-dry-run".into())
                .build()
                .ok();
            for job in rx {
                let id = job.id;
                let outcome = prepare(job, &sim, pool.as_ref());
                if out.send(LoaderMsg::Done(id, Box::new(outcome))).is_err() {
                    return;
                }
            }
        })?;
    Ok(tx)
}

/// A copy of the live run, taken when it costs the simulation least.
fn fork(sim: &Sender<Command>, expected: Duration) -> Option<Run> {
    let (tx, rx) = std::sync::mpsc::channel();
    sim.send(Command::Fork(tx, expected)).ok()?;
    rx.recv_timeout(Duration::from_secs(30)).ok().map(|b| *b)
}

/// Loads the scenario of `job`, and dry-runs it if it differs from the running version.
fn prepare(job: Job, sim: &Sender<Command>, pool: Option<&rayon::ThreadPool>) -> Outcome {
    let t0 = Instant::now();
    let loaded = match files::load(&job.scenario_file, &job.known) {
        Attempt::Failed { diagnostics, watch } => {
            let lines = diagnostics
                .0
                .iter()
                .take(MAX_DIAGNOSTICS)
                .map(|d| d.to_string())
                .collect();
            return Outcome::Failed(lines, watch);
        }
        Attempt::Loaded(l) => l,
    };
    let load_duration = t0.elapsed();
    if files::same_contents(&loaded.files, &job.good) {
        return Outcome::Same;
    }
    let Some(fork) = fork(sim, job.last_dry_run) else {
        return Outcome::Stopped;
    };
    let scenario = loaded.scenario.clone();
    let watch: Vec<PathBuf> = loaded.files.iter().map(|f| f.path.clone()).collect();
    let t1 = Instant::now();
    let checked = match pool {
        Some(p) => p.install(|| dry_run(fork, scenario)),
        None => dry_run(fork, scenario),
    };
    if let Err(lines) = checked {
        return Outcome::Failed(lines, watch);
    }
    Outcome::Ready {
        loaded,
        load_duration,
        dry_run_duration: t1.elapsed(),
    }
}
