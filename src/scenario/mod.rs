//! Scenarios: RON files naming the world, its species, its agents and timed events, loaded and
//! validated once, and a [`Run`] that drives the tick pipeline through them. This layer reads
//! files; the core below it does not.

pub mod def;
pub mod expect;
mod reload;

pub use def::*;
pub use reload::ScenarioReload;

use crate::diag::{Diagnostic, Diagnostics};
use crate::index::Layout;
use crate::sim::Sim;
use crate::species::validate::{locate, ron_diag, ron_options};
use crate::species::{load_species, Draw, Species, SpeciesSet};
use crate::terrain::dem::MAX_DIAGNOSTICS;
use crate::tick::Pipeline;
use crate::world::{Aabb, Rng, Shape, World};
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A scenario read and validated, with its species loaded.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Name (file stem unless given).
    pub name: String,
    /// The scenario file.
    pub file: PathBuf,
    /// Its text.
    pub text: String,
    /// The definition.
    pub def: ScenarioDef,
    /// The behaviors folder species were loaded from.
    pub behaviors_dir: PathBuf,
    /// The species, in the order the scenario lists them.
    pub species: Arc<SpeciesSet>,
    /// The terrain and each walking species' cost grid, when the scenario has terrain.
    pub ground: Option<Arc<crate::squad::Ground>>,
    /// The squads, checked and planned.
    pub squads: Vec<crate::squad::SquadSetup>,
}

/// Removes `.` and `a/..` components without touching the file system, so that diagnostics
/// name files the way a user would.
pub fn normalize(p: &Path) -> PathBuf {
    use std::path::Component;
    let mut out: Vec<Component> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    if out.is_empty() {
        PathBuf::from(".")
    } else {
        out.iter().collect()
    }
}

/// Script limits used for every load.
pub fn script_limits() -> crate::script::Limits {
    crate::script::Limits::default()
}

fn check_region(
    diags: &mut Vec<Diagnostic>,
    file: &Path,
    text: &str,
    bounds: &Aabb,
    region: &Aabb,
    what: &str,
    from: usize,
) {
    if !bounds.contains_box(region) || region.min.cmpgt(region.max).any() {
        let (l, c, _) = locate(text, "region", from).unwrap_or((0, 0, 0));
        diags.push(Diagnostic::new(
            file,
            l,
            c,
            format!(
                "{what}: spawn region {:?}..{:?} is outside the world bounds {:?}..{:?}",
                region.min.to_array(),
                region.max.to_array(),
                bounds.min.to_array(),
                bounds.max.to_array()
            ),
            Some(text),
        ));
    }
}

