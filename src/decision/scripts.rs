//! Script calls of the decision stage: at the species' decision rate (staggered by agent id),
//! each script function the species uses is called with the agent's [`AgentView`] bound as
//! `this`, and its result cached in the agent's [`Mind`] for the native evaluators. A failing call
//! leaves the last valid values in place.

use super::Ctx;
use crate::diag::Diagnostic;
use crate::frame;
use crate::script::{AgentView, Script, ScriptSteer};
use crate::species::{SlotKind, Species};
use crate::world::{Agent, Mind, Sex};
use rhai::{Dynamic, ImmutableString, Scope};
use std::sync::Arc;

/// Whether agent `id` runs its scripts on `tick` (staggered: one agent in `interval` per tick).
#[inline]
pub fn due(tick: u64, id: u32, interval: u32) -> bool {
    interval <= 1 || (tick + id as u64).is_multiple_of(interval as u64)
}

/// Builds the script view of an agent.
pub fn view_of(
    ctx: &Ctx,
    mind: &Mind,
    species_name: &ImmutableString,
    behavior: &ImmutableString,
) -> AgentView {
    let mut v = AgentView::default();
    fill_view(&mut v, ctx, mind, species_name, behavior);
    v
}

/// Refills an existing view in place for another call (what [`view_of`] builds, without
/// allocating: strings and the recipe list are shared, the agent's blackboard is copied into the
/// view's, reusing its keys' and strings' room, and the outbox is emptied).
pub fn fill_view(
    v: &mut AgentView,
    ctx: &Ctx,
    mind: &Mind,
    species_name: &ImmutableString,
    behavior: &ImmutableString,
) {
    fill_scalars(v, ctx, mind, species_name, behavior);
    let a: &Agent = ctx.agent;
    match a.inbox.heard() {
        // A declared event: its name (shared by the species) and its payload.
        Some(h) => {
            let name = ctx
                .species
                .signal_name(crate::world::Signal::Event(h.event));
            if v.heard.as_str() != name {
                v.heard = ImmutableString::from(name);
            }
            v.heard_payload = ctx.world.event_payloads.get(h.payload as usize).cloned();
        }
        None => {
            let heard = a.inbox.kind().map_or("", |k| k.name());
            if v.heard.as_str() != heard {
                v.heard = shared_name(heard);
            }
            v.heard_payload = None;
        }
    }
    crate::script::memory::copy_blackboard(&mut v.memory, &a.memory);
    v.rng = a.rng;
    v.outbox.clear();
    if !Arc::ptr_eq(&v.recipes, &ctx.species.recipe_names) {
        v.recipes = ctx.species.recipe_names.clone();
    }
    if !Arc::ptr_eq(&v.events, &ctx.species.events) {
        v.events = ctx.species.events.clone();
    }
    v.drives_written = false;
    v.terrain = ctx.world.terrain.clone();
}

/// Fills the view for a call of the species' slots: what native evaluation reads when every
/// slot is native ([`Species::scripts_native`]), else everything.
pub fn fill_for_slots(
    v: &mut AgentView,
    ctx: &Ctx,
    mind: &Mind,
    species_name: &ImmutableString,
    behavior: &ImmutableString,
) {
    if ctx.species.scripts_native {
        fill_native(v, ctx, mind);
        if ctx.species.natives_read_memory {
            crate::script::memory::copy_blackboard(&mut v.memory, &ctx.agent.memory);
        }
    } else {
        fill_view(v, ctx, mind, species_name, behavior);
    }
}

/// Fills what a natively evaluated function reads ([`crate::script::native`]'s properties):
/// the agent's scalars, each category's counts and nearest distance, bearing, elevation and
/// strength, and its squad with its position. For a species whose every slot is native
/// ([`Species::scripts_native`]) nothing else is read and nothing is written back; the rest of
/// the view keeps what the worker's last call left there. Not the headings, positions and
/// sectors of the percepts, the velocity and forward vector, the foraging places (two values
/// boxed afresh), names and sex: for a reef fish, about 230 instructions a call against the
/// full scalars' 1,600.
fn fill_native(v: &mut AgentView, ctx: &Ctx, mind: &Mind) {
    let a: &Agent = ctx.agent;
    let strength = ctx.species.senses.strength;
    for (cv, s) in v.cats.iter_mut().zip(ctx.summaries.iter()) {
        let near = s.nearest.map(|k| &ctx.percepts[k as usize]);
        cv.count = s.count as i64;
        cv.seen = s.seen as i64;
        cv.nearest_dist = if s.nearest_dist.is_finite() {
            s.nearest_dist
        } else {
            1e30
        };
        cv.nearest_bearing = near.map_or(0.0, |p| p.bearing);
        cv.nearest_elevation = near.map_or(0.0, |p| p.elevation);
        cv.strength = strength;
    }
    v.id = a.id.0 as i64;
    v.tick = ctx.tick as i64;
    v.time = ctx.tick as f32 * ctx.dt;
    v.dt = ctx.dt;
    v.pos = a.pos;
    v.speed = a.speed;
    v.max_speed = ctx.species.body.limits.max_speed;
    v.hunger = a.drives.hunger;
    v.libido = a.drives.libido;
    v.fear = a.drives.fear;
    v.fatigue = a.drives.fatigue;
    v.state = a.drives.state;
    v.time_in_behavior = ctx.time_in_behavior(mind);
    v.stack_depth = mind.depth as i64;
    v.age = a.attrs.age;
    v.mass = a.attrs.mass;
    v.kind = a.attrs.kind as i64;
    v.squad = ctx.world.squads.as_ref().and_then(|b| b.view(a.id));
}

