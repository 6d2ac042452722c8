//! Live sessions (`shoal watch`): a scenario running in real time with hot reload and a live
//! viewer. Not a tick stage: a layer above [`crate::scenario`] that drives [`crate::tick`] from a
//! simulation thread and swaps new versions of the species and scenario in at tick boundaries
//! (seed 000 §3's behavior stack and the agents' drives and memory carry over by name).
//!
//! Three parts: the simulation thread (`sim.rs`), the loader (`loader.rs`: a debounced watcher on
//! the folders of every file in use, and a worker thread that parses, validates, compiles and
//! dry-runs off the simulation thread, replaced if it hangs) and, optionally, the viewer's HTTP
//! server ([`server`]). What a viewer is sent lives in a
//! [`Hub`]. Everything the session does is reported as a [`LiveEvent`] for the caller to print.

pub mod breakpoints;
pub mod errors;
pub mod files;
pub mod http;
pub mod hub;
pub mod json;
mod loader;
pub mod record;
pub mod server;
mod sim;

pub use hub::{Hub, SessionStatus};
pub use json::{AgentInfo, Decision};
pub use sim::SPEED_RANGE;

use crate::diag::Diagnostics;
use crate::scenario::{Overrides, Run};
use crate::world::World;
use files::Attempt;
use loader::{Loader, LoaderMsg};
use sim::{Command, Sim};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

/// Longest [`Session::stop_because`] waits for the session's threads.
pub const STOP_WAIT: Duration = Duration::from_secs(5);

/// Settings of a live session.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveOptions {
    /// Quiet time the watcher waits for after a file event before reporting it.
    pub debounce: Duration,
    /// Least time between two loads: a burst of saves costs a few loads, the last save is always
    /// loaded.
    pub min_interval: Duration,
    /// Simulated seconds per wall-clock second.
    pub speed: f32,
    /// Start paused.
    pub paused: bool,
    /// Seed (default: the scenario's).
    pub seed: Option<u64>,
    /// Folder to record the versions and reloads in (see [`record`]).
    pub record: Option<PathBuf>,
    /// Least time between two frames sent to viewers.
    pub frame_interval: Duration,
    /// Keep the duration of every tick (for benchmarks): [`Session::tick_times`].
    pub tick_times: bool,
    /// Longest a reload may take (reading, validating, dry run) before it is rejected as timed
    /// out and the next edit is loaded by a fresh worker.
    pub reload_timeout: Duration,
}

impl Default for LiveOptions {
    fn default() -> Self {
        LiveOptions {
            debounce: Duration::from_millis(50),
            min_interval: Duration::from_millis(400),
            speed: 1.0,
            paused: false,
            seed: None,
            record: None,
            frame_interval: Duration::from_millis(40),
            tick_times: false,
            reload_timeout: Duration::from_secs(10),
        }
    }
}

/// A command to the running simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Control {
    /// Stop ticking.
    Pause,
    /// Tick in real time again.
    Resume,
    /// Pause and advance exactly one tick.
    Step,
    /// Simulated seconds per wall-clock second (clamped to [`SPEED_RANGE`]).
    Speed(f32),
}

/// A new version swapped in.
#[derive(Debug, Clone, PartialEq)]
pub struct Accepted {
    /// When.
    pub time: SystemTime,
    /// When (monotonic).
    pub at: Instant,
    /// Version number (the scenario as started is 0).
    pub version: u32,
    /// The tick it took effect at (the first tick it runs).
    pub tick: u64,
    /// Files whose change started the reload.
    pub changed: Vec<PathBuf>,
    /// Agents whose current behavior was renamed or removed and who fell back to their
    /// species' initial behavior, per species.
    pub fell_back: Vec<(String, usize)>,
    /// Agents removed with their species.
    pub removed: usize,
    /// Species added, with the agents spawned.
    pub spawned: Vec<(String, usize)>,
    /// When the watcher reported the change.
    pub detected_at: Instant,
    /// Time reading, parsing, validating and compiling the new version took (loader thread).
    pub load_duration: Duration,
    /// Time its dry run on a copy of the live world took (loader thread).
    pub dry_run_duration: Duration,
    /// Time the swap itself took on the simulation thread.
    pub swap_duration: Duration,
}

