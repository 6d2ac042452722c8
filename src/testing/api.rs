//! The Rhai API of script tests: a world builder (`world()`, `spawn`, `add_food`, `add_rock`,
//! `step`, `step_until`), agent handles that read and set everything a behavior depends on,
//! percept injection (`perceive`), the event log, and assertions whose failures say what was
//! expected, what happened and what the agent last decided.
//!
//! A separate engine from the species scripts' (built per test, with the same safety limits
//! except a larger operation budget, since a whole test is one call). Angles are in degrees.

use super::coverage::Coverage;
use super::failure::{error, raise, Kind};
use super::world::{lock, Feed, Library, Logged, TestWorld};
use crate::events::{Cause, Event};
use crate::frame;
use crate::perception::{Category, Sense};
use crate::species::SexDef;
use crate::terrain::{load_asc, Cell, CellAttrs, Terrain};
use crate::world::{Aabb, AgentId, Sex, MEMORY_CAPACITY};
use glam::{Vec2, Vec3};
use rhai::{
    Array, Dynamic, Engine, EvalAltResult, FnPtr, ImmutableString, Map, NativeCallContext, FLOAT,
    INT,
};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

type R<T> = Result<T, Box<EvalAltResult>>;

/// Default world bounds of a test: 100 × 30 × 100 around the origin, floor at 0.
pub const DEFAULT_BOUNDS: (Vec3, Vec3) =
    (Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 30.0, 50.0));

/// What one running test shares with the functions it calls.
pub struct TestCtx {
    /// Species of its behaviors folder.
    pub library: Arc<Library>,
    /// Coverage of the whole run.
    pub coverage: Arc<Coverage>,
    /// Most ticks one world may run.
    pub max_ticks: u64,
    /// Worlds the test built, in order.
    pub worlds: Mutex<Vec<WorldRef>>,
    /// What the test printed.
    pub output: Mutex<String>,
    /// Parameter counts of the file's functions (anonymous ones included).
    pub fn_params: BTreeMap<String, usize>,
}

/// A world handle in a test script.
#[derive(Clone)]
pub struct WorldRef(pub Arc<Mutex<TestWorld>>);

/// An agent handle: reads the live state of one agent of a world.
#[derive(Clone)]
pub struct AgentRef {
    /// Its world.
    pub world: WorldRef,
    /// Its id.
    pub id: AgentId,
}

impl WorldRef {
    fn get(&self) -> std::sync::MutexGuard<'_, TestWorld> {
        lock(&self.0)
    }
}

fn num(d: &Dynamic, what: &str) -> R<f32> {
    if let Ok(f) = d.as_float() {
        Ok(f)
    } else if let Ok(i) = d.as_int() {
        Ok(i as f32)
    } else {
        Err(error(format!(
            "`{what}` must be a number, not {}",
            d.type_name()
        )))
    }
}

fn int(d: &Dynamic, what: &str) -> R<i64> {
    d.as_int()
        .map_err(|t| error(format!("`{what}` must be an integer, not {t}")))
}

fn vec3(d: &Dynamic, what: &str) -> R<Vec3> {
    d.clone().try_cast::<Vec3>().ok_or_else(|| {
        error(format!(
            "`{what}` must be a vec3(x, y, z), not {}",
            d.type_name()
        ))
    })
}

fn string(d: &Dynamic, what: &str) -> R<String> {
    d.clone()
        .into_immutable_string()
        .map(|s| s.to_string())
        .map_err(|t| error(format!("`{what}` must be a string, not {t}")))
}

fn strings(a: &Array, what: &str) -> R<Vec<String>> {
    a.iter().map(|d| string(d, what)).collect()
}

fn check_keys(m: &Map, known: &[&str], what: &str) -> R<()> {
    for k in m.keys() {
        if !known.contains(&k.as_str()) {
            return Err(error(format!(
                "unknown {what} option `{k}`: expected one of {}",
                known.join(", ")
            )));
        }
    }
    Ok(())
}

use crate::script::{from_mem, to_mem};

fn category(name: &str) -> R<Category> {
    Category::ALL
        .into_iter()
        .find(|c| c.name() == name)
        .ok_or_else(|| {
            error(format!(
                "unknown category \"{name}\": expected one of food, predator, kin, mate, obstacle, other"
            ))
        })
}

fn new_world(ctx: &Arc<TestCtx>, opts: &Map) -> R<WorldRef> {
    check_keys(
        opts,
        &[
            "min",
            "max",
            "seed",
            "dt",
            "max_ticks",
            "current",
            "terrain",
        ],
        "world",
    )?;
    // A terrain file sets the default bounds to its extent.
    let dem = match opts.get("terrain") {
        Some(d) if d.is_string() => Some(load_dem(ctx, &string(d, "terrain")?)?),
        _ => None,
    };
    let (dmin, dmax) = dem.as_ref().map_or(DEFAULT_BOUNDS, |t| {
        let (lo, hi) = height_range(t);
        let size = Vec2::new(t.cols as f32, t.rows as f32) * t.cell_size;
        (
            Vec3::new(t.origin.x, lo - 1.0, t.origin.y),
            Vec3::new(t.origin.x + size.x, hi + 30.0, t.origin.y + size.y),
        )
    });
    let min = opts.get("min").map_or(Ok(dmin), |d| vec3(d, "min"))?;
    let max = opts.get("max").map_or(Ok(dmax), |d| vec3(d, "max"))?;
    if min.cmpge(max).any() {
        return Err(error(
            "world bounds: `min` must be below `max` on every axis",
        ));
    }
    let seed = opts.get("seed").map_or(Ok(1), |d| int(d, "seed"))?;
    let dt = opts.get("dt").map_or(Ok(0.05), |d| num(d, "dt"))?;
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(error("`dt` must be a positive number of seconds"));
    }
    let max_ticks = opts
        .get("max_ticks")
        .map_or(Ok(ctx.max_ticks as i64), |d| int(d, "max_ticks"))?
        .max(0) as u64;
    let mut tw = TestWorld::new(
        Aabb::new(min, max),
        dt,
        seed as u64,
        max_ticks.min(ctx.max_ticks),
        ctx.library.clone(),
        ctx.coverage.clone(),
    );
    if let Some(c) = opts.get("current") {
        tw.sim.world.current = vec3(c, "current")?;
    }
    let terrain = match (dem, opts.get("terrain")) {
        (Some(t), _) => Some(t),
        (None, Some(d)) => Some(flat_terrain(d, &tw.sim.world.bounds)?),
        (None, None) => None,
    };
    if let Some(t) = terrain {
        let (lo, hi) = height_range(&t);
        let b = tw.sim.world.bounds;
        if lo < b.min.y || hi > b.max.y {
            return Err(error(format!(
                "the world bounds must hold the terrain: its heights run from {lo} to {hi}, the bounds' y from {} to {}",
                b.min.y, b.max.y
            )));
        }
        tw.sim.world.terrain = Some(Arc::new(t));
    }
    let w = WorldRef(Arc::new(Mutex::new(tw)));
    lock(&ctx.worlds).push(w.clone());
    Ok(w)
}