/// Fills the agent's scalars, its percept summaries and its squad: the part of the full view
/// ([`fill_view`]) that is not its blackboard, messages or random stream. What native
/// evaluation reads first, then the rest.
fn fill_scalars(
    v: &mut AgentView,
    ctx: &Ctx,
    mind: &Mind,
    species_name: &ImmutableString,
    behavior: &ImmutableString,
) {
    fill_native(v, ctx, mind);
    let a: &Agent = ctx.agent;
    let senses = &ctx.species.senses;
    for (cv, s) in v.cats.iter_mut().zip(ctx.summaries.iter()) {
        let near = s.nearest.map(|k| &ctx.percepts[k as usize]);
        cv.nearest_pos = near.map_or(a.pos, |p| a.pos + p.offset);
        cv.nearest_sector = near.map(|p| senses.sectors.horizontal(p.bearing));
        cv.nearest_level = near.map(|p| senses.sectors.vertical(p.elevation));
        cv.centroid = s.centroid;
        cv.mean_heading = s.mean_heading;
        cv.mean_velocity = s.mean_velocity;
    }
    if !v.species.ptr_eq(species_name) {
        v.species = species_name.clone();
    }
    v.vel = a.velocity();
    v.fwd = frame::forward(a.yaw, a.pitch);
    let point = |p: Option<glam::Vec3>| p.map_or(Dynamic::UNIT, Dynamic::from);
    v.best_food = point(mind.best_food());
    v.school_best = point(mind.school_best());
    if !v.behavior.ptr_eq(behavior) {
        v.behavior = behavior.clone();
    }
    let sex = if a.attrs.sex == Sex::Male {
        "male"
    } else {
        "female"
    };
    if v.sex.as_str() != sex {
        v.sex = shared_name(sex);
    }
    v.eye_height = ctx.species.body.size.y;
}

/// The few fixed names a view holds ("male", "female", message kinds), built once per thread and
/// shared, so that refilling a view does not allocate.
fn shared_name(name: &'static str) -> ImmutableString {
    thread_local! {
        static NAMES: std::cell::RefCell<Vec<ImmutableString>> =
            const { std::cell::RefCell::new(Vec::new()) };
    }
    NAMES.with(|names| {
        let mut names = names.borrow_mut();
        if let Some(n) = names.iter().find(|n| n.as_str() == name) {
            return n.clone();
        }
        let n = ImmutableString::from(name);
        names.push(n.clone());
        n
    })
}

/// Converts a script's return value into a number for a slot.
fn as_number(d: &Dynamic, kind: SlotKind) -> Option<f32> {
    match kind {
        SlotKind::Bool => d.as_bool().ok().map(|b| if b { 1.0 } else { 0.0 }),
        SlotKind::Number => d
            .as_float()
            .ok()
            .or_else(|| d.as_int().ok().map(|i| i as f32)),
        SlotKind::Steer => None,
    }
}

/// Runs every script slot of the species for one agent, updating `mind` and the bound view.
/// Returns the first error, located in the script.
pub fn run_slots(
    species: &Species,
    script: &Script,
    mind: &mut Mind,
    this: &mut Dynamic,
    scope: &mut Scope,
) -> Result<(), Diagnostic> {
    run_slots_of(species, script, mind, this, scope, true)
}

/// Runs only the condition and value slots (no steering, no `on_tick`): what arbitration reads,
/// asked again off schedule (right after a contact) without moving the script's own schedule.
pub fn run_conditions(
    species: &Species,
    script: &Script,
    mind: &mut Mind,
    this: &mut Dynamic,
    scope: &mut Scope,
) -> Result<(), Diagnostic> {
    run_slots_of(species, script, mind, this, scope, false)
}

