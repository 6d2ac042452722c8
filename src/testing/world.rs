//! The world a script test builds: a real [`World`] and [`Pipeline`] with real species loaded
//! from the behaviors folder, an event log stamped with ticks, names for agents, percept
//! injection, the decision history failures print, and squads on terrain driven around each
//! tick as a scenario run drives them (seed 004).

use super::coverage::Coverage;
use crate::events::{Cause, Event};
use crate::formation::{FormationDef, PlanRequest, Planner};
use crate::frame;
use crate::perception::{Category, Percept, Sense, Source};
use crate::sim::Sim;
use crate::species::{load_species, Species, SpeciesSet};
use crate::squad::{shape_named, task_named, Ground, SquadSetup, Squads, SHAPE_NAMES};
use crate::tick::Pipeline;
use crate::world::{Aabb, AgentId, World};
use glam::{Vec2, Vec3};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};

/// The species of one behaviors folder, each loaded (and its script compiled) once per run.
#[derive(Debug)]
pub struct Library {
    /// The behaviors folder.
    pub root: PathBuf,
    loaded: Mutex<BTreeMap<String, Result<Arc<Species>, String>>>,
}

impl Library {
    /// A library over `root`; nothing is read until a species is asked for.
    pub fn new(root: PathBuf) -> Self {
        Library {
            root,
            loaded: Mutex::new(BTreeMap::new()),
        }
    }

    /// Whether `name` has a species file in the folder.
    pub fn exists(&self, name: &str) -> bool {
        self.root.join(format!("{name}.ron")).is_file()
    }

    /// Names of the species files in the folder, sorted.
    pub fn names(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.root)
            .map(|r| {
                r.flatten()
                    .map(|e| e.path())
                    .filter(|p| p.extension().is_some_and(|x| x == "ron"))
                    .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    }

    /// The species `name`, loaded and validated; the error is the text of its diagnostics.
    pub fn get(&self, name: &str) -> Result<Arc<Species>, String> {
        let mut loaded = lock(&self.loaded);
        if let Some(r) = loaded.get(name) {
            return r.clone();
        }
        let r = if self.exists(name) {
            load_species(
                &self.root.join(format!("{name}.ron")),
                &self.root,
                &crate::scenario::script_limits(),
            )
            .map(Arc::new)
            .map_err(|d| format!("species \"{name}\" does not load:\n{d}"))
        } else {
            let names = self.names();
            Err(format!(
                "unknown species \"{name}\"{}: {} has {}",
                crate::load::did_you_mean(name, names.iter().map(String::as_str)),
                self.root.display(),
                if names.is_empty() {
                    "no species files".to_string()
                } else {
                    names.join(", ")
                }
            ))
        };
        loaded.insert(name.to_string(), r.clone());
        r
    }
}

/// Locks a mutex, going on with the data if another test panicked while holding it.
pub fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// An event of the log, with the world tick count after the step it happened in.
#[derive(Debug, Clone)]
pub struct Logged {
    /// Ticks done when it happened (0 for spawns before the first step).
    pub tick: u64,
    /// The event.
    pub event: Event,
}

/// A world built by a test.
pub struct TestWorld {
    /// The world, the real tick pipeline and the squads; a `TestWorld` derefs to it.
    pub sim: Sim,
    /// Species in use, by species index (in order of first spawn).
    pub species: Vec<Arc<Species>>,
    /// Where species come from.
    pub library: Arc<Library>,
    /// Names given to agents.
    pub names: BTreeMap<AgentId, String>,
    /// Every event so far.
    pub log: Vec<Logged>,
    /// Most ticks the world may run.
    pub max_ticks: u64,
    /// Percepts fed to agents instead of what they perceive, by agent.
    pub feeds: BTreeMap<AgentId, Vec<Feed>>,
    coverage: Arc<Coverage>,
}

impl std::ops::Deref for TestWorld {
    type Target = Sim;
    fn deref(&self) -> &Sim {
        &self.sim
    }
}

impl std::ops::DerefMut for TestWorld {
    fn deref_mut(&mut self) -> &mut Sim {
        &mut self.sim
    }
}

impl TestWorld {
    /// An empty world.
    pub fn new(
        bounds: Aabb,
        dt: f32,
        seed: u64,
        max_ticks: u64,
        library: Arc<Library>,
        coverage: Arc<Coverage>,
    ) -> Self {
        let empty = Arc::new(SpeciesSet::new(Vec::new()).expect("an empty set is valid"));
        coverage.add_root(&library.root);
        TestWorld {
            sim: Sim::from_parts(
                World::new(bounds, dt, seed),
                Pipeline::new(empty),
                Squads::default(),
            ),
            species: Vec::new(),
            library,
            names: BTreeMap::new(),
            log: Vec::new(),
            max_ticks,
            feeds: BTreeMap::new(),
            coverage,
        }
    }