impl Accepted {
    /// Total agents that fell back.
    pub fn fell_back_total(&self) -> usize {
        self.fell_back.iter().map(|x| x.1).sum()
    }

    /// One line for people: version, tick and what happened to the agents.
    pub fn summary(&self) -> String {
        let mut s = format!("reloaded: version {} from tick {}", self.version, self.tick);
        for (name, n) in &self.fell_back {
            s.push_str(&format!(
                "; {n} {name} agent{} fell back to the initial behavior",
                if *n == 1 { "" } else { "s" }
            ));
        }
        for (name, n) in &self.spawned {
            s.push_str(&format!("; spawned {n} {name}"));
        }
        if self.removed > 0 {
            s.push_str(&format!("; removed {} agents", self.removed));
        }
        s
    }
}

/// An edit rejected: the last good version keeps running.
#[derive(Debug, Clone, PartialEq)]
pub struct Rejected {
    /// When.
    pub time: SystemTime,
    /// When (monotonic).
    pub at: Instant,
    /// The version that keeps running.
    pub running: u32,
    /// Files whose change started the reload.
    pub changed: Vec<PathBuf>,
    /// What is wrong: `file:line:col: message` and the offending line, one entry each.
    pub diagnostics: Vec<String>,
}

/// Something a live session did.
#[derive(Debug, Clone, PartialEq)]
pub enum LiveEvent {
    /// A new version was swapped in.
    Accepted(Accepted),
    /// An edit was rejected.
    Rejected(Rejected),
    /// The files are back to the running version after a rejected edit: diagnostics cleared.
    Restored {
        /// When.
        time: SystemTime,
        /// The version running.
        version: u32,
    },
    /// The first tick of a new version is done.
    FirstTick {
        /// The version.
        version: u32,
        /// The tick.
        tick: u64,
        /// When it ended.
        at: Instant,
    },
    /// A script of the running version failed (each distinct message once per version).
    ScriptError {
        /// When.
        time: SystemTime,
        /// Tick.
        tick: u64,
        /// `file:line:col: message` and the offending line.
        message: String,
        /// The agent whose call failed.
        agent: u32,
        /// Its species.
        species: String,
        /// The script function the failure is in, when known.
        function: Option<String>,
    },
    /// A breakpoint paused the run.
    Breakpoint(breakpoints::Hit),
    /// The file watcher reported a problem.
    WatchError {
        /// When.
        time: SystemTime,
        /// What.
        message: String,
    },
    /// The record could not be written.
    RecordError {
        /// When.
        time: SystemTime,
        /// What.
        message: String,
    },
}

/// Duration of one tick of a live session (see [`LiveOptions::tick_times`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickTime {
    /// The tick.
    pub tick: u64,
    /// When it started.
    pub started: Instant,
    /// Time `Run::step` took.
    pub step: Duration,
    /// Time spent swapping versions in just before it (zero if none).
    pub swap: Duration,
    /// Version it ran with.
    pub version: u32,
}

/// A cheap handle on a running session, for the viewer's server and other threads.
#[derive(Clone)]
pub struct SessionHandle {
    sim: Sender<Command>,
    hub: Arc<Hub>,
}

impl SessionHandle {
    /// Sends a control command.
    pub fn control(&self, c: Control) {
        let _ = self.sim.send(Command::Control(c));
    }

    /// Adds a breakpoint (checked after every tick from the next one on); returns its number,
    /// or why it was refused.
    pub fn add_breakpoint(&self, b: breakpoints::Breakpoint) -> Result<u32, String> {
        let (tx, rx) = mpsc::channel();
        self.sim
            .send(Command::Break(b, tx))
            .map_err(|_| "the session stopped".to_string())?;
        rx.recv_timeout(Duration::from_secs(10))
            .map_err(|_| "the session did not answer".to_string())?
    }

