//! An agent handle in a test: reading and setting everything a behavior depends on (position,
//! heading, speed, drives, attributes, behavior and stack, memory), its squad, and forcing a
//! behavior. Drives are set so that they stay where the test put them.

use super::{AgentRef, R};
use crate::frame;
use crate::script::memory::store;
use crate::script::{from_mem, to_mem};
use crate::testing::failure::error;
use crate::testing::world::TestWorld;
use crate::world::Sex;
use glam::{Vec2, Vec3};
use rhai::{Array, Dynamic, Engine, Map, FLOAT, INT};

/// Registers the agent handle's getters and setters, `force_behavior`, the memory indexers,
/// `has` and `to_string`.
pub(super) fn register(e: &mut Engine) {
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
                let ag = &tw.sim.world.agents[i];
                match ag.inbox.heard() {
                    Some(h) => tw.sim.species().species[ag.species.0 as usize]
                        .signal_name(crate::world::Signal::Event(h.event))
                        .to_string(),
                    None => ag
                        .inbox
                        .kind()
                        .map_or(String::new(), |k| k.name().to_string()),
                }
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
    // The blackboard as the species declares it: an undeclared key or a value of another type
    // fails the test where it is written.
    e.register_indexer_get(|a: &mut AgentRef, key: &str| -> R<Dynamic> {
        a.with(|tw, i| {
            let agent = &tw.sim.world.agents[i];
            if let Some(why) = tw.species[agent.species.0 as usize].memory.undeclared(key) {
                return Err(error(why));
            }
            Ok(agent
                .memory
                .iter()
                .find(|(k, _)| &**k == key)
                .map_or(Dynamic::UNIT, |(_, v)| from_mem(v)))
        })?
    });
    e.register_indexer_set(|a: &mut AgentRef, key: &str, v: Dynamic| -> R<()> {
        let v = to_mem(v)?;
        a.with_mut(|tw, i| {
            let s = tw.sim.world.agents[i].species.0 as usize;
            let spec = tw.species[s].memory.clone();
            spec.check_write(key, &v).map_err(error)?;
            store(&mut tw.sim.world.agents[i].memory, key, v, &spec).map_err(error)
        })?
    });
    e.register_fn("has", |a: &mut AgentRef, key: &str| -> R<bool> {
        a.with(|tw, i| {
            let agent = &tw.sim.world.agents[i];
            if let Some(why) = tw.species[agent.species.0 as usize].memory.undeclared(key) {
                return Err(error(why));
            }
            Ok(agent.memory.iter().any(|(k, _)| &**k == key))
        })?
    });
    e.register_fn("to_string", |a: &mut AgentRef| a.label());
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
pub(super) fn set_hunger(tw: &mut TestWorld, i: usize, h: f32) {
    let a = &mut tw.sim.world.agents[i];
    let d = &tw.species[a.species.0 as usize].def.drives;
    a.drives.hunger = h.clamp(0.0, 1.0);
    if d.native {
        (a.drives.eaten, a.drives.since_meal) =
            crate::drives::meal_clock_for(a.drives.hunger, 0.0, &d.params);
    }
}

/// Sets libido so that it stays there given the current hunger (`L = p1·Δt_L·(1 − H)`).
pub(super) fn set_libido(tw: &mut TestWorld, i: usize, l: f32) {
    let a = &mut tw.sim.world.agents[i];
    let d = &tw.species[a.species.0 as usize].def.drives;
    a.drives.libido = l.clamp(0.0, 1.0);
    let k = d.params.p1 * (1.0 - a.drives.hunger);
    if d.native && k > 0.0 {
        a.drives.since_mating = a.drives.libido / k;
    }
}
