//! Part of stage 7: declared events (seed 003's messages, extended to the events a species
//! declares). A sent event is logged with its name and payload, its payload stored in the
//! tick's table, and it is offered to every agent within the radius that hears it: the sender's
//! species, and, when the declaration is `shared`, other species that declare the same name.
//! Each agent keeps one message (seed 003's one inbox slot): the higher-ranked one; on a tie
//! the one delivered first (senders in agent order). Agents that heard a declared event then
//! get their species' `on_event(name, payload)`. Touches `Pipeline`'s next inboxes and event
//! log, and the world's agents through `on_event` only.

use super::{Event, Signal};
use crate::species::SpeciesSet;
use crate::tick::Pipeline;
use crate::world::{HeardEvent, Payload, World};

impl Pipeline {
    /// Sends agent `i`'s declared event `e` (its species' index) with the fields `given` (none:
    /// every field its zero) within `radius`; whether anyone heard it.
    pub(super) fn send_event(
        &mut self,
        world: &World,
        set: &SpeciesSet,
        i: usize,
        e: u16,
        given: Option<&Payload>,
        radius: f32,
    ) -> bool {
        let (aid, pos, sid) = {
            let a = &world.agents[i];
            (a.id, a.pos, a.species)
        };
        let Some(spec) = set.species[sid.0 as usize].events.get(e as usize) else {
            return false;
        };
        let payload = spec.complete(given.map_or(&[][..], |p| &p[..]));
        self.events.push(Event::Named {
            from: aid,
            name: spec.name.clone(),
            payload: payload.clone(),
            radius,
        });
        let index = self.next_payloads.len() as u32;
        self.next_payloads.push(payload);
        let agents = &world.agents;
        let inbox = &mut self.next_inbox;
        let heard = &mut self.next_events;
        let mut delivered = false;
        self.agent_grid
            .for_each_within(pos, radius.max(0.0), |j, _, _| {
                let j = j as usize;
                if j == i {
                    return;
                }
                let sj = agents[j].species;
                let receiver = &set.species[sj.0 as usize];
                let local = if sj == sid {
                    Some(e)
                } else if spec.shared {
                    receiver.event_index(&spec.name)
                } else {
                    None
                };
                let Some(local) = local else {
                    return;
                };
                delivered = true;
                let rank = receiver.rank(Signal::Event(local));
                let held = match (heard[j], inbox[j]) {
                    (Some(h), _) => Some(receiver.rank(Signal::Event(h.event))),
                    (None, Some(k)) => Some(k.rank()),
                    (None, None) => None,
                };
                if held.is_none_or(|h| rank > h) {
                    inbox[j] = None;
                    heard[j] = Some(HeardEvent {
                        event: local,
                        payload: index,
                    });
                }
            });
        delivered
    }

    /// Calls `on_event(name, payload)` (or `on_event(name)`) for every living agent that heard
    /// a declared event this tick, in agent order.
    pub(super) fn on_heard_events(&mut self, world: &mut World, set: &SpeciesSet, tick: u64) {
        for i in 0..world.agents.len() {
            let a = &world.agents[i];
            let Some(h) = a.heard_event else { continue };
            let sp = &set.species[a.species.0 as usize];
            if self.dead[i] || !(sp.has_on_event || sp.has_on_event_payload) {
                continue;
            }
            let name = sp.signal_name(Signal::Event(h.event)).to_string();
            let payload = world.event_payloads.get(h.payload as usize).cloned();
            self.on_event_with(world, i, &name, payload.as_ref(), tick);
        }
    }
}
