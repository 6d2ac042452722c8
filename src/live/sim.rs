//! The simulation thread of a live session: runs the scenario in real time (scaled by the
//! speed, pausable, one tick at a time on request), swaps in new versions at tick boundaries,
//! publishes frames to the viewers and answers inspections. Nothing here parses or compiles: new
//! versions arrive ready to install.

use super::breakpoints::{Breakpoint, Breakpoints};
use super::errors::ScriptFailure;
use super::files::FileEntry;
use super::hub::{cap_message, Hub};
use super::json::{self, Decision, DecisionLog, DECISIONS_KEPT};
use super::record::LiveRecorder;
use super::{Accepted, AgentInfo, Control, LiveEvent, TickTime};
use crate::events::Event;
use crate::health::Monitor;
use crate::scenario::{Run, Scenario};
use crate::world::World;
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

/// Slowest and fastest speeds accepted.
pub const SPEED_RANGE: (f32, f32) = (0.01, 100.0);

/// A version ready to be swapped in.
#[derive(Debug)]
pub(crate) struct Swap {
    pub version: u32,
    pub scenario: Scenario,
    pub files: Vec<FileEntry>,
    pub library: Vec<PathBuf>,
    pub changed: Vec<PathBuf>,
    pub detected_at: Instant,
    pub load_duration: Duration,
    pub dry_run_duration: Duration,
}

/// What the simulation thread is asked to do.
pub(crate) enum Command {
    Control(Control),
    Inspect(u32, Sender<Option<AgentInfo>>),
    /// A copy of the run, for work expected to take about the given time on another thread
    /// (answered when that fits before the next tick, else right after it).
    Fork(Sender<Box<Run>>, Duration),
    World(Sender<Box<World>>),
    Swap(Box<Swap>),
    Break(Breakpoint, Sender<Result<u32, String>>),
    Unbreak(Option<u32>),
    Stop,
}

pub(crate) struct Sim {
    pub run: Run,
    pub version: u32,
    pub paused: bool,
    pub speed: f32,
    pub frame_interval: Duration,
    pub hub: Arc<Hub>,
    pub events: Sender<LiveEvent>,
    pub record: Option<Arc<Mutex<LiveRecorder>>>,
    pub tick_times: Option<Arc<Mutex<Vec<TickTime>>>>,
    decisions: BTreeMap<u32, DecisionLog>,
    removed_at: Vec<Option<u64>>,
    reported: BTreeSet<String>,
    first_tick_of: Option<u32>,
    swap_time: Duration,
    step_once: bool,
    next_due: Instant,
    last_step: Duration,
    pending_forks: Vec<Sender<Box<Run>>>,
    last_frame: Option<Instant>,
    /// Run health of the version running (restarted at each swap: its figures are about the
    /// species as they are now).
    monitor: Monitor,
    health_since: u64,
    last_health: Option<Instant>,
    /// The inspected agent's explanations: its latest frame and decisions (the pipeline
    /// explains only the agent last inspected).
    explained: Option<serde_json::Value>,
    explained_decisions: std::collections::VecDeque<serde_json::Value>,
    /// Meals, catches and matings by agent id: `[tick, kind, other]`, the latest kept.
    contacts: BTreeMap<u32, std::collections::VecDeque<serde_json::Value>>,
    breakpoints: Breakpoints,
}

/// Explained decisions and contacts kept per agent.
const EXPLAINED_KEPT: usize = 32;

/// How often the run-health figures are sent to the viewers.
const HEALTH_INTERVAL: Duration = Duration::from_secs(1);

/// Distinct runtime script errors reported to the terminal per session (each agent's first one
/// is an event anyway).
const MAX_REPORTED_ERRORS: usize = 64;

impl Sim {
    pub fn new(run: Run, hub: Arc<Hub>, events: Sender<LiveEvent>) -> Sim {
        let removed_at = vec![None; run.world.obstacles.len()];
        let monitor = Monitor::new(&run.pipeline.species, run.world.dt);
        let health_since = run.world.tick;
        Sim {
            run,
            version: 0,
            paused: false,
            speed: 1.0,
            frame_interval: Duration::from_millis(40),
            hub,
            events,
            record: None,
            tick_times: None,
            decisions: BTreeMap::new(),
            removed_at,
            reported: BTreeSet::new(),
            first_tick_of: None,
            swap_time: Duration::ZERO,
            step_once: false,
            next_due: Instant::now(),
            last_step: Duration::ZERO,
            pending_forks: Vec::new(),
            last_frame: None,
            monitor,
            health_since,
            last_health: None,
            explained: None,
            explained_decisions: Default::default(),
            contacts: BTreeMap::new(),
            breakpoints: Breakpoints::default(),
        }
    }

