//! A scenario being run: the world built at t = 0 (obstacles, food, groups numbered in the agent
//! grid's order, squads), then, each tick, the scenario's timed events and food respawn before
//! [`Sim::advance`]. Draws come from the run's seed only, so a run is reproducible bit for bit.

use super::*;
use crate::index::Layout;
use crate::sim::Sim;
use crate::species::Draw;
use crate::tick::Pipeline;
use crate::world::{Aabb, Rng, Shape, World};
use glam::Vec3;

/// Options a run may override.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Overrides {
    /// Seed.
    pub seed: Option<u64>,
    /// Duration (s).
    pub duration: Option<f32>,
    /// Settings of keys of the scenario and its species: they apply when the scenario is read
    /// ([`Scenario::load_with`]), so [`Run::new`] takes them as already applied.
    pub set: Vec<Setting>,
}

/// A scenario being run: world, pipeline and the scenario's own clock of timed events.
pub struct Run {
    /// The scenario.
    pub scenario: Scenario,
    /// The world, pipeline and squads, stepped by [`Run::step`]; a `Run` derefs to it, so
    /// `run.sim.world`, `run.sim.pipeline` and `run.sim.squads` read through.
    pub sim: Sim,
    /// Ticks to run.
    pub total_ticks: u64,
    pub(super) next_event: usize,
    pub(super) food_rng: Rng,
    pub(super) food_debt: f32,
    /// Events the scenario itself made (spawns of its timed groups).
    pub scenario_events: Vec<crate::events::Event>,
    /// The agents each spawned group got, in spawning order (what group expectations count).
    pub group_spans: Vec<GroupSpan>,
}

/// The agents one spawned group got: ids are given in order, so a group's are one range.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GroupSpan {
    /// The group's name ([`SpawnGroupDef::group_name`]).
    pub name: String,
    /// Its agents' ids (`AgentId.0`).
    pub ids: std::ops::Range<u32>,
}

impl std::ops::Deref for Run {
    type Target = Sim;
    fn deref(&self) -> &Sim {
        &self.sim
    }
}

impl std::ops::DerefMut for Run {
    fn deref_mut(&mut self) -> &mut Sim {
        &mut self.sim
    }
}

/// Where and how one agent of a group starts: drawn before the group is numbered.
struct Place {
    pos: Vec3,
    yaw: f32,
    /// Hunger, libido, fear and fatigue, where the group sets them.
    drives: [Option<f32>; 4],
}

fn uniform_in(r: &Aabb, rng: &mut Rng) -> Vec3 {
    Vec3::new(
        rng.range(r.min.x, r.max.x),
        rng.range(r.min.y, r.max.y),
        rng.range(r.min.z, r.max.z),
    )
}

/// Draws a point of `r` that keeps `clearance` from every active obstacle: up to
/// [`PLACE_TRIES`] draws from `rng`, then the last one drawn (a region that has no such room is
/// refused when the scenario loads).
fn free_in(r: &Aabb, rng: &mut Rng, obstacles: &[Shape], clearance: f32) -> Vec3 {
    let mut p = uniform_in(r, rng);
    for _ in 1..PLACE_TRIES {
        if obstacles.iter().all(|o| o.push_out(p, clearance).is_none()) {
            break;
        }
        p = uniform_in(r, rng);
    }
    p
}

/// Draws a spawning place gets before it gives up looking for room outside the obstacles.
pub const PLACE_TRIES: usize = 64;

/// Room kept between food items and obstacles when food is placed.
const FOOD_CLEARANCE: f32 = 0.3;

impl Run {
    /// The active obstacles' shapes (what spawning keeps clear of).
    fn solid_shapes(&self) -> Vec<Shape> {
        self.sim
            .world
            .obstacles
            .iter()
            .filter(|o| o.active)
            .map(|o| o.shape)
            .collect()
    }