    /// Index of species `name`, loading it into the world on first use.
    pub fn species_index(&mut self, name: &str) -> Result<usize, String> {
        if let Some(i) = self.species.iter().position(|s| s.name == name) {
            return Ok(i);
        }
        let sp = self.library.get(name)?;
        let mut all = self.species.clone();
        all.push(sp);
        let lib = self.library.clone();
        let set =
            SpeciesSet::with_library(all.clone(), |n| lib.exists(n)).map_err(|d| d.to_string())?;
        self.sim.pipeline.set_species(Arc::new(set));
        self.species = all;
        Ok(self.species.len() - 1)
    }

    /// Moves the pipeline's pending events into the log.
    fn drain_events(&mut self) {
        let tick = self.sim.world.tick;
        for e in self.sim.pipeline.events.drain(..) {
            if let Event::Transition {
                species,
                from,
                to,
                cause,
                ..
            } = &e
            {
                let sp = &self.species[*species as usize];
                self.coverage.transition(
                    &sp.name,
                    sp.behavior_name(*from),
                    sp.behavior_name(*to),
                    *cause,
                );
            }
            self.log.push(Logged { tick, event: e });
        }
    }

    /// Spawns an agent of species `s` (an index from [`TestWorld::species_index`]).
    pub fn spawn(&mut self, s: usize, pos: Vec3, yaw: f32, pitch: f32) -> AgentId {
        let id = self
            .sim
            .pipeline
            .spawn(&mut self.sim.world, s, pos, yaw, pitch);
        self.drain_events();
        id
    }

    /// Advances one tick.
    pub fn step(&mut self) -> Result<(), String> {
        if self.sim.world.tick >= self.max_ticks {
            return Err(format!(
                "test exceeded its limit of {} ticks (a `step` or `run` that never ends?)",
                self.max_ticks
            ));
        }
        self.drain_events();
        let feeds = &self.feeds;
        self.sim.step_with(|world, pipeline| {
            // Fed percepts keep their bearing relative to the agent's heading as it turns.
            pipeline.injected.clear();
            for (id, feeds) in feeds {
                if let Some(a) = world.agent(*id) {
                    let percepts = feeds.iter().map(|f| f.percept(a.yaw, a.pitch)).collect();
                    pipeline.injected.insert(*id, percepts);
                }
            }
        });
        self.drain_events();
        for a in &self.sim.world.agents {
            let sp = &self.species[a.species.0 as usize];
            self.coverage
                .behavior(&sp.name, sp.behavior_name(a.mind.current));
        }
        Ok(())
    }