fn run_slots_of(
    species: &Species,
    script: &Script,
    mind: &mut Mind,
    this: &mut Dynamic,
    scope: &mut Scope,
    all: bool,
) -> Result<(), Diagnostic> {
    if mind.script_values.len() < species.slots.len() {
        mind.script_values.resize(species.slots.len(), 0.0);
    }
    if mind.script_steer.len() < species.steer_slots {
        mind.script_steer.resize(species.steer_slots, Vec::new());
    }
    for (i, slot) in species.slots.iter().enumerate() {
        if !all && slot.kind == SlotKind::Steer {
            continue;
        }
        // A condition or value of one expression is evaluated natively (the same result);
        // an integer overflow in it goes back to the interpreter, which raises the error.
        let native = match script.native(&slot.name) {
            Some(f) if slot.kind != SlotKind::Steer => this
                .read_lock::<AgentView>()
                .and_then(|v| f.eval(&v).ok())
                .map(|x| x.to_dynamic()),
            _ => None,
        };
        let r: Dynamic = match native {
            Some(r) => r,
            None => script
                .call(scope, this, &slot.name)
                .map_err(|e| *e.diagnostic)?,
        };
        // Located only when something is wrong: finding the line costs a text search.
        let bad = |what: String| {
            let (line, col) = script.fn_position(&slot.name);
            Diagnostic::new(&script.file, line, col, what, Some(&script.text))
        };
        match slot.kind {
            SlotKind::Steer => {
                let Some(s) = r.clone().try_cast::<ScriptSteer>() else {
                    return Err(bad(format!(
                        "`{}()` must return a steering value (e.g. `this.seek(p)`, `this.recipe(\"name\")`), not {}",
                        slot.name,
                        r.type_name()
                    )));
                };
                let finite = s.terms.iter().all(|(w, t)| {
                    w.is_finite()
                        && match t {
                            crate::steering::Term::Recipe(_) => true,
                            crate::steering::Term::Velocity(v) => v.is_finite(),
                            crate::steering::Term::Turn(a, b, c) => {
                                a.is_finite() && b.is_finite() && c.is_finite()
                            }
                        }
                });
                if !finite {
                    return Err(bad(format!(
                        "`{}()` returned a steering value that is not finite (NaN or infinity)",
                        slot.name
                    )));
                }
                mind.script_steer[slot.index as usize] = s.terms;
            }
            kind => match as_number(&r, kind) {
                Some(v) if v.is_finite() => mind.script_values[i] = v,
                Some(_) => {
                    return Err(bad(format!(
                        "`{}()` returned a number that is not finite (NaN or infinity)",
                        slot.name
                    )))
                }
                None => {
                    return Err(bad(format!(
                        "`{}()` must return {}, not {}",
                        slot.name,
                        if kind == SlotKind::Bool {
                            "a bool"
                        } else {
                            "a number"
                        },
                        r.type_name()
                    )))
                }
            },
        }
    }
    if all && species.has_on_tick {
        // Evaluated natively where it can be (the same writes); handed back, the interpreter
        // runs it from the start (a hand-back changes nothing).
        let native = script.native_on_tick().and_then(|f| {
            this.write_lock::<AgentView>()
                .map(|mut v| f.run(&mut v).is_ok())
        });
        if native != Some(true) {
            let _: Dynamic = script
                .call(scope, this, "on_tick")
                .map_err(|e| *e.diagnostic)?;
        }
    }
    Ok(())
}