fn height_range(t: &Terrain) -> (f32, f32) {
    t.heights
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &h| {
            (a.min(h), b.max(h))
        })
}

/// An ESRI ASCII grid, the path relative to the behaviors folder.
fn load_dem(ctx: &TestCtx, path: &str) -> R<Terrain> {
    let p = ctx.library.root.join(path);
    if !p.is_file() {
        return Err(error(format!("terrain file \"{}\" not found", p.display())));
    }
    load_asc(&p).map_err(|d| error(format!("terrain file does not load:\n{d}")))
}

/// A terrain built in the test over the world's `x`/`z` extent: `#{ cell, height, slope, walls }`
/// (cell size, height at `min.x`, rise per metre towards +x, and rectangles `[x0, z0, x1, z1]`
/// of cells marked as buildings, which walkers cannot enter).
fn flat_terrain(d: &Dynamic, b: &Aabb) -> R<Terrain> {
    let m = d.clone().try_cast::<Map>().ok_or_else(|| {
        error("`terrain` is a terrain file (\"x.asc\") or a map #{ cell, height, slope, walls }")
    })?;
    check_keys(&m, &["cell", "height", "slope", "walls"], "terrain")?;
    let cell = m.get("cell").map_or(Ok(2.0), |d| num(d, "cell"))?;
    if !(cell.is_finite() && cell > 0.0) {
        return Err(error("a terrain's `cell` size must be positive"));
    }
    let height = m.get("height").map_or(Ok(0.0), |d| num(d, "height"))?;
    let slope = m.get("slope").map_or(Ok(0.0), |d| num(d, "slope"))?;
    let cols = ((b.max.x - b.min.x) / cell).ceil().max(1.0) as usize;
    let rows = ((b.max.z - b.min.z) / cell).ceil().max(1.0) as usize;
    if cols * rows > 1 << 20 {
        return Err(error(format!(
            "a terrain of {cols} × {rows} cells is too big for a test: give a larger `cell`"
        )));
    }
    let origin = Vec2::new(b.min.x, b.min.z);
    let heights = (0..rows * cols)
        .map(|i| height + slope * ((i % cols) as f32 + 0.5) * cell)
        .collect();
    let mut t = Terrain::from_heights(cols, rows, cell, origin, heights);
    let walls = match m.get("walls") {
        None => Array::new(),
        Some(w) => w
            .clone()
            .try_cast::<Array>()
            .ok_or_else(|| error("`walls` must be an array of rectangles [x0, z0, x1, z1]"))?,
    };
    for w in walls {
        let r = w
            .try_cast::<Array>()
            .filter(|r| r.len() == 4)
            .ok_or_else(|| error("a wall is a rectangle [x0, z0, x1, z1]"))?;
        let v: Vec<f32> = r.iter().map(|x| num(x, "wall")).collect::<R<_>>()?;
        let (lo, hi) = (
            Vec2::new(v[0].min(v[2]), v[1].min(v[3])),
            Vec2::new(v[0].max(v[2]), v[1].max(v[3])),
        );
        for i in 0..rows * cols {
            let c = t.center_of(Cell::new(i % cols, i / cols));
            if c.cmpge(lo).all() && c.cmple(hi).all() {
                t.attrs[i].flags |= CellAttrs::BUILDING;
            }
        }
    }
    Ok(t)
}

/// World `(x, z)` from a vec3 (its `y` ignored) or an array `[x, z]`.
fn xz(d: &Dynamic, what: &str) -> R<Vec2> {
    if let Some(v) = d.clone().try_cast::<Vec3>() {
        return Ok(Vec2::new(v.x, v.z));
    }
    match d.clone().try_cast::<Array>() {
        Some(a) if a.len() == 2 => Ok(Vec2::new(num(&a[0], what)?, num(&a[1], what)?)),
        _ => Err(error(format!(
            "`{what}` must be [x, z] or a vec3, not {}",
            d.type_name()
        ))),
    }
}

fn add_squad(
    w: &WorldRef,
    species: &str,
    count: INT,
    start: &Dynamic,
    goal: &Dynamic,
    opts: &Map,
) -> R<Array> {
    check_keys(
        opts,
        &["formations", "task", "spacing", "names"],
        "add_squad",
    )?;
    let (start, goal) = (xz(start, "start")?, xz(goal, "goal")?);
    let formations = match opts.get("formations") {
        None => vec!["line".to_string()],
        Some(d) => strings(
            &d.clone()
                .try_cast::<Array>()
                .ok_or_else(|| error("`formations` must be an array of names, e.g. [\"wedge\"]"))?,
            "formations",
        )?,
    };
    let task = opts
        .get("task")
        .map_or(Ok("MayChangeRarely".to_string()), |d| string(d, "task"))?;
    let spacing = opts.get("spacing").map_or(Ok(3.0), |d| num(d, "spacing"))?;
    let names = match opts.get("names") {
        None => Vec::new(),
        Some(d) => strings(
            &d.clone()
                .try_cast::<Array>()
                .ok_or_else(|| error("`names` must be an array of names, by member"))?,
            "names",
        )?,
    };
    let mut tw = w.get();
    for n in &names {
        if tw.named(n).is_some() {
            return Err(error(format!("an agent is already named \"{n}\"")));
        }
    }
    let count = usize::try_from(count).map_err(|_| error("a squad needs at least 1 member"))?;
    let ids = tw
        .add_squad(species, count, start, goal, &formations, &task, spacing)
        .map_err(error)?;
    for (id, n) in ids.iter().zip(names) {
        tw.names.insert(*id, n);
    }
    drop(tw);
    Ok(ids
        .into_iter()
        .map(|id| {
            Dynamic::from(AgentRef {
                world: w.clone(),
                id,
            })
        })
        .collect())
}

