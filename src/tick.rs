//! The tick's stages, run by [`Pipeline::step`] (which [`crate::sim::Sim::step`], the one place
//! the world advances, calls):
//!
//! `index → perception → drives → decision → steering → locomotion → world events`. Stages 3–6
//! run per agent in parallel (rayon) from the state at the start of the tick: each agent's pass
//! reads its own record and perception's copy of the others, then rewrites only its own record
//! and outcome slot; stage 7 applies what reaches beyond the agent (events, messages, contacts)
//! in agent order (`events/apply.rs`). Results are therefore bit-identical whatever the thread
//! count.

use crate::decision::{self, focus, scripts, Ctx, Transitions};
use crate::diag::Diagnostic;
use crate::drives::{self, Stimuli};
use crate::events::{Cause, Event, MessageKind};
use crate::index::{Grid, Layout};
use crate::locomotion::{self, anim, Motion};
use crate::perception::{Category, GroupQueries, Perception, Reads, Source};
use crate::script::AgentView;
use crate::species::{ActionNode, Contact, Draw, SexDef, SpeciesSet};
use crate::steering::recipe::{self, Scratch};
use crate::steering::Steer;
use crate::world::{
    Aabb, Agent, AgentId, Anim, Attributes, Drives, ForwardCache, Mind, Rng, Sex, SpeciesId, World,
};
use glam::Vec3;
use rayon::prelude::*;
use rhai::{Dynamic, ImmutableString, Scope};
use std::sync::Arc;
use std::time::{Duration, Instant};

mod awake;
mod reads;
mod remap;
pub use reads::{bearing_range, reads};
pub use remap::Remap;

/// An empty mind: what an agent's record holds while its pass has its mind.
impl Default for Mind {
    fn default() -> Self {
        Mind::new(0, 0, 0)
    }
}

/// One worker thread's reusable buffers for stages 3–6.
struct Worker {
    scope: Scope<'static>,
    scratch: Scratch,
    /// The script view, refilled in place for each call.
    view: Dynamic,
}

impl Default for Worker {
    fn default() -> Self {
        Worker {
            scope: Scope::new(),
            scratch: Scratch::default(),
            view: Dynamic::from(AgentView::default()),
        }
    }
}

/// Agents from which a tick keeps a helper thread awake: below, perception's passes do not
/// split and a tick is too short for the helper's spinning to pay for the core it takes.
pub const HELPER_FROM: usize = 512;

/// What one agent's pass produced beyond its own record (applied in agent order by stage 7).
#[derive(Debug, Default)]
pub(crate) struct Outcome {
    pub(crate) contact: Option<(Contact, Source)>,
    /// Species and behavior after the tick (for the counters, read without touching the agent).
    pub(crate) species: u16,
    pub(crate) behavior: u16,
    /// Transitions, messages and errors: a few agents a tick have any, so they are boxed and
    /// the per-agent buffer stays small.
    pub(crate) rare: Option<Box<Rare>>,
}

/// The parts of an outcome most agents do not have in a given tick.
#[derive(Debug, Default)]
pub(crate) struct Rare {
    pub(crate) transitions: Transitions,
    pub(crate) messages: [Option<(MessageKind, f32)>; 4],
    pub(crate) error: Option<Diagnostic>,
}

/// Counters a run summary reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Food items eaten.
    pub meals: u64,
    /// Prey caught.
    pub catches: u64,
    /// Matings.
    pub matings: u64,
    /// Behavior transitions.
    pub transitions: u64,
    /// Failed script calls (each agent's first one is also an event).
    pub script_errors: u64,
    /// Of those, calls stopped by a wall-time budget ([`crate::script::TimeBudget`]): when
    /// non-zero, the run's results depend on the machine's speed.
    pub script_timeouts: u64,
    /// Agent-ticks spent in each behavior, by species then behavior index.
    pub behavior_ticks: Vec<Vec<u64>>,
}

/// Wall time spent in each stage of the tick, summed over the ticks since the last
/// [`Pipeline::reset_stage_times`] (what a profile of the pipeline starts from: `shoal bench
/// --stages` prints it). Stages 3–6 run together, per agent, so they are one figure.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    /// Stage 1: the spatial index (agent and food grids).
    pub index: Duration,
    /// Stage 2: perception.
    pub perception: Duration,
    /// Stages 3–6: drives, decision, steering and locomotion, per agent.
    pub agents: Duration,
    /// Stage 7: world events, in agent order.
    pub events: Duration,
    /// Ticks summed (calls of [`Pipeline::perceive`] alone count for stages 1–2 only).
    pub ticks: u64,
}

