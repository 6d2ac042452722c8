//! Building a test world: `world()` with its options (bounds, seed, `dt`, current, a terrain
//! file or a flat terrain built in the test), agents with their state (`add_agent`), food,
//! rocks, boxes and cylinders, and squads. Everything a test places is checked against the
//! world's bounds and the species' behaviors.

use super::agents::{set_hunger, set_libido};
use super::args::{check_keys, int, num, string, strings, vec3, xz};
use super::{AgentRef, TestCtx, WorldRef, DEFAULT_BOUNDS, R};
use crate::script::memory::store;
use crate::script::to_mem;
use crate::species::SexDef;
use crate::terrain::{load_asc, Cell, CellAttrs, Terrain};
use crate::testing::failure::error;
use crate::testing::world::{lock, TestWorld};
use crate::world::{Aabb, Sex};
use glam::{Vec2, Vec3};
use rhai::{Array, Dynamic, Engine, Map, FLOAT, INT};
use std::sync::{Arc, Mutex};

/// Registers the world builders: `world()`, `add_agent`, `add_food`, `add_rock`, `add_box`,
/// `add_cylinder`, `remove_obstacle`, `add_squad`.
pub(super) fn register(e: &mut Engine, ctx: &Arc<TestCtx>) {
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
                "unknown behavior \"{n}\" of species \"{}\"{}: expected one of {}",
                sp.name,
                crate::load::did_you_mean(n, known.iter().copied()),
                known.join(", ")
            ))
        })
    };
    if let Some(d) = opts.get("behavior") {
        // A composed behavior starts in its first part.
        a.mind.current = crate::species::validate::first_leaf(
            &sp.behaviors,
            behavior_of(&string(d, "behavior")?)?,
        );
    }
    if let Some(d) = opts.get("stack") {
        let arr = d
            .clone()
            .try_cast::<Array>()
            .ok_or_else(|| error("`stack` must be an array of behavior names, bottom first"))?;
        for n in strings(&arr, "stack")? {
            let b = crate::species::validate::first_leaf(&sp.behaviors, behavior_of(&n)?);
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
            sp.memory.check_write(&k, &v).map_err(error)?;
            store(&mut a.memory, &k, v, &sp.memory).map_err(error)?;
        }
    }
    drop(tw);
    Ok(AgentRef {
        world: w.clone(),
        id,
    })
}