/// What a squad member's script reads of its squad, now: `member`, `leader`, `slot`,
/// `slot_dist`, `at_goal`, `formation`; `()` for an agent in no squad.
fn squad_of(a: &AgentRef) -> R<Dynamic> {
    a.with(|tw, i| {
        let pos = tw.sim.world.agents[i].pos;
        let Some(sq) = tw
            .sim
            .squads
            .squads
            .iter()
            .find(|s| s.members.contains(&a.id))
        else {
            return Dynamic::UNIT;
        };
        let m = sq.members.iter().position(|x| *x == a.id).unwrap_or(0);
        let slot = sq.slot(m);
        let y = tw
            .sim
            .world
            .terrain
            .as_ref()
            .map_or(pos.y, |t| t.height_at(slot.x, slot.y));
        let mut out = Map::new();
        out.insert("member".into(), Dynamic::from(m as INT));
        out.insert("leader".into(), Dynamic::from(m == sq.leader));
        out.insert("slot".into(), Dynamic::from(Vec3::new(slot.x, y, slot.y)));
        out.insert(
            "slot_dist".into(),
            Dynamic::from(Vec2::new(pos.x, pos.z).distance(slot) as FLOAT),
        );
        out.insert("at_goal".into(), Dynamic::from(sq.progress.finished));
        out.insert(
            "formation".into(),
            Dynamic::from(sq.formations[sq.formation_now()].name().to_string()),
        );
        Dynamic::from(out)
    })
}

/// Sets hunger so that it stays there: the digestion model starts from the value given.
fn set_hunger(tw: &mut TestWorld, i: usize, h: f32) {
    let a = &mut tw.sim.world.agents[i];
    let d = &tw.species[a.species.0 as usize].def.drives;
    a.drives.hunger = h.clamp(0.0, 1.0);
    if d.native {
        (a.drives.eaten, a.drives.since_meal) =
            crate::drives::meal_clock_for(a.drives.hunger, 0.0, &d.params);
    }
}

/// Sets libido so that it stays there given the current hunger (`L = p1·Δt_L·(1 − H)`).
fn set_libido(tw: &mut TestWorld, i: usize, l: f32) {
    let a = &mut tw.sim.world.agents[i];
    let d = &tw.species[a.species.0 as usize].def.drives;
    a.drives.libido = l.clamp(0.0, 1.0);
    let k = d.params.p1 * (1.0 - a.drives.hunger);
    if d.native && k > 0.0 {
        a.drives.since_mating = a.drives.libido / k;
    }
}

fn spawn(w: &WorldRef, species: &str, pos: Vec3, opts: &Map) -> R<AgentRef> {
    check_keys(
        opts,
        &[
            "name", "yaw", "pitch", "speed", "hunger", "libido", "fear", "fatigue", "sex", "age",
            "mass", "kind", "behavior", "stack", "memory",
        ],
        "add_agent",
    )?;
    let mut tw = w.get();
    let s = tw.species_index(species).map_err(error)?;
    if !tw.sim.world.bounds.contains(pos) {
        return Err(error(format!(
            "spawn position {pos} is outside the world bounds {}..{}",
            tw.sim.world.bounds.min, tw.sim.world.bounds.max
        )));
    }
    let name = opts.get("name").map(|d| string(d, "name")).transpose()?;
    if let Some(n) = &name {
        if tw.named(n).is_some() {
            return Err(error(format!("an agent is already named \"{n}\"")));
        }
    }
    let yaw = opts.get("yaw").map_or(Ok(0.0), |d| num(d, "yaw"))?;
    let pitch = opts.get("pitch").map_or(Ok(0.0), |d| num(d, "pitch"))?;
    let id = tw.spawn(s, pos, yaw.to_radians(), pitch.to_radians());
    if let Some(n) = name {
        tw.names.insert(id, n);
    }
    let i = tw.sim.world.agents.len() - 1;
    let sp = tw.species[s].clone();
    if let Some(d) = opts.get("speed") {
        tw.sim.world.agents[i].speed = num(d, "speed")?;
    }
    if let Some(d) = opts.get("hunger") {
        set_hunger(&mut tw, i, num(d, "hunger")?);
    }
    if let Some(d) = opts.get("libido") {
        set_libido(&mut tw, i, num(d, "libido")?);
    }
    let a = &mut tw.sim.world.agents[i];
    if let Some(d) = opts.get("fear") {
        a.drives.fear = num(d, "fear")?.clamp(0.0, 1.0);
    }
    if let Some(d) = opts.get("fatigue") {
        a.drives.fatigue = num(d, "fatigue")?.clamp(0.0, 1.0);
    }
    if let Some(d) = opts.get("sex") {
        a.attrs.sex = match string(d, "sex")?.as_str() {
            "female" => Sex::Female,
            "male" => Sex::Male,
            other => {
                return Err(error(format!(
                    "`sex` is \"female\" or \"male\", not \"{other}\""
                )))
            }
        };
    } else if sp.def.attributes.sex == SexDef::Random {
        // Random sexes would make tests depend on ids: an unstated sex is female.
        a.attrs.sex = Sex::Female;
    }
    if let Some(d) = opts.get("age") {
        a.attrs.age = num(d, "age")?;
    }
    if let Some(d) = opts.get("mass") {
        a.attrs.mass = num(d, "mass")?;
    }
    if let Some(d) = opts.get("kind") {
        a.attrs.kind = int(d, "kind")?.clamp(0, u16::MAX as i64) as u16;
    }
    let behavior_of = |n: &str| {
        sp.behavior_index(n).ok_or_else(|| {
            let known: Vec<&str> = sp.behaviors.iter().map(|b| &*b.name).collect();
            error(format!(
                "unknown behavior \"{n}\" of species \"{}\": expected one of {}",
                sp.name,
                known.join(", ")
            ))
        })
    };
    if let Some(d) = opts.get("behavior") {
        a.mind.current = behavior_of(&string(d, "behavior")?)?;
    }
    if let Some(d) = opts.get("stack") {
        let arr = d
            .clone()
            .try_cast::<Array>()
            .ok_or_else(|| error("`stack` must be an array of behavior names, bottom first"))?;
        for n in strings(&arr, "stack")? {
            let b = behavior_of(&n)?;
            a.mind.push(b);
        }
    }
    if let Some(d) = opts.get("memory") {
        let m = d
            .clone()
            .try_cast::<Map>()
            .ok_or_else(|| error("`memory` must be a map, e.g. #{ meals: 2 }"))?;
        for (k, v) in m {
            let v = to_mem(v)?;
            if a.memory.len() >= MEMORY_CAPACITY {
                return Err(error(format!("memory is full ({MEMORY_CAPACITY} keys)")));
            }
            match a
                .memory
                .binary_search_by(|(x, _)| x.as_str().cmp(k.as_str()))
            {
                Ok(j) => a.memory[j].1 = v,
                Err(j) => a.memory.insert(j, (k.to_string(), v)),
            }
        }
    }
    drop(tw);
    Ok(AgentRef {
        world: w.clone(),
        id,
    })
}