    fn publish_health(&mut self) {
        let mut meta = crate::view::health_meta(&self.monitor.report());
        meta["since_tick"] = self.health_since.into();
        meta["version"] = self.version.into();
        self.hub.set_health(meta.to_string());
        self.last_health = Some(Instant::now());
    }

    fn period(&self) -> Duration {
        Duration::from_secs_f64(self.run.world.dt as f64 / self.speed as f64)
    }

    fn publish_world(&self) {
        self.hub
            .set_world(json::world_json(&self.run, &self.removed_at));
    }

    fn publish_frame(&mut self) {
        self.hub.set_frame(json::frame_json(&self.run));
        self.last_frame = Some(Instant::now());
    }

    fn publish_status(&self) {
        let (tick, time, agents) = (
            self.run.world.tick,
            self.run.world.time(),
            self.run.world.agents.len(),
        );
        let (version, paused, speed) = (self.version, self.paused, self.speed);
        let breakpoints = self.breakpoints.listed();
        self.hub.update_status(|s| {
            s.breakpoints = breakpoints;
            s.tick = tick;
            s.time = time;
            s.agents = agents;
            s.version = version;
            s.paused = paused;
            s.speed = speed;
        });
    }

    /// Runs until told to stop (or every sender is gone).
    pub fn run_loop(mut self, rx: Receiver<Command>) {
        self.publish_world();
        self.publish_frame();
        self.publish_status();
        self.next_due = Instant::now() + self.period();
        loop {
            // Everything already asked for, at this tick boundary.
            loop {
                match rx.try_recv() {
                    Ok(Command::Stop) => return,
                    Ok(c) => self.handle(c),
                    Err(std::sync::mpsc::TryRecvError::Empty) => break,
                    Err(std::sync::mpsc::TryRecvError::Disconnected) => return,
                }
            }
            let now = Instant::now();
            if self.step_once || (!self.paused && now >= self.next_due) {
                self.tick();
                if self.step_once {
                    self.step_once = false;
                } else {
                    self.next_due += self.period();
                    // Far behind (a slow machine or a huge world): drop the debt, keep real time.
                    if Instant::now() > self.next_due + 4 * self.period() {
                        self.next_due = Instant::now() + self.period();
                    }
                }
                let due_frame = self
                    .last_frame
                    .is_none_or(|t| t.elapsed() >= self.frame_interval);
                if due_frame || self.paused {
                    self.publish_frame();
                }
                self.publish_status();
                for reply in std::mem::take(&mut self.pending_forks) {
                    let _ = reply.send(Box::new(self.run.fork()));
                }
                continue;
            }
            let wait = if self.paused {
                Duration::from_millis(100)
            } else {
                self.next_due.saturating_duration_since(now)
            };
            match rx.recv_timeout(wait) {
                Ok(Command::Stop) => return,
                Ok(c) => self.handle(c),
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => return,
            }
        }
    }

    fn handle(&mut self, c: Command) {
        match c {
            Command::Control(c) => {
                match c {
                    Control::Pause => {
                        // Frames go out at most every frame interval, so the last one sent may be
                        // a tick or two old: send the tick the run stops at.
                        if !self.paused {
                            self.publish_frame();
                        }
                        self.paused = true;
                        for reply in std::mem::take(&mut self.pending_forks) {
                            let _ = reply.send(Box::new(self.run.fork()));
                        }
                    }
                    Control::Resume => {
                        self.hub.set_hit(None);
                        if self.paused {
                            self.paused = false;
                            self.next_due = Instant::now() + self.period();
                        }
                    }
                    Control::Step => {
                        self.hub.set_hit(None);
                        self.paused = true;
                        self.step_once = true;
                    }
                    Control::Speed(s) => {
                        if s.is_finite() {
                            self.speed = s.clamp(SPEED_RANGE.0, SPEED_RANGE.1);
                            self.next_due = Instant::now() + self.period();
                        }
                    }
                }
                self.publish_status();
            }
            Command::Inspect(id, reply) => {
                let info = self
                    .run
                    .world
                    .agent(crate::world::AgentId(id))
                    .map(|a| json::agent_info(&self.run, a, self.decisions.get(&id)));
                // From now on the pipeline explains this agent (read-only: the run is the same).
                if self.run.pipeline.explain.only != Some(id) {
                    self.run.pipeline.explain.only = Some(id);
                    self.explained = None;
                    self.explained_decisions.clear();
                }
                let info = info.map(|mut info| {
                    info.explain = self.explained.clone();
                    info.explained_decisions = self.explained_decisions.iter().cloned().collect();
                    info.contacts = self
                        .contacts
                        .get(&id)
                        .map_or_else(Vec::new, |c| c.iter().cloned().collect());
                    info
                });
                let _ = reply.send(info);
            }
            Command::Fork(reply, expected) => {
                // A dry run on the loader thread competes with the tick for the cores: start it
                // in the idle time between two ticks.
                let needed = 2 * expected.max(self.last_step);
                let gap = self.next_due.saturating_duration_since(Instant::now());
                if self.paused || gap >= needed {
                    let _ = reply.send(Box::new(self.run.fork()));
                } else {
                    self.pending_forks.push(reply);
                }
            }
            Command::World(reply) => {
                let _ = reply.send(Box::new(self.run.world.clone()));
            }
            Command::Swap(s) => self.swap(*s),
            Command::Break(b, reply) => {
                let _ = reply.send(self.breakpoints.add(b));
                self.publish_status();
            }
            Command::Unbreak(id) => {
                self.breakpoints.remove(id);
                self.publish_status();
            }
            Command::Stop => {}
        }
    }