    /// Removes breakpoint `id` (`None`: all of them).
    pub fn remove_breakpoint(&self, id: Option<u32>) {
        let _ = self.sim.send(Command::Unbreak(id));
    }

    /// Inspects agent `id` (at the next tick boundary). `None` if it does not exist or the
    /// session stopped.
    pub fn inspect(&self, id: u32) -> Option<AgentInfo> {
        let (tx, rx) = mpsc::channel();
        self.sim.send(Command::Inspect(id, tx)).ok()?;
        rx.recv_timeout(Duration::from_secs(10)).ok().flatten()
    }

    /// A copy of the world (at the next tick boundary).
    pub fn world(&self) -> Option<World> {
        let (tx, rx) = mpsc::channel();
        self.sim.send(Command::World(tx)).ok()?;
        rx.recv_timeout(Duration::from_secs(10)).ok().map(|w| *w)
    }

    /// A copy of the whole run: world, scenario version and clocks (at the next tick boundary).
    pub fn fork(&self) -> Option<Run> {
        let (tx, rx) = mpsc::channel();
        self.sim.send(Command::Fork(tx, Duration::ZERO)).ok()?;
        rx.recv_timeout(Duration::from_secs(10)).ok().map(|r| *r)
    }

    /// What viewers are sent.
    pub fn hub(&self) -> &Arc<Hub> {
        &self.hub
    }

    /// Where the session stands.
    pub fn status(&self) -> SessionStatus {
        self.hub.status()
    }
}

/// A scenario running live with hot reload. Dropping it stops its threads.
pub struct Session {
    handle: SessionHandle,
    events: Receiver<LiveEvent>,
    loader_tx: Sender<LoaderMsg>,
    threads: Vec<JoinHandle<()>>,
    tick_times: Option<Arc<Mutex<Vec<TickTime>>>>,
    record: Option<Arc<Mutex<record::LiveRecorder>>>,
    stopped: bool,
    /// The scenario file.
    pub scenario_file: PathBuf,
    /// Species and agents at the start: `(species, agents)`.
    pub started_with: Vec<(String, usize)>,
}

impl Session {
    /// Loads `scenario` (errors are the diagnostics of the first load) and starts running it.
    pub fn start(scenario: &Path, options: LiveOptions) -> Result<Session, Diagnostics> {
        let loaded = match files::load(scenario, &[]) {
            Attempt::Loaded(l) => *l,
            Attempt::Failed { diagnostics, .. } => return Err(diagnostics),
        };
        let scenario_file = loaded.scenario.file.clone();
        let behaviors_dir = loaded.scenario.behaviors_dir.clone();
        let run = Run::new(
            loaded.scenario.clone(),
            Overrides {
                seed: options.seed,
                duration: None,
                set: Vec::new(),
            },
        );
        let started_with = run.alive();
        let bad = |e: String| Diagnostics::from(crate::diag::Diagnostic::file(scenario, e));
        let record = match &options.record {
            Some(dir) => {
                let mut r = record::LiveRecorder::create(dir, run.world.seed, run.world.dt)
                    .map_err(|e| bad(format!("cannot create the record {}: {e}", dir.display())))?;
                r.version(
                    SystemTime::now(),
                    0,
                    0,
                    &scenario_file,
                    &loaded.files,
                    &loaded.library,
                )
                .map_err(|e| bad(format!("cannot write the record {}: {e}", dir.display())))?;
                Some(Arc::new(Mutex::new(r)))
            }
            None => None,
        };
        let hub = Hub::new();
        let (sim_tx, sim_rx) = mpsc::channel();
        let (ev_tx, ev_rx) = mpsc::channel();
        let (loader_tx, loader_rx) = mpsc::channel();
        let debouncer = loader::debouncer(options.debounce, loader_tx.clone())
            .map_err(|e| bad(format!("cannot watch files: {e}")))?;
        let tick_times = options.tick_times.then(|| Arc::new(Mutex::new(Vec::new())));
        let mut sim = Sim::new(run, hub.clone(), ev_tx.clone());
        sim.paused = options.paused;
        sim.speed = options.speed.clamp(SPEED_RANGE.0, SPEED_RANGE.1);
        sim.frame_interval = options.frame_interval;
        sim.record = record.clone();
        sim.tick_times = tick_times.clone();
        let mut loader = Loader {
            scenario_file: scenario_file.clone(),
            min_interval: options.min_interval,
            sim: sim_tx.clone(),
            hub: hub.clone(),
            events: ev_tx,
            record: record.clone(),
            good: loaded.files,
            version: 0,
            behaviors_dir,
            failed: None,
            debouncer,
            watched: Default::default(),
            inbox: loader_tx.clone(),
            timeout: options.reload_timeout,
            last_dry_run: Duration::ZERO,
            worker: None,
            in_flight: None,
            next_job: 0,
        };
        loader.update_watches();
        let spawn = |name: &str, f: Box<dyn FnOnce() + Send>| {
            std::thread::Builder::new()
                .name(name.into())
                .spawn(f)
                .map_err(|e| bad(format!("cannot start a thread: {e}")))
        };
        let threads = vec![
            spawn("shoal-sim", Box::new(move || sim.run_loop(sim_rx)))?,
            spawn("shoal-loader", Box::new(move || loader.run_loop(loader_rx)))?,
        ];
        Ok(Session {
            handle: SessionHandle { sim: sim_tx, hub },
            events: ev_rx,
            loader_tx,
            threads,
            tick_times,
            record,
            stopped: false,
            scenario_file,
            started_with,
        })
    }

