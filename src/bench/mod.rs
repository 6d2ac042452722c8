//! Benchmark workloads: a layer above the core (not a tick stage) that builds the standard worlds
//! `cargo bench` and `shoal bench` measure, each scaled to N agents at a fixed density so that
//! cost per agent can be compared across sizes, and times them.
//!
//! - `boids`: classic flocking (separation, alignment, cohesion; seed 001) in a flat world at the
//!   density peers publish (0.1 agent per unit², vision radius 10: 1,000 agents on 100×100);
//! - `flock`: the engine-core figure: 3D flocking under static-obstacle avoidance (seed 000 §4.1)
//!   with a perception radius that gives ~20 neighbors;
//! - `reef` / `reef-native`: the reef fish and shark species of `behaviors/` (seed 000's nine
//!   behaviors), with their scripts, or with every `Script(..)` condition replaced by a native one;
//! - `decide`: the decision stage alone (scripts bound to the typed agent view, then arbitration);
//! - `perceive`: stages 1–2 alone (spatial index and perception);
//! - `plan` / `plan-weighted`: formation path planning (seed 004), exact or with a heuristic
//!   weight, see [`plan`];
//! - `reference`: the `boids` world as a minimal hand-written program ([`reference`]), the floor
//!   every `boids` row is compared with.

pub mod plan;
pub mod reference;

use crate::decision::{self, scripts, Ctx};
use crate::diag::Diagnostics;
use crate::perception::Category;
use crate::scenario::{
    FoodDef, HeadingDef, ObstacleDef, Overrides, RecordDef, Run, Scenario, ScenarioDef,
    SpawnGroupDef,
};
use crate::species::{load_species, load_species_str, SpeciesSet};
use crate::world::{Aabb, Mind, Rng};
use glam::Vec3;
use rayon::prelude::*;
use rhai::{Dynamic, ImmutableString, Scope};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// The boid species of the `boids` workload.
pub const BOID_RON: &str = include_str!("boid.ron");
/// The flocking species of the `flock` workload.
pub const FLOCKER_RON: &str = include_str!("flocker.ron");

/// Agents per unit² of the `boids` workload (Mesa's BoidFlockers example: 1,000 on 100×100).
pub const BOIDS_DENSITY: f32 = 0.1;
/// Agents per unit³ of the `flock` workload: ~20 within its vision radius of 5.
pub const FLOCK_DENSITY: f32 = 0.038;
/// Obstacles per unit³ of the `flock` workload.
pub const FLOCK_ROCKS: f32 = 1.0 / 4000.0;
/// Depth (y extent) of the `reef` world.
pub const REEF_DEPTH: f32 = 20.0;
/// Fish per unit³ of the `reef` world.
pub const REEF_DENSITY: f32 = 1.0 / 1000.0;
/// Fish per shark in the `reef` world.
pub const REEF_FISH_PER_SHARK: usize = 500;
/// Fish per food item (initial and maximum) in the `reef` world.
pub const REEF_FISH_PER_FOOD: usize = 10;
/// Fish per rock in the `reef` world.
pub const REEF_FISH_PER_ROCK: usize = 200;
/// Time step of every workload.
pub const DT: f32 = 0.05;
/// Seed of every workload.
pub const SEED: u64 = 7;

/// A standard workload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Workload {
    /// Classic flocking at the peers' 2D density.
    Boids,
    /// 3D flocking with obstacle avoidance, ~20 neighbors.
    Flock,
    /// Reef fish and sharks with their scripts.
    Reef,
    /// The same world with every script condition replaced by a native one.
    ReefNative,
    /// The decision stage alone, with a script call per agent.
    Decide,
    /// The decision stage alone, native conditions only.
    DecideNative,
    /// Spatial index and perception alone.
    Perceive,
    /// Formation path planning on a 1024² terrain.
    Plan,
    /// The `boids` world as a minimal hand-written program: the floor boids is read against.
    Reference,
    /// The same plan with the weighted search ([`crate::formation::astar::SEARCH_WEIGHT_FAST`]).
    PlanWeighted,
}