    /// Plans a squad of `count` members of `species` over the world's terrain from `start` to
    /// `goal` (world `(x, z)`) and spawns it at its first formation, member 0 leading; the same
    /// checks and planner as a scenario's `squads` entry. Returns the members by member index.
    #[allow(clippy::too_many_arguments)]
    pub fn add_squad(
        &mut self,
        species: &str,
        count: usize,
        start: Vec2,
        goal: Vec2,
        formations: &[String],
        task: &str,
        spacing: f32,
    ) -> Result<Vec<AgentId>, String> {
        let terrain = self
            .sim
            .world
            .terrain
            .clone()
            .ok_or("squads walk on terrain: build the world with `world(#{ terrain: ... })`")?;
        let s = self.species_index(species)?;
        if !self.species[s].def.body.on_ground {
            return Err(format!(
                "squad species \"{species}\" must walk: give it `body: (on_ground: true)`"
            ));
        }
        if count == 0 {
            return Err("a squad needs at least 1 member".into());
        }
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(format!(
                "`spacing` must be a positive number, not {spacing}"
            ));
        }
        if formations.is_empty() {
            return Err("a squad needs at least one formation".into());
        }
        let mut shapes = Vec::new();
        for (i, name) in formations.iter().enumerate() {
            let shape = shape_named(name).ok_or_else(|| {
                format!(
                    "unknown formation \"{name}\": expected one of {}",
                    SHAPE_NAMES.join(", ")
                )
            })?;
            let def = FormationDef {
                name: Some(name.to_ascii_lowercase()),
                shape,
                spacing,
            };
            shapes.push(def.validate(count, i + 1).map_err(|e| e.to_string())?);
        }
        let task = task_named(task).ok_or_else(|| {
            format!(
                "unknown task class \"{task}\": expected MustKeep, MayChangeRarely, ShortestFirst or Custom(k1: …, k2: …, may_change: …)"
            )
        })?;
        // Each walking species' grid, as a scenario's load builds them.
        let old = self.sim.squads.ground.clone();
        let grids = self
            .species
            .iter()
            .enumerate()
            .map(|(i, sp)| {
                old.as_ref()
                    .and_then(|g| g.grids.get(i).cloned().flatten())
                    .or_else(|| {
                        sp.def
                            .body
                            .on_ground
                            .then(|| Arc::new(terrain.cost_grid(&sp.def.body.mobility)))
                    })
            })
            .collect::<Vec<_>>();
        let grid = grids[s].clone().expect("a walking species has a grid");
        let plan = Planner::new()
            .plan(&PlanRequest {
                grid: &grid,
                start,
                goal,
                formations: &shapes,
                leader: 0,
                weights: task.weights(),
            })
            .map_err(|e| format!("squad of \"{species}\": {e}"))?;
        self.sim.squads.ground = Some(Arc::new(Ground {
            terrain: terrain.clone(),
            grids,
        }));
        let setup = SquadSetup {
            species: s,
            formations: shapes,
            leader: 0,
            task,
            planning: Default::default(),
            start,
            goal,
            plan,
        };
        let ids = self
            .sim
            .squads
            .add(&setup, &mut self.sim.world, &mut self.sim.pipeline);
        let set = self.sim.pipeline.species.clone();
        self.sim.squads.settle_all(&mut self.sim.world, &set);
        for id in &ids {
            if let Some(i) = self.sim.world.agent_index(*id) {
                let a = &mut self.sim.world.agents[i];
                a.prev_pos = a.pos;
            }
        }
        self.drain_events();
        Ok(ids)
    }

    /// Index of the agent in the world, or why it is not there.
    pub fn index(&self, id: AgentId) -> Result<usize, String> {
        self.sim.world.agent_index(id).ok_or_else(|| {
            let death = self.log.iter().find_map(|l| match &l.event {
                Event::Death { agent, cause, .. } if *agent == id => Some((l.tick, *cause)),
                _ => None,
            });
            let by = self.log.iter().find_map(|l| match &l.event {
                Event::Catch { agent, prey } if *prey == id => Some(*agent),
                _ => None,
            });
            match (death, by) {
                (Some((t, _)), Some(by)) => format!(
                    "{} is no longer in the world: it was caught by {} at tick {t}",
                    self.label(id),
                    self.label(by)
                ),
                (Some((t, cause)), None) => format!(
                    "{} is no longer in the world: it died ({cause}) at tick {t}",
                    self.label(id)
                ),
                _ => format!("there is no agent with id {} in this world", id.0),
            }
        })
    }

    /// Species name of an agent id (alive or not), from the log.
    fn species_of(&self, id: AgentId) -> Option<&Species> {
        if let Some(a) = self.sim.world.agent(id) {
            return self.species.get(a.species.0 as usize).map(|s| &**s);
        }
        self.log.iter().find_map(|l| match l.event {
            Event::Spawn { agent, species } if agent == id => {
                self.species.get(species as usize).map(|s| &**s)
            }
            _ => None,
        })
    }

