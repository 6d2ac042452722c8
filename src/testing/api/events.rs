//! The event log as a test sees it: every event as a map (tick, time, kind and what it is
//! about, names instead of indices), a world's events or an agent's, by kind, and an agent's
//! transitions, meals and catches.

use super::{AgentRef, WorldRef};
use crate::events::Event;
use crate::testing::world::{Logged, TestWorld};
use crate::world::AgentId;
use rhai::{Array, Dynamic, Engine, ImmutableString, Map, FLOAT, INT};

/// Registers `events` (of a world or an agent), `transitions`, `meals` and `catches`.
pub(super) fn register(e: &mut Engine) {
    e.register_fn("events", |w: &mut WorldRef| events(w, |_| true));
    e.register_fn("events", |w: &mut WorldRef, kind: &str| {
        events(w, |e| e.kind() == kind)
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
        Event::Named {
            from,
            name,
            payload,
            radius,
        } => {
            put("agent", id(*from));
            put("message", Dynamic::from(ImmutableString::from(&**name)));
            put(
                "payload",
                Dynamic::from(crate::script::events::payload_map(payload)),
            );
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
        Event::Message { from, .. } | Event::Named { from, .. } => *from == id,
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