/// The scenario's numbers outside what `load_str` checks by name: finite coordinates, obstacle
/// shapes, food, counts within [`MAX_AGENTS`](crate::numbers::MAX_AGENTS), event times, squads.
fn scenario_numbers(file: &Path, text: &str, def: &ScenarioDef) -> Vec<Diagnostic> {
    use crate::numbers::{MAX_AGENTS, MAX_COORD, MAX_FOOD};
    let mut n = crate::numbers::NumberCheck::new(file, text);
    let aabb = |n: &mut crate::numbers::NumberCheck, key: &str, b: &Aabb| {
        n.enter(key);
        n.point("min", &b.min.to_array()) & n.point("max", &b.max.to_array())
    };
    aabb(&mut n, "bounds", &def.bounds);
    n.from = 0;
    n.point("current", &def.current.to_array());
    n.from = 0;
    n.enter("obstacles");
    for o in &def.obstacles {
        match *o {
            ObstacleDef::Sphere { center, radius } => {
                n.enter("Sphere");
                n.point("center", &center.to_array());
                n.range("radius", radius, 0.0, MAX_COORD);
            }
            ObstacleDef::Box { min, max } => {
                n.enter("Box");
                if n.point("min", &min.to_array()) & n.point("max", &max.to_array())
                    && min.cmpgt(max).any()
                {
                    n.error(
                        "min",
                        format!(
                            "`Box`: `min` {:?} must not exceed `max` {:?} on any axis",
                            min.to_array(),
                            max.to_array()
                        ),
                    );
                }
            }
            ObstacleDef::Cylinder {
                base,
                radius,
                height,
            } => {
                n.enter("Cylinder");
                n.point("base", &base.to_array());
                n.range("radius", radius, 0.0, MAX_COORD);
                n.range("height", height, 0.0, MAX_COORD);
            }
        }
    }
    // Food: the respawn loop adds whole items per tick, so the rate is bounded by what the
    // world may hold.
    n.from = 0;
    n.enter("food");
    let f = &def.food;
    n.range(
        "respawn_per_second",
        f.respawn_per_second,
        0.0,
        MAX_FOOD as f32,
    );
    n.count(
        "initial",
        u64::from(f.initial),
        MAX_FOOD,
        "food items a scenario places",
    );
    n.count(
        "max",
        u64::from(f.max),
        MAX_FOOD,
        "food items a world holds",
    );
    if let Some(r) = &f.region {
        aabb(&mut n, "region", r);
    }
    // Agents: every group, timed spawn and squad together.
    let mut total: u64 = 0;
    let group = |n: &mut crate::numbers::NumberCheck, g: &GroupDef, total: &mut u64| {
        n.enter("count");
        let count = u64::try_from(g.count).unwrap_or(0);
        *total = total.saturating_add(count);
        if !n.count(
            "count",
            count,
            MAX_AGENTS,
            "agents a scenario creates in all",
        ) {
            return;
        }
        if *total > MAX_AGENTS {
            n.error(
                "count",
                format!("the groups so far create {total} agents: a scenario creates at most {MAX_AGENTS} agents in all"),
            );
        }
        aabb(n, "region", &g.region);
        match g.heading {
            HeadingDef::Yaw(y) => {
                n.finite("Yaw", y);
            }
            HeadingDef::Toward(t) => {
                n.point("Toward", &t.to_array());
            }
            HeadingDef::Random => {}
        }
        let d = &g.drives;
        for (key, v) in [
            ("hunger", d.hunger),
            ("libido", d.libido),
            ("fear", d.fear),
            ("fatigue", d.fatigue),
        ] {
            match v {
                Some(Draw::Fixed(x)) => {
                    n.finite(key, x);
                }
                Some(Draw::Uniform(lo, hi)) if n.finite(key, lo) & n.finite(key, hi) && lo > hi => {
                    n.error(key, format!("`{key}`: `Uniform(lo, hi)` needs lo ≤ hi"));
                }
                _ => {}
            }
        }
    };
    n.from = 0;
    n.enter("groups");
    for g in &def.groups {
        group(&mut n, g, &mut total);
    }
    n.from = 0;
    n.enter("events");
    for e in &def.events {
        n.enter("at");
        n.non_negative("at", e.at);
        match &e.action {
            EventAction::Spawn(g) => group(&mut n, g, &mut total),
            EventAction::DropFood { count, region } => {
                n.enter("DropFood");
                n.count(
                    "count",
                    u64::from(*count),
                    MAX_FOOD,
                    "food items a scenario places",
                );
                aabb(&mut n, "region", region);
            }
            EventAction::SetCurrent(c) => {
                n.enter("SetCurrent");
                n.point("SetCurrent", &c.to_array());
            }
            EventAction::RemoveObstacle(_) => {}
        }
    }
    n.from = 0;
    n.enter("squads");
    for q in &def.squads {
        n.enter("count");
        total = total.saturating_add(u64::from(q.count));
        if n.count(
            "count",
            u64::from(q.count),
            MAX_AGENTS,
            "agents a scenario creates in all",
        ) && total > MAX_AGENTS
        {
            n.error(
                "count",
                format!("the groups and squads so far create {total} agents: a scenario creates at most {MAX_AGENTS} agents in all"),
            );
        }
        n.point("start", &[q.start.0, q.start.1]);
        n.point("goal", &[q.goal.0, q.goal.1]);
        check_planning(&mut n, &q.planning);
    }
    n.diags
}

/// A squad's `planning` constants (seed 004): `relax_step` and each class's `k1` in (0, 1], each
/// `k2` in [0, 1], `fm_broken` finite and ≥ 1 (one follower fitting costs 1).
fn check_planning(n: &mut crate::numbers::NumberCheck<'_>, p: &crate::formation::PlanningParams) {
    let here = n.from;
    n.enter("planning");
    let unit = |n: &mut crate::numbers::NumberCheck<'_>, key: &str, v: f32| {
        if !(v > 0.0 && v <= 1.0) {
            n.error(key, format!("`{key}` must be a number in (0, 1], not {v}"));
        }
    };
    unit(n, "relax_step", p.relax_step);
    n.range("fm_broken", p.fm_broken, 1.0, f32::MAX);
    let inside = n.from;
    for (class, f) in [
        ("must_keep", p.must_keep),
        ("may_change_rarely", p.may_change_rarely),
        ("shortest_first", p.shortest_first),
    ] {
        n.from = inside;
        n.enter(class);
        unit(n, "k1", f.k1);
        n.range("k2", f.k2, 0.0, 1.0);
    }
    n.from = here;
}