    /// How failures name an agent: `fish (reef_fish #0)` or `reef_fish #0`.
    pub fn label(&self, id: AgentId) -> String {
        let sp = self.species_of(id).map_or("agent", |s| s.name.as_str());
        match self.names.get(&id) {
            Some(n) => format!("{n} ({sp} #{})", id.0),
            None => format!("{sp} #{}", id.0),
        }
    }

    /// The agent named `name`.
    pub fn named(&self, name: &str) -> Option<AgentId> {
        self.names
            .iter()
            .find(|(_, n)| n.as_str() == name)
            .map(|(id, _)| *id)
    }

    /// Behavior names of the species of agent `id`, for validating names in assertions.
    pub fn behavior_names(&self, id: AgentId) -> Vec<String> {
        self.species_of(id)
            .map(|s| s.behaviors.iter().map(|b| b.name.to_string()).collect())
            .unwrap_or_default()
    }

    /// Checks that the species of `id` has a behavior `name`.
    pub fn check_behavior(&self, id: AgentId, name: &str) -> Result<u16, String> {
        let sp = self
            .species_of(id)
            .ok_or_else(|| format!("there is no agent with id {}", id.0))?;
        sp.behavior_index(name).ok_or_else(|| {
            let known = self.behavior_names(id);
            format!(
                "unknown behavior \"{name}\" of species \"{}\"{}: expected one of {}",
                sp.name,
                crate::load::did_you_mean(name, known.iter().map(String::as_str)),
                known.join(", ")
            )
        })
    }

    /// One line per transition: `tick 3 (0.15 s): wander → escape, interrupted: sees predator
    /// [stack: wander]`.
    pub fn transition_line(&self, l: &Logged) -> Option<String> {
        let Event::Transition {
            species,
            from,
            to,
            cause,
            condition,
            stack,
            ..
        } = &l.event
        else {
            return None;
        };
        let sp = &self.species[*species as usize];
        let mut s = format!(
            "tick {} ({:.2} s): {} → {}, {}",
            l.tick,
            l.tick as f64 * self.sim.world.dt as f64,
            sp.behavior_name(*from),
            sp.behavior_name(*to),
            cause.name()
        );
        if let Some(c) = condition {
            let _ = write!(
                s,
                " ({} {c})",
                match cause {
                    Cause::Completed | Cause::Resumed => "done when",
                    _ => "when",
                }
            );
        }
        let names: Vec<&str> = stack.iter().map(|b| sp.behavior_name(*b)).collect();
        let _ = write!(
            s,
            " [stack: {}]",
            if names.is_empty() {
                "empty".to_string()
            } else {
                names.join(", ")
            }
        );
        Some(s)
    }

    /// What a failure prints about one agent: its state now and its last decisions.
    pub fn decisions(&self, id: AgentId, last: usize) -> String {
        let mut out = String::new();
        let label = self.label(id);
        let now = format!(
            "tick {}, {:.2} s",
            self.sim.world.tick,
            self.sim.world.time()
        );
        match self.sim.world.agent(id) {
            Some(a) => {
                let sp = &self.species[a.species.0 as usize];
                let stack: Vec<&str> = a
                    .mind
                    .stack()
                    .iter()
                    .map(|b| sp.behavior_name(*b))
                    .collect();
                let _ = writeln!(
                    out,
                    "{label} now ({now}): in `{}` [stack: {}], hunger {:.2}, libido {:.2}, fear {:.2}, speed {:.2}",
                    sp.behavior_name(a.mind.current),
                    if stack.is_empty() { "empty".to_string() } else { stack.join(", ") },
                    // `+ 0.0` turns a negative zero into 0.
                    a.drives.hunger + 0.0,
                    a.drives.libido + 0.0,
                    a.drives.fear + 0.0,
                    a.speed + 0.0
                );
            }
            None => {
                let why = self.index(id).err().unwrap_or_default();
                let _ = writeln!(out, "{why} ({now})");
            }
        }
        let lines: Vec<String> = self
            .log
            .iter()
            .filter(|l| matches!(l.event, Event::Transition { agent, .. } if agent == id))
            .filter_map(|l| self.transition_line(l))
            .collect();
        if lines.is_empty() {
            let _ = writeln!(out, "{label} made no decisions yet");
        } else {
            let skip = lines.len().saturating_sub(last);
            let _ = writeln!(
                out,
                "last decisions of {label}{}:",
                if skip > 0 {
                    format!(" ({skip} earlier not shown)")
                } else {
                    String::new()
                }
            );
            for l in &lines[skip..] {
                let _ = writeln!(out, "  {l}");
            }
        }
        out
    }