    fn swap(&mut self, s: Swap) {
        let t0 = Instant::now();
        let tick = self.run.world.tick;
        // What agents are doing now, named only for those who fall back (the decision log).
        let old = self.run.pipeline.species.clone();
        let before: Vec<(u32, u16, u16)> = self
            .run
            .world
            .agents
            .iter()
            .map(|a| (a.id.0, a.species.0, a.mind.current))
            .collect();
        let old_name = |id: u32| -> String {
            let Ok(i) = before.binary_search_by_key(&id, |x| x.0) else {
                return String::new();
            };
            let (_, sp, b) = before[i];
            old.species
                .get(sp as usize)
                .map_or_else(String::new, |sp| sp.behavior_name(b).to_string())
        };
        let scenario_file = s.scenario.file.clone();
        match self.run.reload(s.scenario) {
            Ok(r) => {
                let swap_duration = t0.elapsed();
                self.swap_time += swap_duration;
                self.version = s.version;
                self.monitor = Monitor::new(&self.run.pipeline.species, self.run.world.dt);
                self.health_since = self.run.world.tick;
                self.last_health = None;
                for e in &r.remap.events {
                    match e {
                        Event::Death { agent, .. } => {
                            self.decisions.remove(&agent.0);
                        }
                        Event::Transition {
                            agent,
                            species,
                            to,
                            condition,
                            stack,
                            ..
                        } => {
                            let sp = &self.run.pipeline.species.species[*species as usize];
                            let log = self.decisions.entry(agent.0).or_default();
                            push_decision(
                                log,
                                Decision {
                                    tick,
                                    from: old_name(agent.0),
                                    to: sp.behavior_name(*to).to_string(),
                                    cause: "fallback",
                                    condition: condition.as_deref().map(str::to_string),
                                    stack: stack_text(sp, stack),
                                },
                            );
                        }
                        _ => {}
                    }
                }
                self.removed_at.resize(self.run.world.obstacles.len(), None);
                let names = &self.run.pipeline.species.species;
                let fell_back: Vec<(String, usize)> = names
                    .iter()
                    .zip(&r.remap.fell_back)
                    .filter(|(_, &n)| n > 0)
                    .map(|(s, &n)| (s.name.clone(), n))
                    .collect();
                let accepted = Accepted {
                    time: SystemTime::now(),
                    at: Instant::now(),
                    version: s.version,
                    tick,
                    changed: s.changed,
                    fell_back,
                    removed: r.remap.removed,
                    spawned: r.spawned,
                    detected_at: s.detected_at,
                    load_duration: s.load_duration,
                    dry_run_duration: s.dry_run_duration,
                    swap_duration,
                };
                if let Some(rec) = &self.record {
                    let mut rec = rec.lock().unwrap_or_else(|e| e.into_inner());
                    if let Err(e) = rec.version(
                        accepted.time,
                        s.version,
                        tick,
                        &scenario_file,
                        &s.files,
                        &s.library,
                    ) {
                        let _ = self.events.send(LiveEvent::RecordError {
                            time: SystemTime::now(),
                            message: e.to_string(),
                        });
                    }
                }
                self.publish_world();
                self.publish_frame();
                self.hub.set_diagnostics(&[]);
                self.hub.push_reload(&accepted.summary());
                self.publish_status();
                self.first_tick_of = Some(s.version);
                self.reported.clear();
                let _ = self.events.send(LiveEvent::Accepted(accepted));
            }
            Err(d) => {
                // The loader checked this before; the world cannot have made it invalid since.
                let lines = vec![cap_message(&d.to_string())];
                self.hub.set_diagnostics(&lines);
                let _ = self.events.send(LiveEvent::Rejected(super::Rejected {
                    time: SystemTime::now(),
                    at: Instant::now(),
                    running: self.version,
                    changed: s.changed,
                    diagnostics: lines,
                }));
            }
        }
    }