impl Workload {
    /// Every workload, in the order `shoal bench` runs them.
    pub const ALL: [Workload; 10] = [
        Workload::Boids,
        Workload::Reference,
        Workload::Flock,
        Workload::Reef,
        Workload::ReefNative,
        Workload::Decide,
        Workload::DecideNative,
        Workload::Perceive,
        Workload::Plan,
        Workload::PlanWeighted,
    ];

    /// Name on the command line and in tables.
    pub fn name(self) -> &'static str {
        match self {
            Workload::Boids => "boids",
            Workload::Flock => "flock",
            Workload::Reef => "reef",
            Workload::ReefNative => "reef-native",
            Workload::Decide => "decide",
            Workload::DecideNative => "decide-native",
            Workload::Perceive => "perceive",
            Workload::Plan => "plan",
            Workload::Reference => "reference",
            Workload::PlanWeighted => "plan-weighted",
        }
    }

    /// The workload named `s`.
    pub fn parse(s: &str) -> Option<Workload> {
        Self::ALL.into_iter().find(|w| w.name() == s)
    }

    /// Agent counts measured when none are given.
    pub fn default_agents(self) -> &'static [usize] {
        match self {
            Workload::Boids | Workload::Flock | Workload::Reference => &[1_000, 10_000, 100_000],
            Workload::Reef | Workload::ReefNative => &[1_000, 10_000, 50_000],
            Workload::Decide | Workload::DecideNative | Workload::Perceive => &[10_000],
            Workload::Plan | Workload::PlanWeighted => &[1],
        }
    }

    /// Ticks measured for `n` agents when none are given: about two million agent-updates,
    /// between 20 and 500 ticks.
    pub fn default_ticks(self, n: usize) -> u64 {
        (2_000_000 / n.max(1) as u64).clamp(20, 500)
    }
}

/// A world ready to be stepped: a scenario run built in code.
pub struct BenchWorld {
    /// The run (world, pipeline, scenario clock).
    pub run: Run,
    /// Notes about how the world was built (e.g. script conditions replaced).
    pub notes: Vec<String>,
}

/// What one measurement found.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Workload name.
    pub workload: String,
    /// Agents at the start.
    pub agents: usize,
    /// Ticks (or passes over every agent) timed.
    pub ticks: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Agent-updates done (sum over ticks of the agents alive).
    pub updates: u64,
    /// Mean number of kin each agent perceived at the end.
    pub neighbors: f32,
    /// Peak resident memory while running, above what the process held before the world was
    /// built, per agent (bytes), where measured (Linux).
    pub bytes_per_agent: Option<f64>,
    /// Wall time by stage over the timed ticks (the tick workloads and `perceive`).
    pub stages: Option<crate::tick::StageTimes>,
    /// What the row measured besides speed, printed under it (the weighted plan's excess).
    pub note: Option<String>,
    /// Ticks per second over the first and the last tenth of the timed ticks (tick workloads
    /// timed over at least [`STEADY_MIN_TICKS`] ticks): whether a long run slows down.
    pub steady: Option<(f64, f64)>,
}

/// Fewest timed ticks for which [`Sample::steady`] is given (a tenth of them is then at least
/// 10 ticks).
pub const STEADY_MIN_TICKS: u64 = 100;

impl Sample {
    /// Ticks per second.
    pub fn ticks_per_s(&self) -> f64 {
        self.ticks as f64 / self.seconds.max(1e-12)
    }
    /// Agent-updates per second.
    pub fn updates_per_s(&self) -> f64 {
        self.updates as f64 / self.seconds.max(1e-12)
    }
    /// Milliseconds per tick.
    pub fn ms_per_tick(&self) -> f64 {
        1e3 * self.seconds / self.ticks.max(1) as f64
    }
}

fn scenario_def(bounds: Aabb, species: Vec<String>) -> ScenarioDef {
    ScenarioDef {
        name: None,
        seed: SEED,
        dt: DT,
        duration: 1e6,
        bounds,
        current: Vec3::ZERO,
        behaviors: None,
        species,
        obstacles: Vec::new(),
        food: FoodDef::default(),
        groups: Vec::new(),
        events: Vec::new(),
        record: RecordDef::default(),
        expect: Vec::new(),
        terrain: None,
        squads: Vec::new(),
    }
}

