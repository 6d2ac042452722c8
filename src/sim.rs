//! The one place the world advances.
//!
//! A [`Sim`] owns the world, the tick pipeline and the squad layer (terrain, formation plans).
//! [`Sim::step`] runs one tick: the squads' per-tick plan upkeep, then the pipeline's stages
//! (`index → perceive → agent pass: drives, decide, steer, move → events`, see [`crate::tick`]),
//! then the squads' formation measures. Everything that runs the engine steps through here:
//! scenario runs ([`crate::scenario::Run`] adds its timed events and food respawn in the
//! `before` hook of [`Sim::step_with`]), designers' tests (fed percepts), live sessions, the
//! integration tests, and a game or simulator embedding the engine.
//!
//! ```
//! use shoal::prelude::*;
//!
//! let reef = r#"(
//!     name: "drifter",
//!     initial: "drift",
//!     behaviors: [Behavior(name: "drift", priority: 1, steer: Cruise(speed: 0.5))],
//! )"#;
//! let species = Species::parse("drifter.ron", reef).unwrap();
//! let water = Aabb::new(Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 40.0, 50.0));
//! let mut sim = Sim::new(SpeciesSet::new(vec![species.into()]).unwrap(), water, 0.05, 7);
//! let id = sim.spawn("drifter", Vec3::new(0.0, 10.0, 0.0), 0.0).unwrap();
//! for _ in 0..20 {
//!     sim.step();
//! }
//! assert_eq!(sim.behavior(id), Some("drift"));
//! assert!(sim.agent(id).unwrap().pos.z > 0.0); // yaw 0 heads +z
//! ```

use crate::events::{Event, MessageKind};
use crate::perception::Percept;
use crate::species::SpeciesSet;
use crate::squad::Squads;
use crate::tick::{Pipeline, Remap};
use crate::world::{Aabb, Agent, AgentId, World};
use glam::Vec3;
use std::sync::Arc;

/// A world, its tick pipeline and its squads: the engine's running state.
pub struct Sim {
    /// Agents, obstacles, food, bounds, clock and the random streams' seed.
    pub world: World,
    /// The stages of a tick, the species they run and the events of the last tick.
    pub pipeline: Pipeline,
    /// Terrain and squads (empty without them).
    pub squads: Squads,
}

/// A species name that is not in the simulation's species set.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("no species \"{name}\" in this simulation (loaded: {loaded})")]
pub struct UnknownSpecies {
    /// The name asked for.
    pub name: String,
    /// The species loaded, comma-separated.
    pub loaded: String,
}

impl Sim {
    /// An empty world of `bounds` advancing `dt` seconds a tick, whose random streams derive
    /// from `seed`, running `species`.
    pub fn new(species: SpeciesSet, bounds: Aabb, dt: f32, seed: u64) -> Sim {
        Sim::from_parts(
            World::new(bounds, dt, seed),
            Pipeline::new(Arc::new(species)),
            Squads::default(),
        )
    }

    /// A simulation of an existing world, pipeline and squads.
    pub fn from_parts(world: World, pipeline: Pipeline, squads: Squads) -> Sim {
        Sim {
            world,
            pipeline,
            squads,
        }
    }

    /// Advances one tick. Its events are in [`Sim::events`] until the next step.
    pub fn step(&mut self) {
        self.step_with(|_, _| {});
    }

    /// Advances one tick, running `before` first (after the last tick's events are cleared):
    /// where a scenario applies its timed events and a test feeds percepts. Events `before`
    /// pushes to `pipeline.events` are part of this tick's.
    pub fn step_with(&mut self, before: impl FnOnce(&mut World, &mut Pipeline)) {
        self.begin_tick();
        before(&mut self.world, &mut self.pipeline);
        self.advance();
    }

