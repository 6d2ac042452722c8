//! The tick pipeline, run by [`Pipeline::step`] (which [`crate::sim::Sim::step`], the one place
//! the world advances, calls). A tick reads as its phases:
//!
//! `index → perceive → agent pass (drives, decide, steer, move) → events::apply`
//!
//! Stages 1–2 ([`Pipeline::perceive`]): the spatial index, then perception. Stages 3–6
//! (`agent_pass.rs`) run per agent in parallel (rayon) from the state at the start of the tick:
//! each agent's pass reads its own record and perception's copy of the others, then rewrites
//! only its own record and outcome slot. Stage 7 (`events/apply.rs`) applies what reaches beyond
//! the agent (events, messages, contacts) in agent order. Results are therefore bit-identical
//! whatever the thread count.
//!
//! Beside the phases: `spawn.rs` (changes between ticks: spawning, delivered messages, forced
//! behaviors), `stats.rs` (counters and stage times), `reads.rs` (what each species reads of
//! perception), `remap.rs` (hot reload of the species), `awake.rs` (a pool thread kept awake for
//! the length of a tick).

use crate::events::{Event, MessageKind};
use crate::index::{Grid, Layout};
use crate::perception::{Perception, Reads, Source};
use crate::species::{Contact, SpeciesSet};
use crate::world::{Aabb, AgentId, World};
use glam::Vec3;
use rhai::ImmutableString;
use std::sync::Arc;
use std::time::Instant;

mod agent_pass;
mod awake;
pub mod explain;
pub mod governor;
mod reads;
mod remap;
mod spawn;
mod stats;
#[cfg(test)]
mod tests;
use agent_pass::Worker;
pub(crate) use agent_pass::{More, Outcome, Rare};
pub use explain::Explain;
pub use reads::{bearing_range, reads};
pub use remap::Remap;
pub use spawn::force_behavior;
pub use stats::{StageTimes, Stats};

/// Agents from which a tick keeps a helper thread awake: below, perception's passes do not
/// split and a tick is too short for the helper's spinning to pay for the core it takes.
pub const HELPER_FROM: usize = 512;

/// The tick pipeline and its reusable buffers.
pub struct Pipeline {
    /// The species in use (swapped on reload).
    pub species: Arc<SpeciesSet>,
    pub(crate) agent_grid: Grid,
    food_grid: Grid,
    pub(crate) perception: Perception,
    pub(crate) outcomes: Vec<Outcome>,
    pub(crate) species_names: Vec<ImmutableString>,
    pub(crate) behavior_names: Vec<Vec<ImmutableString>>,
    pub(crate) taken_food: Vec<bool>,
    pub(crate) dead: Vec<bool>,
    pub(crate) mated: Vec<bool>,
    pub(crate) next_inbox: Vec<Option<MessageKind>>,
    /// The declared event each agent hears next tick (the other half of its one inbox slot).
    pub(crate) next_events: Vec<Option<crate::world::HeardEvent>>,
    /// Payloads of the declared events sent this tick, for `next_events`.
    pub(crate) next_payloads: Vec<crate::world::Payload>,
    /// Whether the last tick delivered any message (some agent's inbox may be set).
    pub(crate) delivered: bool,
    pub(crate) contacts: Vec<(usize, Contact, Source)>,
    /// Events of the last tick, in order.
    pub events: Vec<Event>,
    /// Running counters.
    pub stats: Stats,
    /// Per-agent targets of planned paths (set by the planning layer), by agent index.
    pub plan_targets: Vec<Option<Vec3>>,
    /// Every agent's own best food position at the start of the tick, by agent index (what
    /// its kin read as the school's best, seed 003): 12 bytes each, not an option's 16.
    known_food: Vec<crate::world::Spot>,
    /// Percepts fed to agents instead of what they perceive (script tests), by agent id.
    pub injected: std::collections::BTreeMap<AgentId, Vec<crate::perception::Percept>>,
    /// Run every agent's scripts every tick, whatever the species' decision interval (a dry
    /// run of a new version exercises every agent in one tick).
    pub scripts_every_tick: bool,
    /// Per species: what its behaviors read of perception (see [`reads`]).
    reads: Vec<Reads>,
    full_bearings: bool,
    species_counts: Vec<u32>,
    /// Per worker thread (by rayon thread index): buffers kept across ticks.
    workers: Vec<std::sync::Mutex<Worker>>,
    times: StageTimes,
    /// Wall-time guard of the tick's script calls.
    pub(crate) script_clock: Arc<crate::script::TickClock>,
    /// What the next ticks explain (off by default; see [`explain`]).
    pub explain: Explain,
    /// The last tick's explanations (frames and decisions, JSON), in agent order.
    pub explained: Vec<serde_json::Value>,
    /// Agent ids by index at the start of the tick, kept while explaining.
    explain_ids: Vec<u32>,
    /// Whether each tick runs on the whole pool or on one thread ([`governor`]).
    pub governor: governor::Governor,
}

