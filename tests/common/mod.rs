//! Helpers shared by the tests: small worlds built with the library API, and the CLI run as a
//! process.
#![allow(dead_code)]

use glam::Vec3;
use shoal::events::{Cause, Event};
use shoal::scenario::script_limits;
use shoal::species::{load_species, Species, SpeciesSet};
use shoal::world::{Aabb, Agent, AgentId};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

/// An agent's id and the bits of its state that the determinism tests compare: position,
/// heading, speed, hunger and current behavior.
pub fn state_bits(a: &Agent) -> (u32, [u32; 8]) {
    (
        a.id.0,
        [
            a.pos.x.to_bits(),
            a.pos.y.to_bits(),
            a.pos.z.to_bits(),
            a.yaw.to_bits(),
            a.pitch.to_bits(),
            a.speed.to_bits(),
            a.drives.hunger.to_bits(),
            a.mind.current as u32,
        ],
    )
}

/// The shipped behaviors folder.
pub fn behaviors() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("behaviors")
}

/// Loads one species file; panics with the diagnostics on failure.
pub fn load(file: &Path, root: &Path) -> Species {
    load_species(file, root, &script_limits()).unwrap_or_else(|e| panic!("{e}"))
}

/// A transition as names, for readable assertions.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    /// Tick of the step it happened in.
    pub tick: u64,
    /// Agent.
    pub agent: AgentId,
    /// From behavior.
    pub from: String,
    /// To behavior.
    pub to: String,
    /// Cause.
    pub cause: Cause,
    /// Condition text.
    pub condition: Option<String>,
    /// Stack after the change, bottom first.
    pub stack: Vec<String>,
}

/// The engine's [`shoal::Sim`] (it derefs to it) and the events of every tick run so far.
pub struct Sim {
    pub engine: shoal::Sim,
    /// Every event with the tick it happened in.
    pub log: Vec<(u64, Event)>,
}

impl std::ops::Deref for Sim {
    type Target = shoal::Sim;
    fn deref(&self) -> &shoal::Sim {
        &self.engine
    }
}

impl std::ops::DerefMut for Sim {
    fn deref_mut(&mut self) -> &mut shoal::Sim {
        &mut self.engine
    }
}

impl Sim {
    /// A world of `bounds` with these species (relations may name species not loaded).
    pub fn new(species: Vec<Species>, bounds: Aabb) -> Sim {
        let set = SpeciesSet::with_library(species.into_iter().map(Arc::new).collect(), |_| true)
            .unwrap_or_else(|e| panic!("{e}"));
        Sim {
            engine: shoal::Sim::new(set, bounds, 0.05, 11),
            log: Vec::new(),
        }
    }