    /// What a failure that names no agent prints: the decisions of every agent (the first few).
    pub fn all_decisions(&self, last: usize) -> String {
        let mut out = String::new();
        let ids: Vec<AgentId> = self
            .log
            .iter()
            .filter_map(|l| match l.event {
                Event::Spawn { agent, .. } => Some(agent),
                _ => None,
            })
            .collect();
        for id in ids.iter().take(4) {
            out.push_str(&self.decisions(*id, last));
        }
        if ids.len() > 4 {
            let _ = writeln!(out, "({} more agents not shown)", ids.len() - 4);
        }
        out
    }

    /// First script error of a species in this world, if any.
    pub fn script_error(&self) -> Option<String> {
        self.log.iter().find_map(|l| match &l.event {
            Event::ScriptError { agent, message, .. } => Some(format!(
                "a species script failed for {} at tick {}: {message}",
                self.label(*agent),
                l.tick
            )),
            _ => None,
        })
    }
}

/// A percept a test feeds to an agent: what it is, how far, where relative to the heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feed {
    /// Category.
    pub category: Category,
    /// Distance.
    pub dist: f32,
    /// Bearing (rad, right positive).
    pub bearing: f32,
    /// Elevation (rad, up positive).
    pub elevation: f32,
    /// Seen (vision) or only smelt.
    pub sense: Sense,
    /// Size S (bounding-box diagonal).
    pub size: f32,
}

impl Feed {
    /// The percept it becomes for an agent heading `(yaw, pitch)`.
    pub fn percept(&self, yaw: f32, pitch: f32) -> Percept {
        let pitch = (pitch + self.elevation).clamp(-frame::PITCH_LIMIT, frame::PITCH_LIMIT);
        let mut p = Percept::new(
            Source::Injected,
            self.category,
            self.sense,
            frame::forward(yaw + self.bearing, pitch) * self.dist,
            self.dist,
            self.size,
        );
        (p.bearing, p.elevation) = (self.bearing, self.elevation);
        p
    }
}

/// The behaviors folder of a test file: the parent of the nearest enclosing `tests` folder, or the
/// file's own folder when there is none.
pub fn behaviors_root(file: &Path) -> PathBuf {
    let dir = file.parent().unwrap_or(Path::new("."));
    let mut d = Some(dir);
    while let Some(p) = d {
        if p.file_name().is_some_and(|n| n == "tests") {
            let root = p.parent().unwrap_or(Path::new("."));
            return if root.as_os_str().is_empty() {
                PathBuf::from(".")
            } else {
                root.to_path_buf()
            };
        }
        d = p.parent();
    }
    if dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        dir.to_path_buf()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn behaviors_root_is_above_the_tests_folder() {
        assert_eq!(
            behaviors_root(Path::new("behaviors/tests/reef_fish.rhai")),
            PathBuf::from("behaviors")
        );
        assert_eq!(
            behaviors_root(Path::new("behaviors/tests/fixtures/failing.rhai")),
            PathBuf::from("behaviors")
        );
        assert_eq!(
            behaviors_root(Path::new("tests/x.rhai")),
            PathBuf::from(".")
        );
        assert_eq!(
            behaviors_root(Path::new("mine/x.rhai")),
            PathBuf::from("mine")
        );
    }

    #[test]
    fn a_fed_percept_has_the_bearing_it_was_given() {
        let f = Feed {
            category: Category::Predator,
            dist: 5.0,
            bearing: 0.5,
            elevation: -0.2,
            sense: Sense::Vision,
            size: 1.0,
        };
        let p = f.percept(0.3, 0.1);
        let (b, e) = frame::bearing_elevation(0.3, 0.1, p.offset);
        assert!((b - 0.5).abs() < 1e-5 && (e + 0.2).abs() < 1e-5, "{b} {e}");
        assert!((p.offset.length() - 5.0).abs() < 1e-5);
    }
}