/// The species with the most agents in `counts` (the first of equals): its query radius sizes
/// the agent grid's cells.
fn most_numerous(counts: &[u32]) -> usize {
    (0..counts.len())
        .max_by_key(|&s| (counts[s], std::cmp::Reverse(s)))
        .unwrap_or(0)
}

/// Cell size of the agent grid when species `s` is the most numerous: its query radius.
fn agent_cell(set: &SpeciesSet, s: usize) -> f32 {
    set.senses.get(s).map_or(1.0, |s| s.query_radius()).max(0.5)
}

impl Pipeline {
    /// A pipeline for these species.
    pub fn new(species: Arc<SpeciesSet>) -> Self {
        let mut p = Pipeline {
            species: species.clone(),
            agent_grid: Grid::new(),
            food_grid: Grid::new(),
            perception: Perception::new(),
            outcomes: Vec::new(),
            species_names: Vec::new(),
            behavior_names: Vec::new(),
            taken_food: Vec::new(),
            dead: Vec::new(),
            mated: Vec::new(),
            next_inbox: Vec::new(),
            next_events: Vec::new(),
            next_payloads: Vec::new(),
            delivered: false,
            contacts: Vec::new(),
            events: Vec::new(),
            stats: Stats::default(),
            plan_targets: Vec::new(),
            known_food: Vec::new(),
            injected: Default::default(),
            scripts_every_tick: false,
            reads: Vec::new(),
            full_bearings: false,
            species_counts: Vec::new(),
            workers: Vec::new(),
            times: StageTimes::default(),
            script_clock: Default::default(),
            explain: Explain::default(),
            explained: Vec::new(),
            explain_ids: Vec::new(),
            governor: governor::Governor::default(),
        };
        p.set_species(species);
        p
    }

    /// Sets the wall-time budgets of script calls (default: [`crate::script::TimeBudget`]'s).
    pub fn set_time_budget(&mut self, budget: crate::script::TimeBudget) {
        self.stats.script_timeouts += self.script_clock.take_exceeded();
        self.script_clock = Arc::new(crate::script::TickClock::new(budget));
    }

    /// The wall-time budgets of script calls.
    pub fn time_budget(&self) -> crate::script::TimeBudget {
        self.script_clock.budget()
    }

    /// Installs a species set (at a tick boundary) and refreshes the name tables.
    pub fn set_species(&mut self, species: Arc<SpeciesSet>) {
        self.species_names = species
            .species
            .iter()
            .map(|s| s.name.as_str().into())
            .collect();
        self.behavior_names = species
            .species
            .iter()
            .map(|s| s.behaviors.iter().map(|b| (&*b.name).into()).collect())
            .collect();
        self.stats
            .behavior_ticks
            .resize(species.species.len(), Vec::new());
        for (i, s) in species.species.iter().enumerate() {
            self.stats.behavior_ticks[i].resize(s.behaviors.len(), 0);
        }
        self.species = species;
        self.refresh_reads();
    }

    /// With `true`, every agent keeps its percepts, each with its bearing and elevation (for
    /// tools that show all of an agent's percepts); by default only what the species' behaviors
    /// can read is kept (see [`reads`]).
    pub fn set_full_bearings(&mut self, on: bool) {
        self.full_bearings = on;
        self.refresh_reads();
    }

    fn refresh_reads(&mut self) {
        let full = self.full_bearings;
        self.reads = self
            .species
            .species
            .iter()
            .map(|s| {
                let mut r = reads(s);
                if full {
                    r.percepts = true;
                    r.agent_percepts = true;
                    r.bearing_range = None;
                }
                r
            })
            .collect();
    }

    /// Percepts of the last tick's perception stage, by agent index.
    pub fn perception(&self) -> &Perception {
        &self.perception
    }

    /// The agent grid of the last tick (or [`Pipeline::perceive`]).
    pub fn agent_grid(&self) -> &Grid {
        &self.agent_grid
    }

    /// The layout of the agent grid over `bounds` for `counts[s]` agents of each species `s`:
    /// cells of the most numerous species' query radius, as [`Pipeline::perceive`] builds it. A
    /// group numbered in its cells' order is walked by perception and the agent pass in the
    /// order perception's lanes hold it.
    pub fn agent_layout(&self, bounds: Aabb, counts: &[u32]) -> Layout {
        let n = counts.iter().map(|&c| c as usize).sum();
        Layout::new(bounds, agent_cell(&self.species, most_numerous(counts)), n)
    }

    /// Stages 1–2 alone: rebuilds the spatial index and runs perception on `world` (results in
    /// [`Pipeline::perception`]). [`Pipeline::step`] starts with this.
    pub fn perceive(&mut self, world: &World) {
        let start = Instant::now();
        self.index(world);
        let indexed = Instant::now();
        self.run_perception(world);
        let perceived = Instant::now();
        self.times.index += indexed - start;
        self.times.perception += perceived - indexed;
        self.times.ticks += 1;
    }