    /// A handle for other threads.
    pub fn handle(&self) -> SessionHandle {
        self.handle.clone()
    }

    /// What the session did, in order.
    pub fn events(&self) -> &Receiver<LiveEvent> {
        &self.events
    }

    /// Durations of the ticks so far (empty unless [`LiveOptions::tick_times`]).
    pub fn tick_times(&self) -> Vec<TickTime> {
        self.tick_times
            .as_ref()
            .map(|t| t.lock().unwrap_or_else(|e| e.into_inner()).clone())
            .unwrap_or_default()
    }

    /// Stops the threads and waits for them (see [`Session::stop_because`]).
    pub fn stop(mut self) {
        self.shutdown("stopped");
    }

    /// Stops the session for `reason` (such as an interrupt): waits up to [`STOP_WAIT`] for its
    /// threads, and marks the record, if any, as stopped at the last tick. Returns whether every
    /// thread ended in time (one that did not is left behind: the process may exit anyway).
    pub fn stop_because(mut self, reason: &str) -> bool {
        self.shutdown(reason)
    }

    fn shutdown(&mut self, reason: &str) -> bool {
        if self.stopped {
            return true;
        }
        self.stopped = true;
        let _ = self.loader_tx.send(LoaderMsg::Stop);
        let _ = self.handle.sim.send(Command::Stop);
        self.handle.hub.close();
        let deadline = Instant::now() + STOP_WAIT;
        while self.threads.iter().any(|t| !t.is_finished()) && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(10));
        }
        let mut all = true;
        for t in self.threads.drain(..) {
            if t.is_finished() {
                let _ = t.join();
            } else {
                all = false;
            }
        }
        if let Some(rec) = &self.record {
            let tick = self.handle.hub.status().tick;
            // A thread left behind may hold the record: wait a little, never forever.
            let until = Instant::now() + Duration::from_secs(1);
            loop {
                match rec.try_lock() {
                    Ok(mut r) => {
                        let _ = r.stopped(SystemTime::now(), tick, reason);
                        break;
                    }
                    Err(std::sync::TryLockError::Poisoned(p)) => {
                        let _ = p.into_inner().stopped(SystemTime::now(), tick, reason);
                        break;
                    }
                    Err(std::sync::TryLockError::WouldBlock) if Instant::now() < until => {
                        std::thread::sleep(Duration::from_millis(10));
                    }
                    Err(std::sync::TryLockError::WouldBlock) => break,
                }
            }
        }
        all
    }
}

impl std::ops::Deref for Session {
    type Target = SessionHandle;
    fn deref(&self) -> &SessionHandle {
        &self.handle
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.shutdown("stopped");
    }
}