fn group(species: &str, count: usize, region: Aabb) -> SpawnGroupDef {
    SpawnGroupDef {
        species: species.into(),
        name: None,
        count: count as i64,
        region,
        heading: HeadingDef::Random,
        drives: Default::default(),
    }
}

fn built(name: &str, def: ScenarioDef, behaviors_dir: PathBuf, species: SpeciesSet) -> BenchWorld {
    let scenario = Scenario {
        name: name.into(),
        file: behaviors_dir.join(format!("bench_{name}.ron")),
        text: String::new(),
        def,
        behaviors_dir,
        species: Arc::new(species),
        ground: None,
        squads: Vec::new(),
        settings: Vec::new(),
        patched: Default::default(),
    };
    BenchWorld {
        run: Run::new(scenario, Overrides::default()),
        notes: Vec::new(),
    }
}

fn embedded(file: &str, text: &str) -> SpeciesSet {
    let path = Path::new("bench").join(file);
    let s = load_species_str(
        &path,
        text,
        Path::new("bench"),
        &crate::scenario::script_limits(),
    )
    .unwrap_or_else(|d| panic!("embedded species {file} is invalid: {d}"));
    SpeciesSet::new(vec![Arc::new(s)]).unwrap_or_else(|d| panic!("{d}"))
}

/// The `boids` world: `n` boids in a flat square of `n / 0.1` units² (all at y = 0, so every
/// neighbor query is the 2D one), random positions and headings.
pub fn boids(n: usize) -> BenchWorld {
    let side = (n as f32 / BOIDS_DENSITY).sqrt().max(10.0);
    let bounds = Aabb::new(Vec3::new(0.0, -5.0, 0.0), Vec3::new(side, 5.0, side));
    let mut def = scenario_def(bounds, vec!["boid".into()]);
    def.groups.push(group(
        "boid",
        n,
        Aabb::new(Vec3::ZERO, Vec3::new(side, 0.0, side)),
    ));
    built("boids", def, "bench".into(), embedded("boid.ron", BOID_RON))
}

/// Side of the `boids` world for `n` agents (for the peer comparison).
pub fn boids_side(n: usize) -> f32 {
    (n as f32 / BOIDS_DENSITY).sqrt().max(10.0)
}

/// The `flock` world: `n` flocking fish in a cube at ~20 neighbors each, with spherical rocks.
pub fn flock(n: usize) -> BenchWorld {
    let volume = n as f32 / FLOCK_DENSITY;
    let side = crate::math::cbrt(volume).max(10.0);
    let bounds = Aabb::new(Vec3::ZERO, Vec3::splat(side));
    let mut def = scenario_def(bounds, vec!["flocker".into()]);
    let mut rng = Rng::new(SEED, 0xB0C5);
    let rocks = (volume * FLOCK_ROCKS).round() as usize;
    for _ in 0..rocks {
        def.obstacles.push(ObstacleDef::Sphere {
            center: Vec3::new(
                rng.range(0.0, side),
                rng.range(0.0, side),
                rng.range(0.0, side),
            ),
            radius: rng.range(1.0, 2.5),
        });
    }
    def.groups.push(group("flocker", n, bounds));
    built(
        "flock",
        def,
        "bench".into(),
        embedded("flocker.ron", FLOCKER_RON),
    )
}

/// Native conditions standing for the reef fish's script conditions in the `reef-native` world,
/// by function name: the same test written in the species format, as far as it can be.
/// `crowded()` is "more than 8 kin seen, the nearest closer than 0.5 and not hungry"; the
/// native form reads kin perceived for kin seen.
pub const NATIVE_EQUIVALENTS: &[(&str, &str)] = &[(
    "crowded",
    "All([Above(Count(Kin), 8), Below(Distance(Kin), 0.5), Below(Drive(Hunger), 0.5)])",
)];