    /// Builds the world of `scenario` at t = 0.
    pub fn new(scenario: Scenario, o: Overrides) -> Run {
        let def = &scenario.def;
        let seed = o.seed.unwrap_or(def.seed);
        let mut world = World::new(def.bounds, def.dt, seed);
        world.current = def.current;
        for ob in &def.obstacles {
            world.add_obstacle(ob.shape());
        }
        let duration = o.duration.unwrap_or(def.duration);
        let total_ticks = (duration / def.dt).round().max(0.0) as u64;
        let pipeline = Pipeline::new(scenario.species.clone());
        let mut food_rng = Rng::new(seed, u64::MAX);
        let region = def.food.region.unwrap_or(def.bounds);
        let solid: Vec<Shape> = world.obstacles.iter().map(|o| o.shape).collect();
        for _ in 0..def.food.initial {
            let p = free_in(&region, &mut food_rng, &solid, FOOD_CLEARANCE);
            world.add_food(p);
        }
        let groups = def.groups.clone();
        let mut run = Run {
            scenario,
            sim: Sim::from_parts(world, pipeline, crate::squad::Squads::default()),
            total_ticks,
            next_event: 0,
            food_rng,
            food_debt: 0.0,
            scenario_events: Vec::new(),
            group_spans: Vec::new(),
        };
        // Every group is numbered against the grid of the first tick, which counts them all and
        // the squads' members.
        let layout = run.layout_with(
            groups.iter().map(|g| (g.species.as_str(), g.count)).chain(
                run.scenario
                    .def
                    .squads
                    .iter()
                    .map(|q| (q.species.as_str(), i64::from(q.count))),
            ),
        );
        // Room for every group and squad at once, exactly: each group's own reservation would
        // double the buffer past the first group and keep up to one spare record per agent.
        let total = groups
            .iter()
            .map(|g| g.count.max(0) as usize)
            .chain(run.scenario.def.squads.iter().map(|q| q.count as usize))
            .fold(0usize, usize::saturating_add);
        run.sim.world.agents.reserve_exact(total);
        run.sim.pipeline.events.reserve_exact(total);
        for (k, g) in groups.iter().enumerate() {
            run.spawn_group_in(g, k as u64, &layout);
        }
        // A leader drawn at random comes from the run's seed, not only the scenario's.
        crate::squad::setup::redraw_leaders(
            &run.scenario.def,
            run.scenario.ground.as_deref(),
            &mut run.scenario.squads,
            seed,
        );
        let sim = &mut run.sim;
        sim.squads = crate::squad::Squads::start(
            run.scenario.ground.clone(),
            &run.scenario.squads,
            &mut sim.world,
            &mut sim.pipeline,
        );
        run
    }

    /// Spawns a group; `salt` separates the random streams of different groups. The group's
    /// places, headings and drive overrides are drawn first, in the order the group lists its
    /// agents; the agents are then numbered in the order of the cells of the agent grid the next
    /// tick builds (the world's agents and this group; [`Pipeline::agent_layout`]), so that
    /// agents close in space are close in the world's agent list, and perception and the agent
    /// pass, which walk that list, read the grid's lanes and their own results in step.
    pub fn spawn_group(&mut self, g: &SpawnGroupDef, salt: u64) {
        let layout = self.layout_with([(g.species.as_str(), g.count)]);
        self.spawn_group_in(g, salt, &layout);
    }