impl AgentRef {
    /// Runs `f` on the live agent, or fails saying why it is gone.
    fn with<T>(&self, f: impl FnOnce(&TestWorld, usize) -> T) -> R<T> {
        let tw = self.world.get();
        let i = tw.index(self.id).map_err(error)?;
        Ok(f(&tw, i))
    }
    fn with_mut<T>(&self, f: impl FnOnce(&mut TestWorld, usize) -> T) -> R<T> {
        let mut tw = self.world.get();
        let i = tw.index(self.id).map_err(error)?;
        Ok(f(&mut tw, i))
    }
    fn label(&self) -> String {
        self.world.get().label(self.id)
    }
    fn behavior(&self) -> R<String> {
        self.with(|tw, i| {
            let a = &tw.sim.world.agents[i];
            tw.species[a.species.0 as usize]
                .behavior_name(a.mind.current)
                .to_string()
        })
    }
    fn stack(&self) -> R<Vec<String>> {
        self.with(|tw, i| {
            let a = &tw.sim.world.agents[i];
            let sp = &tw.species[a.species.0 as usize];
            a.mind
                .stack()
                .iter()
                .map(|b| sp.behavior_name(*b).to_string())
                .collect()
        })
    }
    fn decisions(&self) -> String {
        self.world.get().decisions(self.id, 8)
    }
}

fn step_world(w: &WorldRef, n: i64) -> R<()> {
    let mut tw = w.get();
    for _ in 0..n.max(0) {
        tw.step()
            .map_err(|m| raise(Kind::Error, m, tw.all_decisions(8)))?;
    }
    Ok(())
}

fn event_map(tw: &TestWorld, l: &Logged) -> Map {
    let mut m = Map::new();
    let mut put = |k: &str, v: Dynamic| {
        m.insert(k.into(), v);
    };
    put("tick", Dynamic::from(l.tick as INT));
    put(
        "time",
        Dynamic::from((l.tick as f64 * tw.sim.world.dt as f64) as FLOAT),
    );
    put("kind", Dynamic::from(ImmutableString::from(l.event.kind())));
    let sp_name = |s: u16| {
        Dynamic::from(ImmutableString::from(
            tw.species.get(s as usize).map_or("?", |x| x.name.as_str()),
        ))
    };
    let id = |a: AgentId| Dynamic::from(a.0 as INT);
    match &l.event {
        Event::Spawn { agent, species } => {
            put("agent", id(*agent));
            put("species", sp_name(*species));
        }
        Event::Death {
            agent,
            species,
            cause,
        } => {
            put("agent", id(*agent));
            put("species", sp_name(*species));
            put("cause", Dynamic::from(ImmutableString::from(*cause)));
        }
        Event::Meal { agent, food } => {
            put("agent", id(*agent));
            put("food", Dynamic::from(*food as INT));
        }
        Event::Catch { agent, prey } => {
            put("agent", id(*agent));
            put("prey", id(*prey));
        }
        Event::Mating { agent, mate } => {
            put("agent", id(*agent));
            put("mate", id(*mate));
        }
        Event::Transition {
            agent,
            species,
            from,
            to,
            cause,
            condition,
            stack,
        } => {
            let sp = &tw.species[*species as usize];
            let name = |b: u16| Dynamic::from(ImmutableString::from(sp.behavior_name(b)));
            put("agent", id(*agent));
            put("species", sp_name(*species));
            put("from", name(*from));
            put("to", name(*to));
            put("cause", Dynamic::from(ImmutableString::from(cause.name())));
            put(
                "condition",
                Dynamic::from(ImmutableString::from(
                    condition.as_deref().unwrap_or_default(),
                )),
            );
            put(
                "stack",
                Dynamic::from(stack.iter().map(|b| name(*b)).collect::<Array>()),
            );
        }
        Event::Message { from, kind, radius } => {
            put("agent", id(*from));
            put("message", Dynamic::from(ImmutableString::from(kind.name())));
            put("radius", Dynamic::from(*radius));
        }
        Event::ScriptError { agent, message, .. } => {
            put("agent", id(*agent));
            put(
                "message",
                Dynamic::from(ImmutableString::from(message.as_str())),
            );
        }
    }
    m
}

fn involves(e: &Event, id: AgentId) -> bool {
    match e {
        Event::Spawn { agent, .. }
        | Event::Death { agent, .. }
        | Event::Meal { agent, .. }
        | Event::Transition { agent, .. }
        | Event::ScriptError { agent, .. } => *agent == id,
        Event::Catch { agent, prey } => *agent == id || *prey == id,
        Event::Mating { agent, mate } => *agent == id || *mate == id,
        Event::Message { from, .. } => *from == id,
    }
}

fn events(w: &WorldRef, filter: impl Fn(&Event) -> bool) -> Array {
    let tw = w.get();
    tw.log
        .iter()
        .filter(|l| filter(&l.event))
        .map(|l| Dynamic::from(event_map(&tw, l)))
        .collect()
}

fn feed(d: &Dynamic) -> R<Feed> {
    let m = d
        .clone()
        .try_cast::<Map>()
        .ok_or_else(|| error("a percept is a map, e.g. #{ what: \"predator\", dist: 5.0 }"))?;
    check_keys(
        &m,
        &["what", "dist", "bearing", "elevation", "sense", "size"],
        "percept",
    )?;
    let what = m.get("what").ok_or_else(|| {
        error("a percept needs `what` (food, predator, kin, mate, obstacle, other)")
    })?;
    let category = category(&string(what, "what")?)?;
    let dist = m
        .get("dist")
        .ok_or_else(|| error("a percept needs `dist`"))
        .and_then(|d| num(d, "dist"))?;
    if !(dist >= 0.0 && dist.is_finite()) {
        return Err(error(format!("`dist` must be ≥ 0, not {dist}")));
    }
    let sense = match m
        .get("sense")
        .map(|d| string(d, "sense"))
        .transpose()?
        .as_deref()
    {
        None | Some("vision") => Sense::Vision,
        Some("smell") => Sense::Smell,
        Some(other) => {
            return Err(error(format!(
                "`sense` is \"vision\" or \"smell\", not \"{other}\""
            )))
        }
    };
    Ok(Feed {
        category,
        dist,
        bearing: m
            .get("bearing")
            .map_or(Ok(0.0), |d| num(d, "bearing"))?
            .to_radians(),
        elevation: m
            .get("elevation")
            .map_or(Ok(0.0), |d| num(d, "elevation"))?
            .to_radians(),
        sense,
        size: m.get("size").map_or(
            Ok(if category == Category::Food { 0.0 } else { 1.0 }),
            |d| num(d, "size"),
        )?,
    })
}

fn perceive(a: &AgentRef, feeds: Vec<Feed>) -> R<()> {
    a.with_mut(|tw, _| {
        tw.feeds.insert(a.id, feeds);
    })
}

/// Calls a condition with `this` bound to `subject`, passing the subject too when the function
/// takes a parameter.
fn holds(
    ctx: &NativeCallContext,
    params: &BTreeMap<String, usize>,
    f: &FnPtr,
    subject: &Dynamic,
) -> R<bool> {
    let n = params.get(f.fn_name()).copied().unwrap_or(0);
    let mut this = subject.clone();
    let args: Vec<Dynamic> = (0..n).map(|_| subject.clone()).collect();
    let r = f.call_raw(ctx, Some(&mut this), args)?;
    r.as_bool()
        .map_err(|t| error(format!("the condition must return true or false, not {t}")))
}