impl StageTimes {
    /// The stages' names, in pipeline order.
    pub const NAMES: [&'static str; 4] = ["index", "perception", "agents", "events"];

    /// The stages' names and their summed times, in pipeline order.
    pub fn parts(&self) -> [(&'static str, Duration); 4] {
        let [a, b, c, d] = Self::NAMES;
        [
            (a, self.index),
            (b, self.perception),
            (c, self.agents),
            (d, self.events),
        ]
    }

    /// The stages' names and their mean milliseconds per tick, in pipeline order.
    pub fn ms_per_tick(&self) -> [(&'static str, f64); 4] {
        let per = |d: Duration| 1e3 * d.as_secs_f64() / self.ticks.max(1) as f64;
        self.parts().map(|(name, d)| (name, per(d)))
    }
}

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
    /// its kin read as the school's best, seed 003).
    known_food: Vec<Option<Vec3>>,
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

fn draw(d: Draw, rng: &mut Rng) -> f32 {
    match d {
        Draw::Fixed(x) => x,
        Draw::Uniform(a, b) => rng.range(a, b),
    }
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
        };
        p.set_species(species);
        p
    }

    /// Delivers a message of `kind` to agent `id` between ticks, heard in the next tick as if a
    /// neighbour had sent it (and gone after it, like any message). `false` when the agent is
    /// not in `world`.
    pub fn deliver(&mut self, world: &mut World, id: AgentId, kind: MessageKind) -> bool {
        let Some(a) = world.agent_index(id).map(|i| &mut world.agents[i]) else {
            return false;
        };
        a.inbox = Some(MessageKind::max_priority(a.inbox, kind));
        // The tick clears every inbox it did not fill only when one was filled.
        self.delivered = true;
        true
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

    /// Wall time spent in each stage since the last [`Pipeline::reset_stage_times`] (or since
    /// the pipeline was made).
    pub fn stage_times(&self) -> StageTimes {
        self.times
    }

    /// Starts the stage times again from zero.
    pub fn reset_stage_times(&mut self) {
        self.times = StageTimes::default();
    }

    /// Spawns an agent of species `s` at `pos` heading `(yaw, pitch)`; attributes and initial
    /// drives are drawn from the species' distributions with the agent's own random stream.
    pub fn spawn(
        &mut self,
        world: &mut World,
        s: usize,
        pos: Vec3,
        yaw: f32,
        pitch: f32,
    ) -> AgentId {
        let sp = &self.species.species[s];
        let id = AgentId(world.next_agent_id);
        world.next_agent_id += 1;
        let mut rng = Rng::new(world.seed, id.0 as u64);
        let d = &**sp;
        let sex = match d.attributes.sex {
            SexDef::Random => {
                if rng.next_f32() < 0.5 {
                    Sex::Female
                } else {
                    Sex::Male
                }
            }
            SexDef::Female => Sex::Female,
            SexDef::Male => Sex::Male,
        };
        let attrs = Attributes {
            sex,
            age: draw(d.attributes.age, &mut rng),
            mass: draw(d.attributes.mass, &mut rng),
            kind: d.attributes.kind,
        };
        let mut drives = Drives {
            hunger: draw(d.drives.hunger, &mut rng),
            libido: draw(d.drives.libido, &mut rng),
            since_meal: draw(d.drives.since_meal, &mut rng),
            ..Drives::default()
        };
        // Start the meal clock where the initial hunger says (digestion: n_e·r(Δt)/n_a = 1 − H;
        // exponential: the Δt_H whose hunger is H).
        (drives.eaten, drives.since_meal) =
            drives::meal_clock_for(drives.hunger, drives.since_meal, &d.drives.params);
        // Likewise the mating clock: l(Δt_L)·(1 − H) = L.
        drives.since_mating =
            drives::since_mating_for(drives.libido, drives.hunger, &d.drives.params);
        let mut mind = Mind::new(sp.initial, sp.behaviors.len(), sp.slots.len());
        mind.script_steer = vec![Vec::new(); sp.steer_slots];
        mind.entered_tick = world.tick;
        let speed = 0.5 * d.body.limits.max_speed;
        let agent = Agent {
            id,
            species: SpeciesId(s as u16),
            pos,
            prev_pos: pos,
            yaw,
            pitch: pitch.clamp(-d.body.limits.pitch_limit(), d.body.limits.pitch_limit()),
            speed,
            yaw_rate: 0.0,
            pitch_rate: 0.0,
            size: d.body.size,
            drives,
            attrs,
            mind,
            anim: Anim::default(),
            rng,
            memory: Vec::new(),
            inbox: None,
            forward_cache: crate::world::ForwardCache::NONE,
        };
        world.agents.push(agent);
        self.events.push(Event::Spawn {
            agent: id,
            species: s as u16,
        });
        id
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
        let set = &self.species;
        // 1. Spatial index. Cells of the query radius of the most numerous species, a quarter
        // of it along x: its queries read 9 runs of contiguous entries (3 in a flat world),
        // each 2r and a narrow cell long. Cells of half a radius read less space but in 25
        // runs, each a fresh place in memory: slower at 100k agents (reef 5.7 against 6.4
        // ticks/s), no faster at 10k. Cutting each run to the sphere's chord in its row reads
        // 14 % fewer candidates but costs more per row than it saves (boids +5 %, reef +5 %
        // instructions). Any cell size gives the same neighbors.
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
        let indexed = Instant::now();
        // 2. Perception. Agents fed percepts need slots for them, whatever their species reads.
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
        let perceived = Instant::now();
        self.times.index += indexed - start;
        self.times.perception += perceived - indexed;
        self.times.ticks += 1;
    }

    /// Advances `world` by one tick, appending the tick's events to [`Pipeline::events`]. It
    /// does not clear them: [`crate::sim::Sim::step`], the one caller outside tests of the
    /// stages, clears them before the tick (spawns made between ticks stay in).
    ///
    /// From [`HELPER_FROM`] agents, another thread of the current rayon pool spins for the
    /// length of the tick, looking for the tick's work (`awake::with_helper`); in a pool
    /// shared with other work it may pick up a job of someone else's, and the tick then ends
    /// when that job does. A panic inside a tick (a bug) leaves `world` part-way through it.
    pub fn step(&mut self, world: &mut World) {
        if world.agents.len() >= HELPER_FROM {
            awake::with_helper(|| self.step_on(world));
        } else {
            self.step_on(world);
        }
    }

    fn step_on(&mut self, world: &mut World) {
        let n = world.agents.len();
        let set = self.species.clone();
        self.perceive(world);
        let start = Instant::now();
        // 3–6. Per agent: drives, decision, steering, locomotion. Each agent's pass reads and
        // then rewrites its own record; the records are out of the world meanwhile, and what
        // an agent reads of another is perception's copy from the start of the tick.
        self.outcomes.resize_with(n, Outcome::default);
        self.known_food.clear();
        self.known_food
            .extend(world.agents.iter().map(|a| a.mind.best_food));
        let known_food = &self.known_food[..];
        let mut agents = std::mem::take(&mut world.agents);
        let world_ref: &World = world;
        let perception = &self.perception;
        let names = (&self.species_names, &self.behavior_names);
        let plan_targets = &self.plan_targets;
        let every_tick = self.scripts_every_tick;
        let reads = &self.reads[..];
        let threads = rayon::current_num_threads();
        if self.workers.len() < threads {
            self.workers.resize_with(threads, Default::default);
        }
        let workers = &self.workers;
        let clock = &self.script_clock;
        clock.reset();
        // A panic in the pass (a bug) still gives the world its agents back before it unwinds.
        let pass = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            agents
                .par_iter_mut()
                .zip(self.outcomes.par_iter_mut())
                .enumerate()
                .with_min_len(32)
                .for_each_init(
                    || {
                        crate::script::budget::install(clock);
                        // This thread's buffers, kept from tick to tick; a fresh set only if they
                        // are somehow in use.
                        let own = rayon::current_thread_index()
                            .and_then(|t| workers.get(t))
                            .and_then(|w| w.try_lock().ok());
                        let fresh = own.is_none().then(Worker::default);
                        (own, fresh)
                    },
                    |(own, fresh), (i, (agent, out))| {
                        let w = match (own.as_deref_mut(), fresh.as_mut()) {
                            (Some(w), _) => w,
                            (None, Some(w)) => w,
                            (None, None) => unreachable!("one of the two is set"),
                        };
                        w.scratch.reset();
                        w.scratch.set_velocity(perception.velocity(i));
                        w.scratch.plan_target = plan_targets.get(i).copied().flatten();
                        agent_pass(
                            i,
                            agent,
                            world_ref,
                            &set,
                            perception,
                            names,
                            out,
                            &mut w.scope,
                            &mut w.scratch,
                            &mut w.view,
                            every_tick,
                            reads,
                            known_food,
                        );
                    },
                );
        }));
        world.agents = agents;
        if let Err(panic) = pass {
            std::panic::resume_unwind(panic);
        }
        let passed = Instant::now();
        // 7. World events, applied in agent order.
        self.apply(world);
        self.stats.script_timeouts += self.script_clock.take_exceeded();
        self.times.agents += passed - start;
        self.times.events += passed.elapsed();
    }
}