/// The species text with its script removed and every `Script("f")` replaced by its native
/// equivalent (`Never` when none is known, noted in `notes`).
pub fn without_scripts(text: &str, notes: &mut Vec<String>) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("Script(\"") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 8..];
        let Some(end) = after.find("\")") else {
            out.push_str(&rest[at..]);
            rest = "";
            break;
        };
        let name = &after[..end];
        match NATIVE_EQUIVALENTS.iter().find(|(n, _)| *n == name) {
            Some((_, native)) => out.push_str(native),
            None => {
                notes.push(format!(
                    "no native equivalent of `{name}()`: replaced by Never"
                ));
                out.push_str("Never");
            }
        }
        rest = &after[end + 2..];
    }
    out.push_str(rest);
    out.lines()
        .filter(|l| !l.trim_start().starts_with("script:"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The `reef` world: `n` reef fish (and one shark per 500) from `behaviors_dir` in a layer
/// [`REEF_DEPTH`] deep at [`REEF_DENSITY`], with food (one item per 10 fish, respawning) and
/// rocks. With `scripted == false` the fish's script conditions are replaced by native ones.
pub fn reef(n: usize, behaviors_dir: &Path, scripted: bool) -> Result<BenchWorld, Diagnostics> {
    let area = n as f32 / REEF_DENSITY / REEF_DEPTH;
    let side = area.sqrt().max(30.0);
    let bounds = Aabb::new(Vec3::ZERO, Vec3::new(side, REEF_DEPTH, side));
    let limits = crate::scenario::script_limits();
    let fish_file = behaviors_dir.join("reef_fish.ron");
    let shark_file = behaviors_dir.join("shark.ron");
    let mut notes = Vec::new();
    let fish = if scripted {
        load_species(&fish_file, behaviors_dir, &limits)?
    } else {
        let text = std::fs::read_to_string(&fish_file).map_err(|e| {
            crate::diag::Diagnostic::file(&fish_file, format!("cannot read species file: {e}"))
        })?;
        let native = without_scripts(&text, &mut notes);
        load_species_str(&fish_file, &native, behaviors_dir, &limits)?
    };
    let shark = load_species(&shark_file, behaviors_dir, &limits)?;
    // Relations may name species that are not in this world (or not in this tree).
    let set = SpeciesSet::with_library(vec![Arc::new(fish), Arc::new(shark)], |_| true)?;
    let mut def = scenario_def(bounds, vec!["reef_fish".into(), "shark".into()]);
    let mut rng = Rng::new(SEED, 0x2EEF);
    for _ in 0..(n / REEF_FISH_PER_ROCK).max(1) {
        def.obstacles.push(ObstacleDef::Sphere {
            center: Vec3::new(rng.range(0.0, side), 0.0, rng.range(0.0, side)),
            radius: rng.range(2.0, 5.0),
        });
    }
    let food = (n / REEF_FISH_PER_FOOD).max(1) as u32;
    def.food = FoodDef {
        initial: food,
        region: Some(Aabb::new(
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(side, REEF_DEPTH - 1.0, side),
        )),
        respawn_per_second: food as f32 / 20.0,
        max: food,
    };
    let inner = Aabb::new(
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(side - 1.0, REEF_DEPTH - 1.0, side - 1.0),
    );
    def.groups.push(group("reef_fish", n, inner));
    def.groups
        .push(group("shark", (n / REEF_FISH_PER_SHARK).max(1), inner));
    let mut w = built(
        if scripted { "reef" } else { "reef_native" },
        def,
        behaviors_dir.to_path_buf(),
        set,
    );
    w.notes = notes;
    Ok(w)
}

/// The behaviors folder of this source tree.
pub fn default_behaviors_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors")
}

/// Resets the peak resident set size of this process (Linux; `false` elsewhere).
pub fn reset_peak_memory() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// (Resident, peak resident) memory of this process in bytes (Linux).
pub fn memory() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = s.lines().find(|l| l.starts_with(name))?;
        let kb: u64 = line[name.len()..]
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()?;
        Some(kb * 1024)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// Mean number of kin perceived per agent in the last tick.
pub fn mean_neighbors(w: &BenchWorld) -> f32 {
    let p = w.run.sim.pipeline.perception();
    if p.is_empty() {
        return 0.0;
    }
    let total: u64 = (0..p.len())
        .map(|i| p.summaries(i)[Category::Kin as usize].count as u64)
        .sum();
    total as f32 / p.len() as f32
}

/// The sample of median speed (agent-updates per second) among `samples`: the lower middle
/// one for an even count; `None` when there are none.
pub fn median_sample(mut samples: Vec<Sample>) -> Option<Sample> {
    if samples.is_empty() {
        return None;
    }
    samples.sort_by(|a, b| a.updates_per_s().total_cmp(&b.updates_per_s()));
    let middle = (samples.len() - 1) / 2;
    Some(samples.swap_remove(middle))
}

/// Steps `w` `ticks` times; returns (seconds, agent-updates, the ticks per second of the
/// first and of the last tenth of the ticks when there are at least [`STEADY_MIN_TICKS`]).
#[inline(never)]
pub fn step_timed(w: &mut BenchWorld, ticks: u64) -> (f64, u64, Option<(f64, f64)>) {
    let tenth = ticks / 10;
    let (first_end, last_start) = (tenth, ticks - tenth);
    let mut updates = 0;
    let t0 = Instant::now();
    let (mut first, mut last) = (t0, t0);
    for t in 0..ticks {
        if t == first_end {
            first = Instant::now();
        }
        if t == last_start {
            last = Instant::now();
        }
        updates += w.run.sim.world.agents.len() as u64;
        w.run.step();
    }
    let end = Instant::now();
    let rate = |from: Instant, to: Instant| tenth as f64 / (to - from).as_secs_f64().max(1e-12);
    let steady = (ticks >= STEADY_MIN_TICKS).then(|| (rate(t0, first), rate(last, end)));
    ((end - t0).as_secs_f64(), updates, steady)
}

/// Ticks run before timing starts, so buffers are warm and the world has left its spawn state.
pub const WARMUP_TICKS: u64 = 10;

/// Steps `w` `ticks` times, untimed.
pub fn warm_up(w: &mut BenchWorld, ticks: u64) {
    for _ in 0..ticks {
        w.run.step();
    }
}

/// Builds the world of a tick workload (`boids`, `flock`, `reef`, `reef-native`).
pub fn world_of(
    workload: Workload,
    n: usize,
    behaviors_dir: &Path,
) -> Result<BenchWorld, Diagnostics> {
    match workload {
        Workload::Boids => Ok(boids(n)),
        Workload::Flock => Ok(flock(n)),
        Workload::Reef | Workload::Perceive | Workload::Decide | Workload::DecideNative => {
            reef(n, behaviors_dir, true)
        }
        Workload::ReefNative => reef(n, behaviors_dir, false),
        Workload::Plan | Workload::PlanWeighted | Workload::Reference => Ok(boids(0)),
    }
}

/// Measures `workload` at `n` agents over `ticks` ticks (passes, for the stage workloads), on
/// the current rayon pool. `None` for `plan` when its map has no path (see [`plan::measure`]).
pub fn measure(
    workload: Workload,
    n: usize,
    ticks: u64,
    behaviors_dir: &Path,
) -> Result<Option<Sample>, Diagnostics> {
    match workload {
        Workload::Plan => return Ok(plan::measure(ticks, 1.0)),
        Workload::PlanWeighted => {
            return Ok(plan::measure(
                ticks,
                crate::formation::astar::SEARCH_WEIGHT_FAST,
            ))
        }
        Workload::Reference => return Ok(Some(reference::measure(n, ticks))),
        _ => {}
    }
    let base = memory().map(|m| m.0);
    let mut w = world_of(workload, n, behaviors_dir)?;
    let agents = w.run.sim.world.agents.len();
    warm_up(&mut w, WARMUP_TICKS);
    // Peak while running: construction transients (spawning) are not counted, what the world
    // keeps resident is.
    let tracked = reset_peak_memory();
    w.run.sim.pipeline.reset_stage_times();
    let untracked = |(seconds, updates)| (seconds, updates, None);
    let (seconds, updates, steady) = match workload {
        Workload::Perceive => untracked(perceive_timed(&mut w, ticks)),
        Workload::Decide => untracked(decide_timed(&w, ticks, true)),
        Workload::DecideNative => untracked(decide_timed(&w, ticks, false)),
        _ => step_timed(&mut w, ticks),
    };
    let bytes_per_agent = match (tracked, base, memory()) {
        (true, Some(b), Some((_, peak))) if agents > 0 => {
            Some(peak.saturating_sub(b) as f64 / agents as f64)
        }
        _ => None,
    };
    Ok(Some(Sample {
        workload: workload.name().into(),
        agents,
        ticks,
        seconds,
        updates,
        neighbors: mean_neighbors(&w),
        bytes_per_agent,
        stages: match workload {
            Workload::Decide | Workload::DecideNative => None,
            _ => Some(w.run.sim.pipeline.stage_times()),
        },
        // Every boids figure is read against the minimal program doing the same work.
        note: (workload == Workload::Boids).then(|| {
            let floor = reference::measure(n, ticks);
            format!(
                "reference kernel (same world, minimal program): {:.0} ticks/s, {:.2} M agent-upd/s, \
                 {:.1} kin each; boids runs at {:.2}× its speed",
                floor.ticks_per_s(),
                floor.updates_per_s() / 1e6,
                floor.neighbors,
                (updates as f64 / seconds.max(1e-12)) / floor.updates_per_s().max(1e-12)
            )
        }),
        steady,
    }))
}

/// Runs stages 1–2 (spatial index, perception) `ticks` times on the current world.
#[inline(never)]
pub fn perceive_timed(w: &mut BenchWorld, ticks: u64) -> (f64, u64) {
    let n = w.run.sim.world.agents.len() as u64;
    let t0 = Instant::now();
    for _ in 0..ticks {
        w.run.sim.pipeline.perceive(&w.run.sim.world);
    }
    (t0.elapsed().as_secs_f64(), n * ticks)
}

/// Runs the decision stage alone for every agent `passes` times, as if every agent were due:
/// with `scripted`, the species' script functions are called with the agent's view bound as
/// `this` (the view is refilled in place, not rebuilt), then conditions are arbitrated natively.
/// Minds are copies, so the world does not change between passes.
#[inline(never)]
pub fn decide_timed(w: &BenchWorld, passes: u64, scripted: bool) -> (f64, u64) {
    let world = &w.run.sim.world;
    let pipeline = &w.run.sim.pipeline;
    let set = pipeline.species.clone();
    let perception = pipeline.perception();
    let n = world.agents.len().min(perception.len());
    let names: Vec<(ImmutableString, Vec<ImmutableString>)> = set
        .species
        .iter()
        .map(|s| {
            (
                s.name.as_str().into(),
                s.behaviors.iter().map(|b| (&*b.name).into()).collect(),
            )
        })
        .collect();
    let t0 = Instant::now();
    for _ in 0..passes {
        (0..n).into_par_iter().with_min_len(32).for_each_init(
            || {
                (
                    Scope::new(),
                    Mind::new(0, 0),
                    Dynamic::from(crate::script::AgentView::default()),
                    crate::perception::PerceptBuf::default(),
                )
            },
            |(scope, mind, this, percepts), i| {
                let a = &world.agents[i];
                let sp = &set.species[a.species.0 as usize];
                let summaries = perception.summaries(i);
                let percepts = perception.percepts_in(i, percepts);
                let ctx = Ctx {
                    world,
                    perception,
                    species: sp,
                    agent: a,
                    percepts,
                    summaries: &summaries,
                    // Decisions read no group sums.
                    group_queries: &crate::perception::GroupQueries::EMPTY,
                    group_sums: &[],
                    tick: world.tick,
                    dt: world.dt,
                };
                mind.clone_from(&a.mind);
                let mut rng = a.rng;
                if let (true, Some(script)) = (scripted, sp.script.as_deref()) {
                    if !sp.slots.is_empty() || sp.has_on_tick {
                        let (sname, bnames) = &names[a.species.0 as usize];
                        if let Some(mut v) = this.write_lock::<crate::script::AgentView>() {
                            let behavior = &bnames[mind.current as usize];
                            scripts::fill_for_slots(&mut v, &ctx, mind, sname, behavior);
                        }
                        let _ = scripts::run_slots(sp, script, mind, this, scope);
                    }
                }
                std::hint::black_box(decision::arbitrate(&ctx, mind, &mut rng));
            },
        );
    }
    (t0.elapsed().as_secs_f64(), n as u64 * passes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn behaviors() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors")
    }

    fn sample(seconds: f64) -> Sample {
        Sample {
            workload: "boids".into(),
            agents: 10,
            ticks: 5,
            seconds,
            updates: 50,
            neighbors: 0.0,
            bytes_per_agent: None,
            stages: None,
            note: None,
            steady: None,
        }
    }

    #[test]
    fn the_median_sample_is_the_middle_speed() {
        assert_eq!(median_sample(Vec::new()), None);
        let m = median_sample(vec![sample(2.0), sample(1.0), sample(4.0)]).unwrap();
        assert_eq!(m.seconds, 2.0);
        // An even count gives the lower middle speed (the slower of the two middle runs).
        let m = median_sample(vec![sample(1.0), sample(3.0), sample(2.0), sample(4.0)]).unwrap();
        assert_eq!(m.seconds, 3.0);
    }

    #[test]
    fn every_tick_workload_builds_and_steps() {
        for w in [
            Workload::Boids,
            Workload::Flock,
            Workload::Reef,
            Workload::ReefNative,
        ] {
            let mut b = world_of(w, 300, &behaviors()).unwrap_or_else(|d| panic!("{w:?}: {d}"));
            let n = b.run.sim.world.agents.len();
            assert!(n >= 300, "{w:?}: {n} agents");
            for _ in 0..3 {
                b.run.step();
            }
            assert!(
                b.run.sim.world.agents.iter().all(|a| a.pos.is_finite()),
                "{w:?}"
            );
        }
    }

    #[test]
    fn stage_times_count_the_timed_ticks_within_their_wall_time() {
        let s = measure(Workload::Boids, 300, 4, &behaviors())
            .unwrap()
            .unwrap();
        let t = s.stages.expect("a tick workload times its stages");
        assert_eq!(t.ticks, 4, "the warm-up ticks are not counted");
        let staged = (t.index + t.perception + t.agents + t.events).as_secs_f64();
        assert!(staged <= s.seconds, "{t:?} within {}", s.seconds);
        // (That they cover most of it is checked on a whole run, in `tests/scenarios_e2e.rs`:
        // over four short ticks one preemption between two stages could outweigh them.)
        let parts = [t.index, t.perception, t.agents, t.events];
        assert!(parts.iter().all(|d| !d.is_zero()), "{t:?}");
        // Stages 1–2 alone: nothing is counted for the others.
        let p = measure(Workload::Perceive, 300, 3, &behaviors())
            .unwrap()
            .unwrap();
        let t = p.stages.expect("perceive times its stages");
        assert_eq!(
            (t.ticks, t.agents, t.events),
            (3, std::time::Duration::ZERO, std::time::Duration::ZERO)
        );
        assert!(!t.perception.is_zero(), "{t:?}");
        let names: Vec<&str> = t.ms_per_tick().iter().map(|(n, _)| *n).collect();
        assert_eq!(names, ["index", "perception", "agents", "events"]);
        let decide = measure(Workload::Decide, 300, 1, &behaviors())
            .unwrap()
            .unwrap();
        assert_eq!(decide.stages, None, "the decision stage is timed whole");
    }

    #[test]
    fn reef_native_has_a_native_form_of_every_script_condition() {
        let b = reef(300, &behaviors(), false).unwrap_or_else(|d| panic!("{d}"));
        assert!(
            b.notes.iter().all(|n| !n.contains("no native equivalent")),
            "{:?}",
            b.notes
        );
        let set = &b.run.sim.pipeline.species;
        assert!(set.species.iter().all(|s| s.script.is_none()));
    }
}
