//! What a test reads of a world: its tick, time, `dt`, food and agents, agents counted by
//! species, found by name (`w["name"]`) or by id, and the world as text.

use super::{AgentRef, WorldRef, R};
use crate::events::Event;
use crate::testing::failure::error;
use crate::world::AgentId;
use rhai::{Array, Dynamic, Engine, FLOAT, INT};

/// Registers the world's getters, `count`, the name indexer, `agent(id)` and `to_string`.
pub(super) fn register(e: &mut Engine) {
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
    e.register_fn("to_string", |w: &mut WorldRef| {
        let tw = w.get();
        format!(
            "world at tick {} with {} agents and {} food",
            tw.sim.world.tick,
            tw.sim.world.agents.len(),
            tw.sim.world.food.len()
        )
    });
}