/// Seed 003's foraging memory, particle-swarm style. The own best food position is where the
/// agent last perceived food (the nearest item or prey), forgotten once the place is within
/// its vision radius and no food is perceived (eaten or gone). The school's best is the own
/// best of a perceived kin nearest to it (their values from the start of the tick); none when
/// no perceived kin knows food, so a school without food has no foraging target.
fn remember_food(
    mind: &mut Mind,
    pos: Vec3,
    percepts: &[crate::perception::Percept],
    vision_radius: f32,
    known_food: &[Option<Vec3>],
) {
    let food = percepts
        .iter()
        .filter(|p| p.category == Category::Food)
        .min_by(|a, b| a.dist.total_cmp(&b.dist));
    match food {
        Some(f) => mind.best_food = Some(pos + f.offset),
        None => {
            if mind
                .best_food
                .is_some_and(|b| b.distance_squared(pos) <= vision_radius * vision_radius)
            {
                mind.best_food = None;
            }
        }
    }
    mind.school_best = percepts
        .iter()
        .filter(|p| p.category == Category::Kin)
        .filter_map(|p| match p.source {
            Source::Agent(j) => known_food.get(j as usize).copied().flatten(),
            _ => None,
        })
        .min_by(|a, b| a.distance_squared(pos).total_cmp(&b.distance_squared(pos)));
}