/// What a condition is about: a whole world or one agent.
#[derive(Clone)]
enum Subject {
    World(WorldRef),
    Agent(AgentRef),
}

impl Subject {
    fn world(&self) -> &WorldRef {
        match self {
            Subject::World(w) => w,
            Subject::Agent(a) => &a.world,
        }
    }
    fn dynamic(&self) -> Dynamic {
        match self {
            Subject::World(w) => Dynamic::from(w.clone()),
            Subject::Agent(a) => Dynamic::from(a.clone()),
        }
    }
    fn context(&self) -> String {
        match self {
            Subject::World(w) => w.get().all_decisions(8),
            Subject::Agent(a) => a.decisions(),
        }
    }
}

fn ticks_text(w: &WorldRef, ticks: u64) -> String {
    let dt = w.get().world.dt as f64;
    format!("{ticks} ticks ({:.2} s)", ticks as f64 * dt)
}

fn assert_within(
    ctx: &NativeCallContext,
    params: &BTreeMap<String, usize>,
    s: Subject,
    ticks: INT,
    f: FnPtr,
) -> R<()> {
    let d = s.dynamic();
    let start = s.world().get().world.tick;
    for k in 0..=ticks.max(0) {
        if holds(ctx, params, &f, &d)? {
            return Ok(());
        }
        if k < ticks {
            step_world(s.world(), 1)?;
        }
    }
    let now = s.world().get().world.tick;
    Err(raise(
        Kind::Fail,
        format!(
            "expected the condition to become true within {}, but it was still false at tick {now} (started at tick {start})",
            ticks_text(s.world(), ticks.max(0) as u64)
        ),
        s.context(),
    ))
}

fn assert_always(
    ctx: &NativeCallContext,
    params: &BTreeMap<String, usize>,
    s: Subject,
    ticks: INT,
    f: FnPtr,
) -> R<()> {
    let d = s.dynamic();
    for k in 0..=ticks.max(0) {
        if !holds(ctx, params, &f, &d)? {
            let now = s.world().get().world.tick;
            return Err(raise(
                Kind::Fail,
                format!(
                    "expected the condition to stay true for {}, but it was false at tick {now} (after {k} ticks)",
                    ticks_text(s.world(), ticks.max(0) as u64)
                ),
                s.context(),
            ));
        }
        if k < ticks {
            step_world(s.world(), 1)?;
        }
    }
    Ok(())
}

fn last_context(ctx: &TestCtx) -> String {
    lock(&ctx.worlds)
        .last()
        .map(|w| w.get().all_decisions(8))
        .unwrap_or_default()
}

fn show(d: &Dynamic) -> String {
    if let Some(s) = d.clone().try_cast::<ImmutableString>() {
        format!("\"{s}\"")
    } else if let Some(v) = d.clone().try_cast::<Vec3>() {
        format!("vec3({}, {}, {})", v.x, v.y, v.z)
    } else if let Some(a) = d.clone().try_cast::<Array>() {
        format!("[{}]", a.iter().map(show).collect::<Vec<_>>().join(", "))
    } else if let Some(a) = d.clone().try_cast::<AgentRef>() {
        a.label()
    } else {
        d.to_string()
    }
}

fn same(a: &Dynamic, b: &Dynamic) -> bool {
    let n = |d: &Dynamic| {
        d.as_float()
            .ok()
            .map(|f| f as f64)
            .or_else(|| d.as_int().ok().map(|i| i as f64))
    };
    if let (Some(x), Some(y)) = (n(a), n(b)) {
        return x == y;
    }
    if let (Some(x), Some(y)) = (a.clone().try_cast::<Array>(), b.clone().try_cast::<Array>()) {
        return x.len() == y.len() && x.iter().zip(&y).all(|(p, q)| same(p, q));
    }
    if let (Some(x), Some(y)) = (
        a.clone().try_cast::<AgentRef>(),
        b.clone().try_cast::<AgentRef>(),
    ) {
        return x.id == y.id && Arc::ptr_eq(&x.world.0, &y.world.0);
    }
    a.type_id() == b.type_id() && show(a) == show(b)
}

fn near(a: &Dynamic, b: &Dynamic, tol: &Dynamic) -> R<(bool, f32)> {
    let tol = num(tol, "tolerance")?;
    let off = match (a.clone().try_cast::<Vec3>(), b.clone().try_cast::<Vec3>()) {
        (Some(x), Some(y)) => x.distance(y),
        _ => (num(a, "value")? - num(b, "expected")?).abs(),
    };
    Ok((off <= tol, off))
}