/// Whether no point of a 9×9×9 lattice over `region` lies outside every obstacle: a region
/// that cannot hold a group (spawning would have to put agents inside rock).
fn region_blocked(region: &Aabb, obstacles: &[ObstacleDef]) -> bool {
    let shapes: Vec<Shape> = obstacles.iter().map(ObstacleDef::shape).collect();
    if shapes.is_empty() {
        return false;
    }
    const N: usize = 9;
    let step = region.size() / (N - 1) as f32;
    for i in 0..N {
        for j in 0..N {
            for k in 0..N {
                let p = region.min + step * Vec3::new(i as f32, j as f32, k as f32);
                if shapes.iter().all(|s| s.push_out(p, 0.0).is_none()) {
                    return false;
                }
            }
        }
    }
    true
}

impl Scenario {
    /// Reads, validates and loads a scenario and every species it names.
    pub fn load(file: &Path) -> Result<Scenario, Diagnostics> {
        let text = crate::diag::read_text(file, "scenario")?;
        Self::load_str(file, &text)
    }

    /// Validates scenario `text` (named `file`).
    pub fn load_str(file: &Path, text: &str) -> Result<Scenario, Diagnostics> {
        let def: ScenarioDef = ron_options()
            .from_str(text)
            .map_err(|e| Diagnostics::from(ron_diag(file, text, &e)))?;
        let dir = file.parent().unwrap_or(Path::new("."));
        let behaviors_dir =
            normalize(&dir.join(def.behaviors.as_deref().unwrap_or("../behaviors")));
        let mut diags = Vec::new();
        let at = |needle: &str, from: usize| locate(text, needle, from).unwrap_or((0, 0, 0));
        // A species name written with escapes is not in the text as parsed: point at the list.
        let at_species = |needle: &str, from: usize| {
            locate(text, needle, from)
                .or_else(|| locate(text, "species", 0))
                .unwrap_or((0, 0, 0))
        };
        if !(def.dt > 0.0 && def.dt.is_finite()) {
            let (l, c, _) = at("dt", 0);
            diags.push(Diagnostic::new(
                file,
                l,
                c,
                "`dt` must be a positive number of seconds",
                Some(text),
            ));
        }
        if !(def.duration >= 0.0 && def.duration.is_finite()) {
            let (l, c, _) = at("duration", 0);
            diags.push(Diagnostic::new(
                file,
                l,
                c,
                "`duration` must be ≥ 0 seconds",
                Some(text),
            ));
        }
        diags.extend(scenario_numbers(file, text, &def));
        if def.bounds.min.cmpge(def.bounds.max).any() {
            let (l, c, _) = at("bounds", 0);
            diags.push(Diagnostic::new(
                file,
                l,
                c,
                "`bounds`: `min` must be below `max` on every axis",
                Some(text),
            ));
        }
        let mut loaded: Vec<Arc<Species>> = Vec::new();
        let mut listed = std::collections::BTreeSet::new();
        for name in &def.species {
            // Each problem scans the text to locate it: a list of 40,000 bad names took 5 s.
            if diags.len() >= MAX_DIAGNOSTICS {
                break;
            }
            // Loaded once each: a name repeated 40,000 times would compile its script as often.
            if !listed.insert(name.as_str()) {
                let needle = format!("\"{name}\"");
                let second = locate(text, &needle, 0).map_or(0, |x| x.2 + 1);
                let (l, c, _) = at_species(&needle, second);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!("species \"{name}\" is listed twice"),
                    Some(text),
                ));
                continue;
            }
            let path = behaviors_dir.join(format!("{name}.ron"));
            if let Some(problem) = crate::diag::file_problem(&path) {
                let (l, c, _) = at_species(&format!("\"{name}\""), 0);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!("species file \"{}\" {problem}", path.display()),
                    Some(text),
                ));
                continue;
            }
            match load_species(&path, &behaviors_dir, &script_limits()) {
                Ok(s) => {
                    if &s.name != name {
                        let (l, c, _) = at_species(&format!("\"{name}\""), 0);
                        diags.push(Diagnostic::new(
                            file,
                            l,
                            c,
                            format!(
                                "\"{}\" defines species \"{}\", not \"{name}\"",
                                path.display(),
                                s.name
                            ),
                            Some(text),
                        ));
                    }
                    loaded.push(Arc::new(s))
                }
                Err(d) => diags.extend(d.0),
            }
        }
        let known = |n: &str| def.species.iter().any(|s| s == n);
        let check_group = |g: &GroupDef, diags: &mut Vec<Diagnostic>, from: usize| {
            let from = locate(text, &format!("\"{}\"", g.species), from).map_or(from, |x| x.2);
            if !known(&g.species) {
                let (l, c, _) = at(&format!("\"{}\"", g.species), from);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!(
                        "unknown species \"{}\": the scenario loads {}",
                        g.species,
                        def.species.join(", ")
                    ),
                    Some(text),
                ));
            }
            if g.count < 0 {
                let (l, c, _) = at("count", from);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!("`count` must be ≥ 0, not {}", g.count),
                    Some(text),
                ));
            }
            check_region(
                diags,
                file,
                text,
                &def.bounds,
                &g.region,
                &format!("group of \"{}\"", g.species),
                from,
            );
            if g.count > 0 && region_blocked(&g.region, &def.obstacles) {
                let (l, c, _) = at("region", from);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!(
                        "group of \"{}\": its spawn region {:?}..{:?} lies inside obstacles; \
                         expected a region with room outside them",
                        g.species,
                        g.region.min.to_array(),
                        g.region.max.to_array()
                    ),
                    Some(text),
                ));
            }
            from + 1
        };
        let mut from = locate(text, "groups", 0).map_or(0, |x| x.2);
        for g in &def.groups {
            if diags.len() >= MAX_DIAGNOSTICS {
                break;
            }
            from = check_group(g, &mut diags, from);
        }
        let mut from = locate(text, "events", 0).map_or(0, |x| x.2);
        for e in &def.events {
            if diags.len() >= MAX_DIAGNOSTICS {
                break;
            }
            match e.action.clone() {
                EventAction::Spawn(g) => from = check_group(&g, &mut diags, from),
                EventAction::RemoveObstacle(id) if id as usize >= def.obstacles.len() => {
                    let (l, c, _) = at("RemoveObstacle", from);
                    diags.push(Diagnostic::new(
                        file,
                        l,
                        c,
                        format!(
                            "no obstacle {id}: the scenario has {} (ids start at 0)",
                            def.obstacles.len()
                        ),
                        Some(text),
                    ));
                }
                EventAction::DropFood { region, .. } => check_region(
                    &mut diags,
                    file,
                    text,
                    &def.bounds,
                    &region,
                    "DropFood",
                    from,
                ),
                _ => {}
            }
        }
        if let Some(r) = def.food.region {
            check_region(&mut diags, file, text, &def.bounds, &r, "food", 0);
        }
        if !diags.is_empty() {
            return Err(Diagnostics(diags));
        }
        let lib = behaviors_dir.clone();
        let species = Arc::new(SpeciesSet::with_library(loaded, |n| {
            lib.join(format!("{n}.ron")).is_file()
        })?);
        let (ground, squads) = crate::squad::setup::load(file, text, &def, &species)?;
        Ok(Scenario {
            name: def.name.clone().unwrap_or_else(|| {
                file.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            }),
            file: file.to_path_buf(),
            text: text.to_string(),
            def,
            behaviors_dir,
            species,
            ground,
            squads,
        })
    }

    /// Every file the scenario was built from: itself, species, scripts and imports.
    pub fn files(&self) -> Vec<PathBuf> {
        let mut v = vec![self.file.clone()];
        for s in &self.species.species {
            v.extend(s.files());
        }
        v
    }
}

/// Options a run may override.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Overrides {
    /// Seed.
    pub seed: Option<u64>,
    /// Duration (s).
    pub duration: Option<f32>,
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
    next_event: usize,
    food_rng: Rng,
    food_debt: f32,
    /// Events the scenario itself made (spawns of its timed groups).
    pub scenario_events: Vec<crate::events::Event>,
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
    pub fn spawn_group(&mut self, g: &GroupDef, salt: u64) {
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
    fn spawn_group_in(&mut self, g: &GroupDef, salt: u64, layout: &Layout) {
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
        let clearance = self.scenario.species.species[s].def.body.size.length() * 0.5;
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
        let params = &self.scenario.species.species[s].def.drives.params;
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
}