/// Stages 3–6 for agent `i`.
#[allow(clippy::too_many_arguments)]
fn agent_pass(
    i: usize,
    agent: &mut Agent,
    world: &World,
    set: &SpeciesSet,
    perception: &Perception,
    names: (&Vec<ImmutableString>, &Vec<Vec<ImmutableString>>),
    out: &mut Outcome,
    scope: &mut Scope,
    scratch: &mut Scratch,
    view: &mut Dynamic,
    scripts_every_tick: bool,
    reads: &[Reads],
    known_food: &[Option<Vec3>],
) {
    // The mind is out of the record until the end of the pass (the record is read through
    // `Ctx` meanwhile); the random stream is the pass's own copy.
    let mut mind = std::mem::take(&mut agent.mind);
    let mind = &mut mind;
    let mut rng = agent.rng;
    let rng = &mut rng;
    let s = agent.species.0 as usize;
    let group_queries = reads.get(s).map_or(&GroupQueries::EMPTY, |r| &r.groups);
    let sp = &set.species[s];
    let def = &**sp;
    let percepts = perception.percepts(i);
    let summaries = perception.summaries(i);
    let group_sums = perception.group_sums(i);
    let dt = world.dt;
    let tick = world.tick;

    // 3. Drives, in the agent's own record (what others read of it is perception's copy from
    // the start of the tick).
    let me = agent;
    if def.drives.native {
        let stim = |c: Category| {
            drives::stimulus(summaries[c as usize].nearest_dist, sp.senses.smell_radius)
        };
        let stimuli = Stimuli {
            food: stim(Category::Food),
            mate: stim(Category::Mate),
        };
        // Every predator perceived, not only the kept percepts.
        let sm = &summaries[Category::Predator as usize];
        let predators = drives::PredatorSums {
            count: sm.count,
            nearest: sm.nearest_dist,
            inv_dist_sum: sm.inv_dist_sum,
        };
        drives::update(&mut me.drives, &def.drives.params, stimuli, &predators, dt);
    } else {
        me.drives.since_meal += dt;
        me.drives.since_mating += dt;
        let q = &def.drives.params;
        me.drives.state = drives::internal_state(me.drives.since_meal, q.s_max, q.delta);
    }
    remember_food(mind, me.pos, percepts, sp.senses.vision_radius, known_food);
    let mut error = None;
    let mut messages: [Option<(MessageKind, f32)>; 4] = [None; 4];

    // 4. Decision: scripts at the decision rate, then arbitration.
    let script = sp
        .script
        .as_deref()
        .filter(|_| !sp.slots.is_empty() || sp.has_on_tick);
    if let Some(script) = script {
        // Right after a contact (a meal, a mating) the script's last answers predate what just
        // happened (its `on_event` may have changed the blackboard): its conditions are asked
        // again now, so the behavior that ends on the contact hands over to the right next one
        // at once instead of to a stale choice that the next scheduled call overturns a few
        // ticks later.
        let due = scripts_every_tick || scripts::due(tick, me.id.0, def.decision_interval);
        if due || mind.reached {
            let ctx = Ctx {
                world,
                perception,
                species: sp,
                agent: &*me,
                percepts,
                summaries,
                group_queries,
                group_sums,
                tick,
                dt,
            };
            // The worker's view is refilled in place (no allocation per call). The blackboard
            // is copied in and back out, not moved: a script that replaces `this` leaves the
            // agent's own blackboard as it was.
            if !view.is::<AgentView>() {
                *view = Dynamic::from(AgentView::default());
            }
            if let Some(mut v) = view.write_lock::<AgentView>() {
                let behavior = &names.1[s][mind.current as usize];
                scripts::fill_view(&mut v, &ctx, mind, &names.0[s], behavior);
                v.rng = *rng;
            }
            let r = if due {
                scripts::run_slots(sp, script, mind, view, scope)
            } else {
                scripts::run_conditions(sp, script, mind, view, scope)
            };
            if let Some(mut v) = view.write_lock::<AgentView>() {
                scripts::write_back(&v, me);
                *rng = v.rng;
                for (k, m) in v.outbox.drain(..).take(2).enumerate() {
                    messages[2 + k] = Some(m);
                }
            }
            if let Err(e) = r {
                error = Some(e);
            }
        }
    }
    let ctx = Ctx {
        world,
        perception,
        species: sp,
        agent: &*me,
        percepts,
        summaries,
        group_queries,
        group_sums,
        tick,
        dt,
    };
    let transitions = decision::arbitrate(&ctx, mind, rng);
    let mut pending = None;
    if let Some(t) = transitions.iter().flatten().last() {
        let b = &sp.behaviors[t.to as usize];
        let mut k = 0;
        for a in &b.on_enter {
            match a {
                ActionNode::Send(kind, r) if k < 2 => {
                    let quiet = &mut mind.quiet_until[*kind as usize];
                    if tick >= *quiet {
                        *quiet =
                            tick.saturating_add((def.resend_after.max(0.0) / dt).ceil() as u64);
                        messages[k] = Some((*kind, *r));
                        k += 1;
                    }
                }
                ActionNode::Call(f) => {
                    if let Some(script) = sp.script.as_deref() {
                        let mut view = scripts::view_of(
                            &ctx,
                            mind,
                            &names.0[s],
                            &names.1[s][mind.current as usize],
                        );
                        // The stream as arbitration left it (the record's is the tick's start).
                        view.rng = *rng;
                        let mut this = Dynamic::from(view);
                        match script.call::<Dynamic>(scope, &mut this, f) {
                            Ok(_) => pending = this.try_cast::<crate::script::AgentView>(),
                            Err(e) => error = Some(*e.diagnostic),
                        }
                    }
                }
                _ => {}
            }
        }
    }
    if let Some(v) = pending {
        scripts::write_back(&v, me);
        *rng = v.rng;
    }
    let ctx = Ctx {
        world,
        perception,
        species: sp,
        agent: &*me,
        percepts,
        summaries,
        group_queries,
        group_sums,
        tick,
        dt,
    };

    // 5. Steering.
    let b = &sp.behaviors[mind.current as usize];
    let mut steer = match b.focus {
        None => recipe::evaluate(&b.steer, &ctx, mind, rng, scratch, 0),
        // Seed 000 §1's focuser: the steering of the current intention sees only what it
        // cares about (the group sums are kin's).
        Some(f) => {
            let mut kept = std::mem::take(&mut scratch.focused);
            let summaries = focus::narrow(f, percepts, summaries, &mut kept);
            let focused = Ctx {
                percepts: &kept,
                summaries: &summaries,
                group_sums: if f.contains(Category::Kin) {
                    group_sums
                } else {
                    &[]
                },
                ..ctx
            };
            let s = recipe::evaluate(&b.steer, &focused, mind, rng, scratch, 0);
            scratch.focused = kept;
            s
        }
    };
    if error.is_some() || !steer.is_finite() {
        steer = mind.last_steer;
    }
    if steer.is_none() {
        steer = Steer::keep(&ctx.kin());
    }
    mind.last_steer = steer;

    // 6. Locomotion and animation.
    let mut motion = Motion {
        pos: me.pos,
        yaw: me.yaw,
        pitch: me.pitch,
        speed: me.speed,
        yaw_rate: me.yaw_rate,
        pitch_rate: me.pitch_rate,
    };
    // A behavior may turn faster or slower than the body does by default.
    let body = &def.body.limits;
    let limits = &match sp
        .behaviors
        .get(mind.current as usize)
        .and_then(|b| b.response)
    {
        Some(response) => locomotion::Limits { response, ..*body },
        None => *body,
    };
    let info = locomotion::step(
        &mut motion,
        steer,
        limits,
        &def.body.locomotion,
        world.current,
        dt,
    );
    locomotion::solid::keep_solid(&mut motion.pos, i, me, percepts, world, perception);
    let mut an = me.anim;
    let accel = if dt > 0.0 { info.dspeed / dt } else { 0.0 };
    anim::advance(
        &mut an,
        &def.body.anim,
        motion.speed,
        def.body.size.z,
        accel,
        info.dyaw,
        limits.max_turn,
        dt,
    );

    // Contact intent (resolved in agent order by stage 7).
    out.contact = match b.contact {
        Some(c @ Contact::Eat { reach }) => ctx
            .nearest(Category::Food)
            .filter(|p| p.dist <= reach)
            .map(|p| (c, p.source)),
        Some(c @ Contact::Mate { reach }) => ctx
            .nearest(Category::Mate)
            .filter(|p| p.dist <= reach)
            .map(|p| (c, p.source)),
        None => None,
    };
    let rare = transitions.iter().any(Option::is_some)
        || messages.iter().any(Option::is_some)
        || error.is_some();
    out.rare = rare.then(|| {
        Box::new(Rare {
            transitions,
            messages,
            error,
        })
    });
    out.species = me.species.0;
    out.behavior = mind.current;

    // The agent's new state, in its own record.
    let a = me;
    a.prev_pos = a.pos;
    a.pos = world.bounds.closest_point(motion.pos);
    a.yaw = motion.yaw;
    a.pitch = motion.pitch;
    a.speed = motion.speed;
    a.yaw_rate = motion.yaw_rate;
    a.pitch_rate = motion.pitch_rate;
    a.forward_cache = ForwardCache::new(a.yaw, a.pitch, info.forward);
    a.anim = an;
    a.mind = std::mem::take(mind);
    a.rng = *rng;
}

/// Cause of a forced behavior change (tests and tools).
pub fn force_behavior(
    world: &mut World,
    set: &SpeciesSet,
    id: AgentId,
    behavior: &str,
) -> Option<Event> {
    let i = world.agent_index(id)?;
    let a = &mut world.agents[i];
    let sp = &set.species[a.species.0 as usize];
    let to = sp.behavior_index(behavior)?;
    let from = a.mind.current;
    a.mind.current = to;
    a.mind.entered_tick = world.tick;
    Some(Event::Transition {
        agent: a.id,
        species: a.species.0,
        from,
        to,
        cause: Cause::Script,
        condition: None,
        stack: a.mind.stack().to_vec(),
    })
}