    /// The layout of the agent grid once `added` (species name, count) join the world's agents.
    fn layout_with<'a>(&self, added: impl IntoIterator<Item = (&'a str, i64)>) -> Layout {
        let set = &self.scenario.species;
        let mut counts = vec![0u32; set.species.len()];
        self.sim.world.count_species(&mut counts);
        for (name, n) in added {
            if let Some(c) = set.index_of(name).and_then(|s| counts.get_mut(s)) {
                *c = c.saturating_add(n.clamp(0, u32::MAX as i64) as u32);
            }
        }
        self.sim
            .pipeline
            .agent_layout(self.sim.world.bounds, &counts)
    }

    /// [`Run::spawn_group`], numbering the group in the cells of `layout`.
    fn spawn_group_in(&mut self, g: &SpawnGroupDef, salt: u64, layout: &Layout) {
        let Some(s) = self.scenario.species.index_of(&g.species) else {
            return;
        };
        let mut rng = Rng::new(
            self.sim.world.seed ^ 0x5EED_0000,
            salt.wrapping_add(self.sim.world.tick << 16),
        );
        let count = g.count.max(0) as usize;
        // Room for the whole group at once: growing by doubling would leave the outgrown
        // buffers behind in the allocator, about one more agent record per agent.
        self.sim.world.agents.reserve(count);
        self.sim.pipeline.events.reserve(count);
        // Each agent's draws, from the group's stream in the order the group lists them.
        let solid = self.solid_shapes();
        let clearance = self.scenario.species.species[s].body.size.length() * 0.5;
        let place = |rng: &mut Rng| {
            let pos = free_in(&g.region, rng, &solid, clearance);
            let yaw = match g.heading {
                HeadingDef::Random => rng.range(-std::f32::consts::PI, std::f32::consts::PI),
                HeadingDef::Yaw(d) => d.to_radians(),
                HeadingDef::Toward(t) => crate::frame::heading_of(t - pos).map_or(0.0, |h| h.0),
            };
            let mut draw = |v: Option<Draw>| {
                v.map(|v| match v {
                    Draw::Fixed(x) => x,
                    Draw::Uniform(lo, hi) => rng.range(lo, hi),
                })
            };
            let d = &g.drives;
            let drives = [
                draw(d.hunger),
                draw(d.libido),
                draw(d.fear),
                draw(d.fatigue),
            ];
            Place { pos, yaw, drives }
        };
        // The grid cell of each agent's place and the stream's state before its draws (16
        // bytes an agent, where keeping the places would take 48): sorted, the agents are
        // drawn again in cell order. Equal cells fall back on the states (all distinct), so the
        // order is one order whatever the sort.
        let mut order: Vec<u128> = (0..count)
            .map(|_| {
                let state = rng.0;
                let key = layout.cell_of(place(&mut rng).pos);
                u128::from(key) << 64 | u128::from(state)
            })
            .collect();
        order.sort_unstable();
        let first = self.sim.world.next_agent_id;
        self.group_spans.push(GroupSpan {
            name: g.group_name().to_string(),
            ids: first..first.saturating_add(count as u32),
        });
        let params = &self.scenario.species.species[s].drives.params;
        for p in order.into_iter().map(|o| place(&mut Rng(o as u64))) {
            let id = self
                .sim
                .pipeline
                .spawn(&mut self.sim.world, s, p.pos, p.yaw, 0.0);
            let a = self.sim.world.agents.last_mut().expect("just spawned");
            debug_assert_eq!(a.id, id);
            let [hunger, libido, fear, fatigue] = p.drives;
            let dr = &mut a.drives;
            for (v, f) in [
                (hunger, &mut dr.hunger),
                (libido, &mut dr.libido),
                (fear, &mut dr.fear),
                (fatigue, &mut dr.fatigue),
            ] {
                if let Some(v) = v {
                    *f = v;
                }
            }
            if hunger.is_some() {
                (dr.eaten, dr.since_meal) = crate::drives::meal_clock_for(dr.hunger, 0.0, params);
            }
            if hunger.is_some() || libido.is_some() {
                dr.since_mating = crate::drives::since_mating_for(dr.libido, dr.hunger, params);
            }
        }
    }

    /// Whether the run has done all its ticks.
    pub fn finished(&self) -> bool {
        self.sim.world.tick >= self.total_ticks
    }

    /// Applies timed events due now and food respawn, then advances one tick. Events of the
    /// tick (scenario ones first) are in `self.sim.pipeline.events` afterwards.
    pub fn step(&mut self) {
        self.sim.begin_tick();
        let t = self.sim.world.time() as f32;
        let dt = self.sim.world.dt;
        while let Some(ev) = self.scenario.def.events.get(self.next_event) {
            if ev.at > t + dt * 0.5 {
                break;
            }
            let ev = ev.clone();
            self.next_event += 1;
            match ev.action {
                EventAction::Spawn(g) => self.spawn_group(&g, 1000 + self.next_event as u64),
                EventAction::RemoveObstacle(id) => {
                    if let Some(o) = self.sim.world.obstacles.get_mut(id as usize) {
                        o.active = false;
                    }
                }
                EventAction::DropFood { count, region } => {
                    let solid = self.solid_shapes();
                    for _ in 0..count {
                        let p = free_in(&region, &mut self.food_rng, &solid, FOOD_CLEARANCE);
                        self.sim.world.add_food(p);
                    }
                }
                EventAction::SetCurrent(c) => self.sim.world.current = c,
            }
        }
        let f = &self.scenario.def.food;
        if f.respawn_per_second > 0.0 {
            // Whole items due this tick, counted as an integer: subtracting 1 from a huge float
            // does not change it, so a loop on the float could run forever. The fraction carries
            // over; what the world cannot hold is dropped, not owed.
            self.food_debt += f.respawn_per_second * dt;
            let due = self.food_debt.floor();
            self.food_debt -= due;
            if !self.food_debt.is_finite() {
                self.food_debt = 0.0;
            }
            let room = (f.max as usize).saturating_sub(self.sim.world.food.len());
            let add = if due.is_finite() && due >= 0.0 {
                (due as usize).min(room)
            } else {
                room
            };
            if add > 0 {
                let region = f.region.unwrap_or(self.sim.world.bounds);
                let solid = self.solid_shapes();
                for _ in 0..add {
                    let p = free_in(&region, &mut self.food_rng, &solid, FOOD_CLEARANCE);
                    self.sim.world.add_food(p);
                }
            }
        }
        self.sim.advance();
    }

    /// Agents alive per species, in species order.
    pub fn alive(&self) -> Vec<(String, usize)> {
        let mut counts = vec![0usize; self.scenario.species.species.len()];
        for a in &self.sim.world.agents {
            counts[a.species.0 as usize] += 1;
        }
        self.scenario
            .species
            .species
            .iter()
            .zip(counts)
            .map(|(s, c)| (s.name.clone(), c))
            .collect()
    }

    /// The run summary as JSON, as `shoal run` stores it in the manifest and the Python package
    /// returns it: counters, each species' behavior shares (per behavior, to 0.001) and
    /// `ticks_per_second` over `elapsed` seconds (the only figure that is not a pure function of
    /// the inputs).
    pub fn summary(&self, elapsed: f64) -> serde_json::Value {
        let s = &self.pipeline.stats;
        let mut shares = serde_json::Map::new();
        for (i, sp) in self.scenario.species.species.iter().enumerate() {
            let row = &s.behavior_ticks[i];
            let total: u64 = row.iter().sum();
            let mut m = serde_json::Map::new();
            for (b, n) in sp.behaviors.iter().zip(row) {
                let share = if total > 0 {
                    *n as f64 / total as f64
                } else {
                    0.0
                };
                m.insert(
                    b.name.to_string(),
                    serde_json::json!((share * 1000.0).round() / 1000.0),
                );
            }
            shares.insert(sp.name.clone(), serde_json::Value::Object(m));
        }
        let alive: serde_json::Map<String, serde_json::Value> = self
            .alive()
            .into_iter()
            .map(|(k, v)| (k, serde_json::json!(v)))
            .collect();
        serde_json::json!({
            "ticks": self.world.tick,
            "alive": alive,
            "food_eaten": s.meals,
            "catches": s.catches,
            "matings": s.matings,
            "transitions": s.transitions,
            "script_errors": s.script_errors,
            "behavior_shares": shares,
            "ticks_per_second": (self.world.tick as f64 / elapsed.max(1e-9)).round(),
        })
    }
}