/// Registers the test API on `e` for the test described by `ctx`.
pub fn register(e: &mut Engine, ctx: Arc<TestCtx>) {
    e.register_type_with_name::<WorldRef>("World")
        .register_type_with_name::<AgentRef>("Agent");
    let c = ctx.clone();
    e.register_fn("world", move || new_world(&c, &Map::new()));
    let c = ctx.clone();
    e.register_fn("world", move |opts: Map| new_world(&c, &opts));

    // World building.
    e.register_fn("add_agent", |w: &mut WorldRef, species: &str, pos: Vec3| {
        spawn(w, species, pos, &Map::new())
    });
    e.register_fn(
        "add_agent",
        |w: &mut WorldRef, species: &str, pos: Vec3, opts: Map| spawn(w, species, pos, &opts),
    );
    e.register_fn("add_food", |w: &mut WorldRef, pos: Vec3| -> R<INT> {
        let mut tw = w.get();
        if !tw.sim.world.bounds.contains(pos) {
            return Err(error(format!("food at {pos} is outside the world bounds")));
        }
        Ok(tw.sim.world.add_food(pos) as INT)
    });
    e.register_fn(
        "add_rock",
        |w: &mut WorldRef, center: Vec3, radius: FLOAT| -> R<INT> {
            if radius.is_nan() || radius <= 0.0 {
                return Err(error("a rock's radius must be positive"));
            }
            Ok(w.get()
                .world
                .add_obstacle(crate::world::Shape::Sphere { center, radius }) as INT)
        },
    );
    e.register_fn("add_box", |w: &mut WorldRef, min: Vec3, max: Vec3| -> INT {
        w.get()
            .world
            .add_obstacle(crate::world::Shape::Box(Aabb::new(min, max))) as INT
    });
    e.register_fn(
        "add_cylinder",
        |w: &mut WorldRef, base: Vec3, radius: FLOAT, height: FLOAT| -> R<INT> {
            if radius.is_nan() || radius <= 0.0 || height.is_nan() || height < 0.0 {
                return Err(error(
                    "a cylinder's radius must be positive and its height not negative",
                ));
            }
            Ok(w.get().world.add_obstacle(crate::world::Shape::Cylinder {
                base,
                radius,
                height,
            }) as INT)
        },
    );
    e.register_fn("remove_obstacle", |w: &mut WorldRef, id: INT| -> R<()> {
        let mut tw = w.get();
        let o = usize::try_from(id)
            .ok()
            .and_then(|i| tw.sim.world.obstacles.get_mut(i))
            .ok_or_else(|| error(format!("no obstacle {id}")))?;
        o.active = false;
        Ok(())
    });
    e.register_fn(
        "add_squad",
        |w: &mut WorldRef, species: &str, count: INT, start: Dynamic, goal: Dynamic| {
            add_squad(w, species, count, &start, &goal, &Map::new())
        },
    );
    e.register_fn(
        "add_squad",
        |w: &mut WorldRef, species: &str, count: INT, start: Dynamic, goal: Dynamic, opts: Map| {
            add_squad(w, species, count, &start, &goal, &opts)
        },
    );
    e.register_fn("step", |w: &mut WorldRef| step_world(w, 1));
    e.register_fn("step", |w: &mut WorldRef, n: INT| step_world(w, n));
    e.register_fn("run", |w: &mut WorldRef, seconds: FLOAT| {
        let dt = w.get().world.dt;
        step_world(w, (seconds / dt).round() as i64)
    });
    let c = ctx.clone();
    e.register_fn(
        "step_until",
        move |nc: NativeCallContext, w: &mut WorldRef, f: FnPtr, max: INT| -> R<bool> {
            let d = Dynamic::from(w.clone());
            for k in 0..=max.max(0) {
                if holds(&nc, &c.fn_params, &f, &d)? {
                    return Ok(true);
                }
                if k < max {
                    step_world(w, 1)?;
                }
            }
            Ok(false)
        },
    );
    e.register_get("tick", |w: &mut WorldRef| w.get().world.tick as INT)
        .register_get("time", |w: &mut WorldRef| w.get().world.time() as FLOAT)
        .register_get("dt", |w: &mut WorldRef| w.get().world.dt)
        .register_get("food", |w: &mut WorldRef| w.get().world.food.len() as INT)
        .register_get("agents", |w: &mut WorldRef| -> Array {
            let ids: Vec<AgentId> = w.get().world.agents.iter().map(|a| a.id).collect();
            ids.into_iter()
                .map(|id| {
                    Dynamic::from(AgentRef {
                        world: w.clone(),
                        id,
                    })
                })
                .collect()
        });
    e.register_fn("count", |w: &mut WorldRef, species: &str| -> INT {
        let tw = w.get();
        tw.sim
            .world
            .agents
            .iter()
            .filter(|a| tw.species[a.species.0 as usize].name == species)
            .count() as INT
    });
    e.register_indexer_get(|w: &mut WorldRef, name: &str| -> R<AgentRef> {
        let tw = w.get();
        let id = tw.named(name).ok_or_else(|| {
            let names: Vec<&str> = tw.names.values().map(String::as_str).collect();
            error(format!(
                "no agent named \"{name}\" (named agents: {})",
                if names.is_empty() {
                    "none; name one with `w.add_agent(species, pos, #{ name: \"...\" })`"
                        .to_string()
                } else {
                    names.join(", ")
                }
            ))
        })?;
        drop(tw);
        Ok(AgentRef {
            world: w.clone(),
            id,
        })
    });
    e.register_fn("agent", |w: &mut WorldRef, id: INT| -> R<AgentRef> {
        let id = AgentId(id.clamp(0, u32::MAX as i64) as u32);
        let tw = w.get();
        let known = tw
            .log
            .iter()
            .any(|l| matches!(l.event, Event::Spawn { agent, .. } if agent == id));
        drop(tw);
        if !known {
            return Err(error(format!("no agent with id {} in this world", id.0)));
        }
        Ok(AgentRef {
            world: w.clone(),
            id,
        })
    });
    e.register_fn("events", |w: &mut WorldRef| events(w, |_| true));
    e.register_fn("events", |w: &mut WorldRef, kind: &str| {
        events(w, |e| e.kind() == kind)
    });
    e.register_fn("to_string", |w: &mut WorldRef| {
        let tw = w.get();
        format!(
            "world at tick {} with {} agents and {} food",
            tw.sim.world.tick,
            tw.sim.world.agents.len(),
            tw.sim.world.food.len()
        )
    });

    // Agents.
    e.register_get("id", |a: &mut AgentRef| a.id.0 as INT)
        .register_get("name", |a: &mut AgentRef| {
            a.world.get().names.get(&a.id).cloned().unwrap_or_default()
        })
        .register_get("alive", |a: &mut AgentRef| {
            a.world.get().world.agent(a.id).is_some()
        })
        .register_get("species", |a: &mut AgentRef| -> R<String> {
            a.with(|tw, i| {
                tw.species[tw.sim.world.agents[i].species.0 as usize]
                    .name
                    .clone()
            })
        })
        .register_get("behavior", |a: &mut AgentRef| a.behavior())
        .register_get("stack", |a: &mut AgentRef| -> R<Array> {
            Ok(a.stack()?.into_iter().map(Dynamic::from).collect())
        })
        .register_get("stack_depth", |a: &mut AgentRef| -> R<INT> {
            a.with(|tw, i| tw.sim.world.agents[i].mind.depth as INT)
        })
        .register_get("time_in_behavior", |a: &mut AgentRef| -> R<FLOAT> {
            a.with(|tw, i| {
                tw.sim
                    .world
                    .tick
                    .saturating_sub(tw.sim.world.agents[i].mind.entered_tick) as f32
                    * tw.sim.world.dt
            })
        })
        .register_get("fwd", |a: &mut AgentRef| -> R<Vec3> {
            a.with(|tw, i| tw.sim.world.agents[i].forward())
        })
        .register_get("vel", |a: &mut AgentRef| -> R<Vec3> {
            a.with(|tw, i| tw.sim.world.agents[i].velocity())
        })
        .register_get("sex", |a: &mut AgentRef| -> R<String> {
            a.with(|tw, i| {
                if tw.sim.world.agents[i].attrs.sex == Sex::Male {
                    "male".to_string()
                } else {
                    "female".to_string()
                }
            })
        })
        .register_get("age", |a: &mut AgentRef| -> R<FLOAT> {
            a.with(|tw, i| tw.sim.world.agents[i].attrs.age)
        })
        .register_get("mass", |a: &mut AgentRef| -> R<FLOAT> {
            a.with(|tw, i| tw.sim.world.agents[i].attrs.mass)
        })
        .register_get("squad", |a: &mut AgentRef| squad_of(a))
        .register_get("heard", |a: &mut AgentRef| -> R<String> {
            a.with(|tw, i| {
                tw.sim.world.agents[i]
                    .inbox
                    .map_or(String::new(), |k| k.name().to_string())
            })
        });
    e.register_get_set(
        "pos",
        |a: &mut AgentRef| a.with(|tw, i| tw.sim.world.agents[i].pos),
        |a: &mut AgentRef, p: Vec3| {
            a.with_mut(|tw, i| {
                let p = tw.sim.world.bounds.closest_point(p);
                let ag = &mut tw.sim.world.agents[i];
                ag.pos = p;
                ag.prev_pos = p;
            })
        },
    );
    e.register_get_set(
        "yaw",
        |a: &mut AgentRef| a.with(|tw, i| tw.sim.world.agents[i].yaw.to_degrees()),
        |a: &mut AgentRef, deg: FLOAT| {
            a.with_mut(|tw, i| tw.sim.world.agents[i].yaw = frame::wrap(deg.to_radians()))
        },
    );
    e.register_get_set(
        "pitch",
        |a: &mut AgentRef| a.with(|tw, i| tw.sim.world.agents[i].pitch.to_degrees()),
        |a: &mut AgentRef, deg: FLOAT| {
            a.with_mut(|tw, i| {
                tw.sim.world.agents[i].pitch = deg
                    .to_radians()
                    .clamp(-frame::PITCH_LIMIT, frame::PITCH_LIMIT)
            })
        },
    );
    e.register_get_set(
        "speed",
        |a: &mut AgentRef| a.with(|tw, i| tw.sim.world.agents[i].speed),
        |a: &mut AgentRef, v: FLOAT| a.with_mut(|tw, i| tw.sim.world.agents[i].speed = v.max(0.0)),
    );
    e.register_get_set(
        "hunger",
        |a: &mut AgentRef| a.with(|tw, i| tw.sim.world.agents[i].drives.hunger),
        |a: &mut AgentRef, v: FLOAT| a.with_mut(|tw, i| set_hunger(tw, i, v)),
    );
    e.register_get_set(
        "libido",
        |a: &mut AgentRef| a.with(|tw, i| tw.sim.world.agents[i].drives.libido),
        |a: &mut AgentRef, v: FLOAT| a.with_mut(|tw, i| set_libido(tw, i, v)),
    );
    e.register_get_set(
        "fear",
        |a: &mut AgentRef| a.with(|tw, i| tw.sim.world.agents[i].drives.fear),
        |a: &mut AgentRef, v: FLOAT| {
            a.with_mut(|tw, i| tw.sim.world.agents[i].drives.fear = v.clamp(0.0, 1.0))
        },
    );
    e.register_get_set(
        "fatigue",
        |a: &mut AgentRef| a.with(|tw, i| tw.sim.world.agents[i].drives.fatigue),
        |a: &mut AgentRef, v: FLOAT| {
            a.with_mut(|tw, i| tw.sim.world.agents[i].drives.fatigue = v.clamp(0.0, 1.0))
        },
    );
    e.register_fn("force_behavior", |a: &mut AgentRef, name: &str| -> R<()> {
        let mut tw = a.world.get();
        tw.index(a.id).map_err(error)?;
        tw.check_behavior(a.id, name).map_err(error)?;
        let set = tw.sim.pipeline.species.clone();
        if let Some(ev) = crate::tick::force_behavior(&mut tw.sim.world, &set, a.id, name) {
            tw.sim.pipeline.events.push(ev);
        }
        Ok(())
    });
    e.register_indexer_get(|a: &mut AgentRef, key: &str| -> R<Dynamic> {
        a.with(|tw, i| {
            tw.sim.world.agents[i]
                .memory
                .iter()
                .find(|(k, _)| k == key)
                .map_or(Dynamic::UNIT, |(_, v)| from_mem(v))
        })
    });
    e.register_indexer_set(|a: &mut AgentRef, key: &str, v: Dynamic| -> R<()> {
        let v = to_mem(v)?;
        a.with_mut(|tw, i| {
            let mem = &mut tw.sim.world.agents[i].memory;
            match mem.binary_search_by(|(k, _)| k.as_str().cmp(key)) {
                Ok(j) => {
                    mem[j].1 = v;
                    Ok(())
                }
                Err(_) if mem.len() >= MEMORY_CAPACITY => {
                    Err(error(format!("memory is full ({MEMORY_CAPACITY} keys)")))
                }
                Err(j) => {
                    mem.insert(j, (key.to_string(), v));
                    Ok(())
                }
            }
        })?
    });
    e.register_fn("has", |a: &mut AgentRef, key: &str| -> R<bool> {
        a.with(|tw, i| tw.sim.world.agents[i].memory.iter().any(|(k, _)| k == key))
    });
    e.register_fn("transitions", |a: &mut AgentRef| {
        let id = a.id;
        events(
            &a.world,
            |e| matches!(e, Event::Transition { agent, .. } if *agent == id),
        )
    });
    e.register_fn("events", |a: &mut AgentRef| {
        let id = a.id;
        events(&a.world, |e| involves(e, id))
    });
    e.register_fn("events", |a: &mut AgentRef, kind: &str| {
        let id = a.id;
        events(&a.world, |e| e.kind() == kind && involves(e, id))
    });
    e.register_fn("meals", |a: &mut AgentRef| -> INT {
        let id = a.id;
        events(
            &a.world,
            |e| matches!(e, Event::Meal { agent, .. } if *agent == id),
        )
        .len() as INT
    });
    e.register_fn("catches", |a: &mut AgentRef| -> INT {
        let id = a.id;
        events(
            &a.world,
            |e| matches!(e, Event::Catch { agent, .. } if *agent == id),
        )
        .len() as INT
    });
    e.register_fn("percepts", |a: &mut AgentRef, what: &str| -> R<Map> {
        let c = category(what)?;
        a.with(|tw, i| {
            let p = tw.sim.pipeline.perception();
            let mut m = Map::new();
            let (count, seen, dist) = if i < p.len() && p.len() == tw.sim.world.agents.len() {
                let s = p.summaries(i)[c as usize];
                (s.count as INT, s.seen as INT, s.nearest_dist)
            } else {
                (0, 0, f32::INFINITY)
            };
            m.insert("count".into(), Dynamic::from(count));
            m.insert("seen".into(), Dynamic::from(seen));
            m.insert(
                "nearest_dist".into(),
                Dynamic::from(if dist.is_finite() { dist } else { 1e30 }),
            );
            m
        })
    });
    e.register_fn("perceive", |a: &mut AgentRef, list: Array| -> R<()> {
        let feeds = list.iter().map(feed).collect::<R<Vec<_>>>()?;
        perceive(a, feeds)
    });
    e.register_fn("perceive", |a: &mut AgentRef, one: Map| -> R<()> {
        perceive(a, vec![feed(&Dynamic::from(one))?])
    });
    e.register_fn("perceive_world", |a: &mut AgentRef| {
        a.world.get().feeds.remove(&a.id);
    });
    e.register_fn("to_string", |a: &mut AgentRef| a.label());

    // Assertions.
    let c = ctx.clone();
    e.register_fn("assert", move |ok: bool| -> R<()> {
        if ok {
            Ok(())
        } else {
            Err(raise(Kind::Fail, "assertion failed", last_context(&c)))
        }
    });
    let c = ctx.clone();
    e.register_fn("assert", move |ok: bool, msg: &str| -> R<()> {
        if ok {
            Ok(())
        } else {
            Err(raise(Kind::Fail, msg, last_context(&c)))
        }
    });
    let c = ctx.clone();
    e.register_fn("assert_eq", move |a: Dynamic, b: Dynamic| -> R<()> {
        if same(&a, &b) {
            Ok(())
        } else {
            Err(raise(
                Kind::Fail,
                format!("expected {}, got {}", show(&b), show(&a)),
                last_context(&c),
            ))
        }
    });
    let c = ctx.clone();
    e.register_fn(
        "assert_eq",
        move |a: Dynamic, b: Dynamic, msg: &str| -> R<()> {
            if same(&a, &b) {
                Ok(())
            } else {
                Err(raise(
                    Kind::Fail,
                    format!("{msg}: expected {}, got {}", show(&b), show(&a)),
                    last_context(&c),
                ))
            }
        },
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_near",
        move |a: Dynamic, b: Dynamic, tol: Dynamic| -> R<()> {
            let (ok, off) = near(&a, &b, &tol)?;
            if ok {
                Ok(())
            } else {
                Err(raise(
                    Kind::Fail,
                    format!(
                        "expected {} ± {}, got {} (off by {off})",
                        show(&b),
                        show(&tol),
                        show(&a)
                    ),
                    last_context(&c),
                ))
            }
        },
    );
    e.register_fn("assert_behavior", |a: AgentRef, name: &str| -> R<()> {
        a.world.get().check_behavior(a.id, name).map_err(error)?;
        let now = a.behavior()?;
        if now == name {
            return Ok(());
        }
        Err(raise(
            Kind::Fail,
            format!("expected {} in `{name}`, but it is in `{now}`", a.label()),
            a.decisions(),
        ))
    });
    e.register_fn("assert_stack", |a: AgentRef, names: Array| -> R<()> {
        let want = strings(&names, "stack")?;
        for n in &want {
            a.world.get().check_behavior(a.id, n).map_err(error)?;
        }
        let now = a.stack()?;
        if now == want {
            return Ok(());
        }
        Err(raise(
            Kind::Fail,
            format!(
                "expected the stack of {} to be [{}] (bottom first), but it is [{}]",
                a.label(),
                want.join(", "),
                now.join(", ")
            ),
            a.decisions(),
        ))
    });
    e.register_fn(
        "assert_behavior_within",
        |a: AgentRef, name: &str, ticks: INT| -> R<()> {
            a.world.get().check_behavior(a.id, name).map_err(error)?;
            for k in 0..=ticks.max(0) {
                if a.behavior()? == name {
                    return Ok(());
                }
                if k < ticks {
                    step_world(&a.world, 1)?;
                }
            }
            let now = a.behavior()?;
            Err(raise(
                Kind::Fail,
                format!(
                    "expected {} in `{name}` within {}, but it is in `{now}`",
                    a.label(),
                    ticks_text(&a.world, ticks.max(0) as u64)
                ),
                a.decisions(),
            ))
        },
    );
    let transition = |a: AgentRef, from: &str, to: &str, cause: Option<&str>| -> R<()> {
        {
            let tw = a.world.get();
            tw.check_behavior(a.id, from).map_err(error)?;
            tw.check_behavior(a.id, to).map_err(error)?;
        }
        let causes = [
            Cause::Activated,
            Cause::Interrupted,
            Cause::Completed,
            Cause::Resumed,
            Cause::Fallback,
            Cause::Script,
        ];
        if let Some(c) = cause {
            if !causes.iter().any(|x| x.name() == c) {
                return Err(error(format!(
                    "unknown cause \"{c}\": expected one of {}",
                    causes.map(|x| x.name()).join(", ")
                )));
            }
        }
        let id = a.id;
        let found = {
            let tw = a.world.get();
            tw.log.iter().any(|l| match &l.event {
                Event::Transition {
                    agent,
                    species,
                    from: f,
                    to: t,
                    cause: c,
                    ..
                } if *agent == id => {
                    let sp = &tw.species[*species as usize];
                    sp.behavior_name(*f) == from
                        && sp.behavior_name(*t) == to
                        && cause.is_none_or(|x| x == c.name())
                }
                _ => false,
            })
        };
        if found {
            return Ok(());
        }
        Err(raise(
            Kind::Fail,
            format!(
                "expected {} to have gone from `{from}` to `{to}`{}, but it never did",
                a.label(),
                cause.map_or(String::new(), |c| format!(" ({c})"))
            ),
            a.decisions(),
        ))
    };
    e.register_fn(
        "assert_transition",
        move |a: AgentRef, from: &str, to: &str| transition(a, from, to, None),
    );
    e.register_fn(
        "assert_transition",
        move |a: AgentRef, from: &str, to: &str, cause: &str| transition(a, from, to, Some(cause)),
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_within",
        move |nc: NativeCallContext, w: WorldRef, ticks: INT, f: FnPtr| {
            assert_within(&nc, &c.fn_params, Subject::World(w), ticks, f)
        },
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_within",
        move |nc: NativeCallContext, a: AgentRef, ticks: INT, f: FnPtr| {
            assert_within(&nc, &c.fn_params, Subject::Agent(a), ticks, f)
        },
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_always",
        move |nc: NativeCallContext, w: WorldRef, ticks: INT, f: FnPtr| {
            assert_always(&nc, &c.fn_params, Subject::World(w), ticks, f)
        },
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_always",
        move |nc: NativeCallContext, a: AgentRef, ticks: INT, f: FnPtr| {
            assert_always(&nc, &c.fn_params, Subject::Agent(a), ticks, f)
        },
    );
    let c = ctx.clone();
    e.register_fn("fail", move |msg: &str| -> R<()> {
        Err(raise(Kind::Fail, msg, last_context(&c)))
    });
    e.register_fn("skip", |msg: &str| -> R<()> {
        Err(raise(Kind::Skip, msg, String::new()))
    });
    let c = ctx;
    e.on_print(move |s| {
        let mut o = lock(&c.output);
        if o.len() < 64 * 1024 {
            o.push_str(s);
            o.push('\n');
        }
    });
}
