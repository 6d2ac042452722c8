//! JSON forms of events and of the world description, shared by the recorder and the live
//! viewer.

use crate::events::Event;
use crate::scenario::Run;
use crate::species::SpeciesSet;
use crate::world::Shape;
use serde_json::{json, Value};

/// One event as a JSON object with `tick`, `time`, `kind` and its fields, names resolved.
pub fn event_json(e: &Event, tick: u64, dt: f32, set: &SpeciesSet) -> Value {
    let time = tick as f64 * dt as f64;
    let sname = |s: u16| {
        set.species
            .get(s as usize)
            .map_or("?", |x| x.name.as_str())
            .to_string()
    };
    let bname = |s: u16, b: u16| {
        set.species
            .get(s as usize)
            .map_or("?", |x| x.behavior_name(b))
            .to_string()
    };
    let mut v = match e {
        Event::Spawn { agent, species } => json!({"agent": agent.0, "species": sname(*species)}),
        Event::Death {
            agent,
            species,
            cause,
        } => json!({"agent": agent.0, "species": sname(*species), "cause": cause}),
        Event::Meal { agent, food } => json!({"agent": agent.0, "food": food}),
        Event::Catch { agent, prey } => json!({"agent": agent.0, "prey": prey.0}),
        Event::Mating { agent, mate } => json!({"agent": agent.0, "mate": mate.0}),
        Event::Transition {
            agent,
            species,
            from,
            to,
            cause,
            condition,
            stack,
        } => json!({
            "agent": agent.0,
            "species": sname(*species),
            "from": bname(*species, *from),
            "to": bname(*species, *to),
            "cause": cause.name(),
            "condition": condition.as_deref(),
            "stack": stack.iter().map(|b| bname(*species, *b)).collect::<Vec<_>>(),
        }),
        Event::Message { from, kind, radius } => {
            json!({"from": from.0, "kind": kind.name(), "radius": radius})
        }
        Event::Named {
            from,
            name,
            payload,
            radius,
        } => {
            let fields: serde_json::Map<String, Value> = payload
                .iter()
                .map(|(k, v)| (k.to_string(), mem_json(v)))
                .collect();
            json!({"from": from.0, "message": &**name, "payload": fields, "radius": radius})
        }
        Event::ScriptError {
            agent,
            species,
            message,
        } => {
            json!({"agent": agent.0, "species": sname(*species), "message": message})
        }
    };
    let obj = v.as_object_mut().expect("object");
    // Message events carry their own `kind`; name the event kind first.
    let mut out = serde_json::Map::new();
    out.insert("tick".into(), json!(tick));
    out.insert("time".into(), json!(time));
    out.insert("kind".into(), json!(e.kind()));
    if let Event::Message { kind, .. } = e {
        obj.remove("kind");
        out.insert("message".into(), json!(kind.name()));
    }
    out.extend(std::mem::take(obj));
    Value::Object(out)
}

/// A payload field as JSON (a vector as `[x, y, z]`).
fn mem_json(v: &crate::world::MemValue) -> Value {
    use crate::world::MemValue;
    match v {
        MemValue::Bool(b) => json!(b),
        MemValue::Int(i) => json!(i),
        MemValue::Float(f) => json!(f),
        MemValue::Vec3(x) => json!([x.x, x.y, x.z]),
        MemValue::Str(s) => json!(s),
    }
}

/// Per behavior of `s`, in the order of its `behaviors` names, what the viewer's state-machine
/// graph draws: priority level, whether an equal level may interrupt it, its `when` and `done`
/// text, whether it is the initial behavior, and where its name is written (`file:line:col`).
/// A part of a composed behavior is drawn on the level of the behavior of the species' list
/// that holds it, and names what it is part of (`parent`), its `fail` and its kind.
pub fn behavior_info(s: &crate::species::Species) -> Vec<Value> {
    use crate::species::Compose;
    let root = |i: usize| {
        crate::species::validate::ancestors(&s.behaviors, i as u16)
            .last()
            .map_or(i, |r| r as usize)
    };
    s.behaviors
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let (line, col) = b.source;
            let kind = match b.compose {
                Compose::Leaf => "leaf",
                Compose::Select => "behaviors",
                Compose::Sequence => "sequence",
                Compose::Fallback => "fallback",
            };
            json!({
                "priority": s.behaviors[root(i)].priority,
                "parent": b.parent.map(|p| s.behavior_name(p)),
                "kind": kind,
                "fail": &*b.fail_text,
                "equal_may_interrupt": b.equal_may_interrupt,
                "when": &*b.when_text,
                "done": &*b.done_text,
                "initial": i == s.initial as usize,
                "source": format!("{}:{line}:{col}", s.file.display()),
            })
        })
        .collect()
}

/// The world description of `world.json`: bounds, obstacles (with the tick each was removed at),
/// species with colors and behavior names, terrain and the squads' plans.
pub fn world_json(run: &Run, removed: &[Option<u64>]) -> Value {
    let w = &run.world;
    let obstacles: Vec<Value> = w
        .obstacles
        .iter()
        .enumerate()
        .map(|(k, o)| {
            let removed_tick = removed.get(k).copied().flatten();
            match o.shape {
                Shape::Sphere { center, radius } => json!({
                    "id": o.id, "shape": "sphere", "center": center.to_array(), "radius": radius, "removed_tick": removed_tick
                }),
                Shape::Box(b) => json!({
                    "id": o.id, "shape": "box", "min": b.min.to_array(), "max": b.max.to_array(), "removed_tick": removed_tick
                }),
                Shape::Cylinder { base, radius, height } => json!({
                    "id": o.id, "shape": "cylinder", "base": base.to_array(), "radius": radius, "height": height, "removed_tick": removed_tick
                }),
            }
        })
        .collect();
    let species: Vec<Value> = run
        .scenario
        .species
        .species
        .iter()
        .map(|s| {
            json!({
                "name": s.name,
                "color": s.def.color,
                "length": s.def.body.size.z,
                "behaviors": s.behaviors.iter().map(|b| b.name.to_string()).collect::<Vec<_>>(),
                "look": s.def.look.resolve(&s.def.color, &s.def.body),
                "behavior_info": behavior_info(s),
            })
        })
        .collect();
    json!({
        "bounds": {"min": w.bounds.min.to_array(), "max": w.bounds.max.to_array()},
        "obstacles": obstacles,
        "species": species,
        "terrain": crate::squad::record::terrain_json(&run.squads),
        "plans": crate::squad::record::plans_json(&run.squads),
    })
}