    /// The shipped species named, in a box of ±50 (height 0..40).
    pub fn shipped(names: &[&str]) -> Sim {
        let root = behaviors();
        let species = names
            .iter()
            .map(|n| load(&root.join(format!("{n}.ron")), &root))
            .collect();
        Sim::new(
            species,
            Aabb::new(Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 40.0, 50.0)),
        )
    }

    /// Spawns an agent of `species` at `pos` heading `yaw` (level).
    pub fn spawn(&mut self, species: &str, pos: Vec3, yaw: f32) -> AgentId {
        let s = self
            .pipeline
            .species
            .index_of(species)
            .unwrap_or_else(|| panic!("no species {species}"));
        let engine = &mut self.engine;
        engine.pipeline.spawn(&mut engine.world, s, pos, yaw, 0.0)
    }

    /// One tick; its events are appended to the log.
    pub fn step(&mut self) {
        let tick = self.world.tick;
        self.engine.step();
        self.log
            .extend(self.engine.events().iter().cloned().map(|e| (tick, e)));
    }

    /// Steps until `done` holds (checked after each tick) or `max` ticks pass; returns the number
    /// of ticks run when it held.
    pub fn run_until(&mut self, max: u64, mut done: impl FnMut(&Sim) -> bool) -> Option<u64> {
        for k in 1..=max {
            self.step();
            if done(self) {
                return Some(k);
            }
        }
        None
    }

    /// Steps `n` ticks.
    pub fn run(&mut self, n: u64) {
        for _ in 0..n {
            self.step();
        }
    }

    /// The agent (panics when it is gone).
    pub fn agent(&self, id: AgentId) -> &Agent {
        self.world.agent(id).expect("agent alive")
    }

    /// The agent, mutable.
    pub fn agent_mut(&mut self, id: AgentId) -> &mut Agent {
        let i = self.world.agent_index(id).expect("agent alive");
        &mut self.engine.world.agents[i]
    }

    /// Whether the agent is alive.
    pub fn alive(&self, id: AgentId) -> bool {
        self.world.agent(id).is_some()
    }

    /// Name of the agent's current behavior.
    pub fn behavior(&self, id: AgentId) -> String {
        let a = self.agent(id);
        self.pipeline.species.species[a.species.0 as usize]
            .behavior_name(a.mind.current)
            .to_string()
    }

    /// Names of the agent's stacked behaviors, bottom first.
    pub fn stack(&self, id: AgentId) -> Vec<String> {
        let a = self.agent(id);
        let sp = &self.pipeline.species.species[a.species.0 as usize];
        a.mind
            .stack()
            .iter()
            .map(|&b| sp.behavior_name(b).to_string())
            .collect()
    }

    /// Every transition of `id` so far, as names.
    pub fn changes(&self, id: AgentId) -> Vec<Change> {
        self.log
            .iter()
            .filter_map(|(tick, e)| match e {
                Event::Transition {
                    agent,
                    species,
                    from,
                    to,
                    cause,
                    condition,
                    stack,
                } if *agent == id => {
                    let sp = &self.pipeline.species.species[*species as usize];
                    Some(Change {
                        tick: *tick,
                        agent: *agent,
                        from: sp.behavior_name(*from).to_string(),
                        to: sp.behavior_name(*to).to_string(),
                        cause: *cause,
                        condition: condition.as_deref().map(str::to_string),
                        stack: stack
                            .iter()
                            .map(|&b| sp.behavior_name(b).to_string())
                            .collect(),
                    })
                }
                _ => None,
            })
            .collect()
    }

    /// The last transition of `id`.
    pub fn last_change(&self, id: AgentId) -> Change {
        self.changes(id)
            .pop()
            .unwrap_or_else(|| panic!("agent {id:?} made no transition"))
    }

    /// Moves an agent somewhere (its previous position too, so nothing predicts a jump).
    pub fn teleport(&mut self, id: AgentId, pos: Vec3) {
        let a = self.agent_mut(id);
        a.pos = pos;
        a.prev_pos = pos;
    }

    /// Sets hunger through the seed 000 §2 state (meal eaten just now), so native drives keep it.
    pub fn set_hunger(&mut self, id: AgentId, hunger: f32) {
        let i = self.world.agent_index(id).expect("agent alive");
        let s = self.world.agents[i].species.0 as usize;
        let params = self.pipeline.species.species[s].def.drives.params;
        let a = &mut self.engine.world.agents[i];
        (a.drives.eaten, a.drives.since_meal) = shoal::drives::meal_clock_for(hunger, 0.0, &params);
        a.drives.hunger = hunger;
    }

    /// Script errors reported so far.
    pub fn script_errors(&self) -> Vec<String> {
        self.log
            .iter()
            .filter_map(|(_, e)| match e {
                Event::ScriptError { message, .. } => Some(message.clone()),
                _ => None,
            })
            .collect()
    }
}

/// A temporary behaviors folder with the given files (path relative to the folder, text).
pub fn folder(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    for (rel, text) in files {
        let p = dir.path().join(rel);
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent).expect("mkdir");
        }
        std::fs::write(&p, text).expect("write");
    }
    dir
}

/// The `name figure` pairs of a printed line such as `index 0.2, perception 3.4` (a figure may
/// end in `%`, which is dropped).
pub fn named_figures(line: &str) -> Vec<(&str, f64)> {
    line.split(", ")
        .map(|p| {
            let (name, figure) = p
                .split_once(' ')
                .unwrap_or_else(|| panic!("`{p}` is not a name and a figure"));
            let figure = figure.trim_end_matches('%');
            let value = figure
                .parse()
                .unwrap_or_else(|_| panic!("`{figure}` is not a number"));
            (name, value)
        })
        .collect()
}

/// Runs the `shoal` binary with `args`: (exit code, stdout, stderr).
pub fn shoal(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