    /// The first half of [`Sim::step_with`], for a caller whose additions need more than the
    /// world and the pipeline (a scenario spawning a timed group): clears the last tick's
    /// events. Call [`Sim::advance`] after the additions.
    pub fn begin_tick(&mut self) {
        self.pipeline.events.clear();
    }

    /// The second half of [`Sim::step_with`]: runs the tick.
    pub fn advance(&mut self) {
        self.squads.before_tick(&mut self.world, &mut self.pipeline);
        self.pipeline.step(&mut self.world);
        let set = self.pipeline.species.clone();
        self.squads.after_tick(&mut self.world, &set);
    }

    /// The species running.
    pub fn species(&self) -> &SpeciesSet {
        &self.pipeline.species
    }

    /// Installs a new version of the running species between ticks (hot reload), matched by
    /// name: agents keep their position, drives, memory, behavior and stack by behavior name;
    /// one whose behavior no longer exists falls back to the initial behavior, one whose species
    /// is gone is removed. The returned [`Remap`] lists those changes as events.
    pub fn set_species(&mut self, species: SpeciesSet) -> Remap {
        self.pipeline
            .install_species(&mut self.world, Arc::new(species))
    }

    /// Spawns an agent of `species` at `pos` (clamped into the world) heading `yaw` radians
    /// about world up (0 heads +z), level. Attributes and drives are drawn from the species'
    /// distributions with the agent's own random stream.
    pub fn spawn(&mut self, species: &str, pos: Vec3, yaw: f32) -> Result<AgentId, UnknownSpecies> {
        let set = &self.pipeline.species;
        let Some(s) = set.index_of(species) else {
            return Err(UnknownSpecies {
                name: species.to_string(),
                loaded: set
                    .species
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        };
        let pos = self.world.bounds.closest_point(pos);
        Ok(self.pipeline.spawn(&mut self.world, s, pos, yaw, 0.0))
    }

    /// Removes an agent between ticks; `false` when it is not in the world.
    pub fn despawn(&mut self, id: AgentId) -> bool {
        match self.world.agent_index(id) {
            Some(i) => {
                self.world.agents.remove(i);
                self.pipeline.injected.remove(&id);
                true
            }
            None => false,
        }
    }

    /// The agent `id`, while it is in the world.
    pub fn agent(&self, id: AgentId) -> Option<&Agent> {
        self.world.agent(id)
    }

    /// Every agent, in spawn order.
    pub fn agents(&self) -> &[Agent] {
        &self.world.agents
    }

    /// The name of the behavior agent `id` is in.
    pub fn behavior(&self, id: AgentId) -> Option<&str> {
        let a = self.world.agent(id)?;
        let sp = self.pipeline.species.species.get(a.species.0 as usize)?;
        Some(sp.behavior_name(a.mind.current))
    }

    /// The events of the last tick (transitions, meals, catches, messages, script errors…).
    pub fn events(&self) -> &[Event] {
        &self.pipeline.events
    }

    /// Adds `percepts` to what agent `id` perceives, every tick until [`Sim::clear_injected`]
    /// (a game's own sensing: a sound, the player). Offsets are in world axes from the agent;
    /// bearings are taken as given.
    pub fn inject(&mut self, id: AgentId, percepts: Vec<Percept>) {
        self.pipeline.injected.insert(id, percepts);
    }

    /// Stops adding injected percepts to agent `id`.
    pub fn clear_injected(&mut self, id: AgentId) {
        self.pipeline.injected.remove(&id);
    }

    /// Delivers a message of `kind` to agent `id`, heard in the next tick (`Heard(kind)`) as if
    /// a neighbour had sent it. `false` when the agent is not in the world.
    pub fn send(&mut self, id: AgentId, kind: MessageKind) -> bool {
        self.pipeline.deliver(&mut self.world, id, kind)
    }

    /// Ticks run so far.
    pub fn tick(&self) -> u64 {
        self.world.tick
    }

    /// Simulated seconds so far.
    pub fn time(&self) -> f64 {
        self.world.time()
    }
}