/// Copies what a script may change from the view back to the agent.
pub fn write_back(view: &AgentView, agent: &mut Agent) {
    if view.drives_written {
        agent.drives.hunger = view.hunger;
        agent.drives.libido = view.libido;
        agent.drives.fear = view.fear;
        agent.drives.fatigue = view.fatigue;
    }
    crate::script::memory::copy_blackboard(&mut agent.memory, &view.memory);
    // A blackboard holds a few keys: no room kept for more (a growing Vec would reserve four).
    if agent.memory.capacity() > agent.memory.len() {
        agent.memory.shrink_to_fit();
    }
    agent.rng = view.rng;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::{world_of, Workload};
    use crate::perception::{Category, GroupQueries, PerceptBuf, Strength};
    use crate::scenario::{Overrides, Run, Scenario};
    use crate::script::native::every_property;
    use crate::species::Species;

    /// A view whose every field native evaluation reads holds a value no agent has (the squad
    /// none: the squad world below has one for every member).
    fn stale() -> AgentView {
        let mut v = AgentView {
            id: -7,
            tick: -7,
            time: -7.5,
            dt: -7.5,
            pos: glam::Vec3::splat(-7.5),
            speed: -7.5,
            max_speed: -7.5,
            hunger: -7.5,
            libido: -7.5,
            fear: -7.5,
            fatigue: -7.5,
            state: -7.5,
            time_in_behavior: -7.5,
            stack_depth: -7,
            age: -7.5,
            mass: -7.5,
            kind: -7,
            ..Default::default()
        };
        for c in v.cats.iter_mut() {
            (c.count, c.seen) = (1_000_007, 1_000_007);
            (c.nearest_dist, c.nearest_bearing, c.nearest_elevation) = (-7.5, -7.5, -7.5);
            c.strength = Strength {
                power: 7.0,
                near: 7.0,
            };
        }
        v
    }

    /// For every agent of `sim` whose species `fill` takes: its view filled by `fill` over a
    /// stale one reads every native property as the full view does. Returns how many agents,
    /// category nearests and squad members it compared.
    fn compare(
        sim: &crate::sim::Sim,
        fill: impl Fn(&Species, &mut AgentView, &Ctx, &Mind) -> bool,
    ) -> (usize, usize, usize) {
        let (world, perception) = (&sim.world, sim.pipeline.perception());
        let set = sim.pipeline.species.clone();
        let (name, behavior) = (ImmutableString::from("s"), ImmutableString::from("b"));
        let mut buf = PerceptBuf::default();
        let (mut agents, mut nearest, mut in_squad) = (0, 0, 0);
        for (i, a) in world.agents.iter().enumerate() {
            let sp = &set.species[a.species.0 as usize];
            let summaries = perception.summaries(i);
            let ctx = Ctx {
                world,
                perception,
                species: sp,
                agent: a,
                percepts: perception.percepts_in(i, &mut buf),
                summaries: &summaries,
                group_queries: &GroupQueries::EMPTY,
                group_sums: &[],
                tick: world.tick,
                dt: world.dt,
            };
            let mut native = stale();
            if !fill(sp, &mut native, &ctx, &a.mind) {
                continue;
            }
            let mut full = AgentView::default();
            fill_view(&mut full, &ctx, &a.mind, &name, &behavior);
            let (f, n) = (every_property(&full), every_property(&native));
            assert_eq!(format!("{f:?}"), format!("{n:?}"), "agent {i}");
            agents += 1;
            nearest += summaries.iter().filter(|s| s.nearest.is_some()).count();
            in_squad += full.squad.is_some() as usize;
            // The stale view reads differently, so the comparison can fail: the 16 scalars
            // before the squad's four, and of each category (7 properties from 20 on) its
            // count, seen and nearest distance.
            let s = every_property(&stale());
            let differs = |k: usize| format!("{:?}", f[k]) != format!("{:?}", s[k]);
            assert!((0..16).all(differs), "agent {i}");
            let mut of_categories =
                (0..Category::COUNT).flat_map(|c| [0, 1, 3].map(|p| 20 + 7 * c + p));
            assert!(of_categories.all(differs), "agent {i}");
        }
        (agents, nearest, in_squad)
    }

    #[test]
    fn a_view_filled_for_native_slots_reads_as_the_full_view() {
        // Reef fish: every slot native, filled as the agent pass fills them. After a few ticks
        // they perceive kin, food, rocks and sharks, so each category's nearest is read from
        // real percepts.
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors");
        let mut b = world_of(Workload::Reef, 300, &dir).unwrap();
        for _ in 0..5 {
            b.run.step();
        }
        let (agents, nearest, _) = compare(&b.run.sim, |sp, v, ctx, mind| {
            let name = ImmutableString::from("s");
            sp.scripts_native && {
                fill_for_slots(v, ctx, mind, &name, &name);
                true
            }
        });
        assert!(agents > 200 && nearest > 200, "{agents} {nearest}");
        // Squad members (their `on_tick` is interpreted, so the pass fills them whole): the
        // native fill alone gives their squad properties too.
        let sc = Scenario::load(std::path::Path::new("scenarios/squad_march.ron")).unwrap();
        let o = Overrides {
            seed: None,
            duration: Some(5.0),
            set: Vec::new(),
        };
        let mut run = Run::new(sc, o);
        for _ in 0..5 {
            run.step();
        }
        let (agents, _, in_squad) = compare(&run.sim, |sp, v, ctx, mind| {
            sp.script.is_some() && {
                fill_native(v, ctx, mind);
                true
            }
        });
        assert!(agents >= 4 && in_squad == agents, "{agents} {in_squad}");
    }
}