    /// Stage 1: the agent and food grids.
    fn index(&mut self, world: &World) {
        let set = &self.species;
        // 1. Spatial index. Cells of the query radius of the most numerous species, a quarter
        // of it along x: its queries read 9 runs of contiguous entries (3 in a flat world),
        // each 2r and a narrow cell long. Cells of half a radius read less space but in 25
        // runs, each a fresh place in memory: slower at 100k agents (reef 5.7 against 6.4
        // ticks/s), no faster at 10k. Cutting each run to the sphere's chord in its row reads
        // 14 % fewer candidates but costs more per row than it saves (boids +5 %, reef +5 %
        // instructions). Any cell size gives the same neighbors (but for one within a few units in
        // the last place of the range, across a cell boundary from where the box's bound rounded).
        let most = if set.species.len() <= 1 {
            0
        } else {
            self.species_counts.clear();
            self.species_counts.resize(set.species.len(), 0);
            world.count_species(&mut self.species_counts);
            most_numerous(&self.species_counts)
        };
        let cell = agent_cell(set, most);
        self.agent_grid
            .rebuild_with(world.bounds, cell, world.agents.len(), |i| {
                world.agents[i].pos
            });
        self.food_grid
            .rebuild(world.bounds, cell, world.food.iter().map(|f| f.pos));
    }

    /// Stage 2: perception, then the percepts fed to agents (script tests).
    fn run_perception(&mut self, world: &World) {
        let set = &self.species;
        // 2. Perception. Agents fed percepts need slots for them, whatever their species reads.
        // A fed percept may be of any category: every row then holds every category.
        self.perception.set_full_rows(!self.injected.is_empty());
        if !self.injected.is_empty() {
            for r in &mut self.reads {
                r.percepts = true;
                r.agent_percepts = true;
                r.headings = true;
            }
        }
        self.perception.run_selective(
            world,
            &self.agent_grid,
            &self.food_grid,
            &set.senses,
            &set.relations,
            &self.reads,
        );
        for (id, percepts) in &self.injected {
            if let Some(i) = world.agent_index(*id) {
                self.perception.inject(i, world.agents[i].pos, percepts);
            }
        }
    }

    /// Advances `world` by one tick, appending the tick's events to [`Pipeline::events`]. It
    /// does not clear the events: [`crate::sim::Sim::step`] does, before its `before` hook, so
    /// what the hook pushes (a scenario's timed spawns) is part of the tick's events, while
    /// spawns made between two steps are in them only until the next step. Nor does it clear
    /// [`Pipeline::plan_targets`] or [`Pipeline::injected`]. What a tick replaces is every
    /// agent's inbox, by what this tick sent it, once a message was delivered in this tick or
    /// the last ([`Pipeline::deliver`] counts).
    ///
    /// From [`HELPER_FROM`] agents, another thread of the current rayon pool spins for the
    /// length of the tick, looking for the tick's work (`awake::with_helper`); in a pool
    /// shared with other work it may pick up a job of someone else's, and the tick then ends
    /// when that job does. A panic inside a tick (a bug) leaves `world` part-way through it.
    ///
    /// With two threads or more and [`HELPER_FROM`] agents, the [`governor`] chooses whether
    /// the tick runs on the pool or on one thread (the results are the same either way).
    pub fn step(&mut self, world: &mut World) {
        let agents = world.agents.len();
        let adaptive = self.governor.schedule == governor::Schedule::Adaptive;
        if rayon::current_num_threads() < 2 || (adaptive && agents < HELPER_FROM) {
            self.step_on(world);
            return;
        }
        let mode = self.governor.next_mode();
        let start = Instant::now();
        match mode {
            governor::Mode::Pool => awake::with_helper(|| self.step_on(world)),
            // The tick's script clock is this thread's for the tick only: a thread outside any
            // pool keeps its own afterwards.
            governor::Mode::Solo => {
                let clock = self.script_clock.clone();
                crate::script::budget::with_tick(&clock, || {
                    crate::par::alone(|| self.step_on(world))
                })
            }
        }
        self.governor.record(mode, agents, start.elapsed());
    }

    /// The phases of a tick, timed.
    fn step_on(&mut self, world: &mut World) {
        // A spawn of many agents leaves a long event list behind (a scenario's groups: an
        // event each): give the memory back once it is far larger than what ticks use, before
        // perception takes its own (at a million agents the two at once were the run's peak).
        if self.events.capacity() > 8 * (self.events.len() + 1024) {
            self.events.shrink_to(2 * (self.events.len() + 1024));
        }
        // 1–2. Spatial index and perception.
        self.perceive(world);
        // 3–6. Per agent: drives, decision, steering, locomotion.
        let start = Instant::now();
        self.agent_pass(world);
        self.explained.clear();
        if self.explain.on() {
            for o in &mut self.outcomes {
                let more = o.rare.as_mut().and_then(|r| r.more.as_mut());
                if let Some(e) = more.and_then(|m| m.explain.take()) {
                    self.explained.extend(e.decision);
                    self.explained.extend(e.frame);
                }
            }
        }
        let passed = Instant::now();
        // 7. World events, applied in agent order.
        self.apply(world);
        self.stats.script_timeouts += self.script_clock.take_exceeded();
        self.times.agents += passed - start;
        self.times.events += passed.elapsed();
    }
}