    fn tick(&mut self) {
        let t0 = Instant::now();
        self.run.step();
        let step = t0.elapsed();
        self.last_step = step;
        let tick = self.run.world.tick - 1;
        if let Some(times) = &self.tick_times {
            times
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(TickTime {
                    tick,
                    started: t0,
                    step,
                    swap: std::mem::take(&mut self.swap_time),
                    version: self.version,
                });
        }
        self.swap_time = Duration::ZERO;
        self.monitor.observe(&self.run.world, &self.run.pipeline);
        if self
            .last_health
            .is_none_or(|t| t.elapsed() >= HEALTH_INTERVAL)
        {
            self.publish_health();
        }
        if let Some(v) = self.first_tick_of.take() {
            let _ = self.events.send(LiveEvent::FirstTick {
                version: v,
                tick,
                at: Instant::now(),
            });
        }
        for v in &self.run.pipeline.explained {
            if v["type"] == "frame" {
                self.explained = Some(v.clone());
            } else {
                if self.explained_decisions.len() >= EXPLAINED_KEPT {
                    self.explained_decisions.pop_front();
                }
                self.explained_decisions.push_back(v.clone());
            }
        }
        let set = self.run.pipeline.species.clone();
        for e in &self.run.pipeline.events {
            let contact = match e {
                Event::Meal { agent, food } => Some((agent.0, "meal", *food as u64)),
                Event::Catch { agent, prey } => Some((agent.0, "catch", prey.0 as u64)),
                Event::Mating { agent, mate } => Some((agent.0, "mating", mate.0 as u64)),
                _ => None,
            };
            if let Some((a, kind, other)) = contact {
                let list = self.contacts.entry(a).or_default();
                if list.len() >= EXPLAINED_KEPT {
                    list.pop_front();
                }
                list.push_back(serde_json::json!([tick, kind, other]));
            }
            match e {
                Event::Transition {
                    agent,
                    species,
                    from,
                    to,
                    cause,
                    condition,
                    stack,
                } => {
                    let sp = &set.species[*species as usize];
                    push_decision(
                        self.decisions.entry(agent.0).or_default(),
                        Decision {
                            tick,
                            from: sp.behavior_name(*from).to_string(),
                            to: sp.behavior_name(*to).to_string(),
                            cause: cause.name(),
                            condition: condition.as_deref().map(str::to_string),
                            stack: stack_text(sp, stack),
                        },
                    );
                }
                Event::Death { agent, .. } => {
                    self.decisions.remove(&agent.0);
                }
                Event::ScriptError {
                    agent,
                    species,
                    message,
                } if self.reported.len() < MAX_REPORTED_ERRORS
                    && self.reported.insert(message.clone()) =>
                {
                    let f = ScriptFailure::new(
                        tick,
                        agent.0,
                        &set.species[*species as usize],
                        &cap_message(message),
                    );
                    self.hub
                        .push_script_error(serde_json::to_string(&f).unwrap_or_default());
                    let _ = self.events.send(LiveEvent::ScriptError {
                        time: SystemTime::now(),
                        tick,
                        message: cap_message(message),
                        agent: f.agent,
                        species: f.species,
                        function: f.function,
                    });
                }
                _ => {}
            }
        }
        // Checked right after the tick that triggers them: the run stops at that tick.
        if !self.breakpoints.is_empty() {
            let done = self.run.world.tick;
            if let Some(hit) = self
                .breakpoints
                .check(&self.run.pipeline.events, &set, done)
            {
                self.paused = true;
                self.hub.set_hit(Some(hit.clone()));
                let _ = self.events.send(LiveEvent::Breakpoint(hit));
            }
        }
        let mut world_changed = false;
        for (i, o) in self.run.world.obstacles.iter().enumerate() {
            if let Some(slot) = self.removed_at.get_mut(i) {
                if !o.active && slot.is_none() {
                    *slot = Some(tick);
                    world_changed = true;
                }
            }
        }
        if world_changed {
            self.publish_world();
        }
    }
}

fn stack_text(sp: &crate::species::Species, stack: &[u16]) -> String {
    stack
        .iter()
        .map(|&b| sp.behavior_name(b))
        .collect::<Vec<_>>()
        .join(" > ")
}

fn push_decision(log: &mut DecisionLog, d: Decision) {
    if log.len() == DECISIONS_KEPT {
        log.pop_front();
    }
    log.push_back(d);
}
