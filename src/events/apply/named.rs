//! Part of stage 7: declared events (seed 003's messages, extended to the events a species
//! declares). A sent event is logged with its name and payload, its payload stored in the
//! tick's table, and it is offered to every agent within the radius that hears it: the sender's
//! species, and, when the declaration is `shared`, other species that declare the same name.
//! Each agent keeps one message (seed 003's one inbox slot): the higher-ranked one; on a tie
//! the one delivered first (senders in agent order). Agents that heard a declared event then
//! get their species' `on_event(name, payload)`. Touches `Pipeline`'s next inboxes and event
//! log, and the world's agents through `on_event` only.

use crate::events::{Event, Signal};
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
        let (inbox, heard) = super::inboxes(
            &mut self.next_inbox,
            &mut self.next_events,
            world.agents.len(),
        );
        let agents = &world.agents;
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
            let Some(h) = a.inbox.heard() else { continue };
            let sp = &set.species[a.species.0 as usize];
            if self.dead.get(i).copied().unwrap_or(false)
                || !(sp.has_on_event || sp.has_on_event_payload)
            {
                continue;
            }
            let name = sp.signal_name(Signal::Event(h.event)).to_string();
            let payload = world.event_payloads.get(h.payload as usize).cloned();
            self.on_event_with(world, i, &name, payload.as_ref(), tick);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::events::{Event, MessageKind};
    use crate::species::{Species, SpeciesSet};
    use crate::tick::Pipeline;
    use crate::world::{Aabb, AgentId, MemValue, Signal, World};
    use glam::Vec3;
    use std::sync::Arc;

    /// A caller that shouts (`on_enter`) when near the +X bound, a listener that declares the
    /// caller's events, and a species that declares none.
    fn world_of(on_enter: &str) -> (Pipeline, World, [AgentId; 4]) {
        let events = r#"events: [
            (name: "alarm_call", priority: 25, fields: {"strength": Float}, shared: true),
            (name: "chirp", priority: 5),
        ]"#;
        let caller = format!(
            r#"(
            name: "caller",
            initial: "idle",
            behaviors: [
                Behavior(name: "idle", priority: 3, steer: Stop),
                Behavior(name: "shout", priority: 1, when: NearBounds(3.0), steer: Stop,
                    on_enter: [{on_enter}]),
            ],
            {events},
        )"#
        );
        let listener = format!(
            r#"(name: "listener", initial: "idle",
                behaviors: [Behavior(name: "idle", priority: 1, steer: Stop)], {events})"#
        );
        let deaf = r#"(name: "deaf", initial: "idle",
            behaviors: [Behavior(name: "idle", priority: 1, steer: Stop)])"#;
        let set = SpeciesSet::new(
            [
                ("caller.ron", &*caller),
                ("listener.ron", &*listener),
                ("deaf.ron", deaf),
            ]
            .iter()
            .map(|(f, t)| Arc::new(Species::parse(f, t).unwrap()))
            .collect(),
        )
        .unwrap();
        let bounds = Aabb::new(Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 40.0, 50.0));
        let mut w = World::new(bounds, 0.05, 3);
        let mut p = Pipeline::new(Arc::new(set));
        let at = |x: f32| Vec3::new(x, 10.0, 0.0);
        let ids = [
            p.spawn(&mut w, 0, at(48.0), 0.0, 0.0),
            p.spawn(&mut w, 0, at(44.0), 0.0, 0.0),
            p.spawn(&mut w, 1, at(44.0), 0.0, 0.0),
            p.spawn(&mut w, 2, at(44.0), 0.0, 0.0),
        ];
        (p, w, ids)
    }

    #[test]
    fn a_declared_event_is_heard_by_kin_and_by_species_that_declare_a_shared_one() {
        let (mut p, mut w, _) = world_of(r#"Send("alarm_call", 10.0)"#);
        p.step(&mut w);
        let named: Vec<_> = p
            .events
            .iter()
            .filter_map(|e| match e {
                Event::Named { name, payload, .. } => Some((name.to_string(), payload.clone())),
                _ => None,
            })
            .collect();
        assert_eq!(named.len(), 1);
        assert_eq!(named[0].0, "alarm_call");
        // Sent from `on_enter`: every declared field at its zero.
        assert_eq!(
            &named[0].1[..],
            &[("strength".into(), MemValue::Float(0.0))]
        );
        let heard: Vec<_> = w.agents.iter().map(|a| a.inbox.heard()).collect();
        assert_eq!(heard[0], None, "the sender does not hear itself");
        let kin = heard[1].expect("kin hears it");
        let other = heard[2].expect("a species that declares the shared event hears it");
        assert_eq!((kin.event, other.event), (0, 0));
        assert_eq!(heard[3], None, "a species that does not declare it");
        assert_eq!(kin.payload, other.payload);
        assert_eq!(
            w.event_payloads[kin.payload as usize][0].1,
            MemValue::Float(0.0)
        );
        assert!(w.agents.iter().all(|a| a.inbox.kind().is_none()));
        // Heard for one tick, like a built-in message.
        p.step(&mut w);
        assert!(w.agents.iter().all(|a| a.inbox.heard().is_none()));
    }

    #[test]
    fn an_event_not_shared_is_heard_by_the_sender_species_only() {
        let (mut p, mut w, _) = world_of(r#"Send("chirp", 10.0)"#);
        p.step(&mut w);
        assert_eq!(w.agents[1].inbox.heard().map(|h| h.event), Some(1));
        assert_eq!(w.agents[2].inbox.heard(), None);
    }

    #[test]
    fn one_inbox_slot_keeps_the_highest_rank() {
        // alarm_call (25) over Mate (10), in either order.
        for send in [
            r#"Send("alarm_call", 10.0), Send(Mate, 10.0)"#,
            r#"Send(Mate, 10.0), Send("alarm_call", 10.0)"#,
        ] {
            let (mut p, mut w, _) = world_of(send);
            p.step(&mut w);
            assert_eq!(
                w.agents[1].inbox.heard().map(|h| h.event),
                Some(0),
                "{send}"
            );
            assert_eq!(w.agents[1].inbox.kind(), None, "{send}");
        }
        // Danger (30) over alarm_call, in either order.
        for send in [
            r#"Send("alarm_call", 10.0), Send(Danger, 10.0)"#,
            r#"Send(Danger, 10.0), Send("alarm_call", 10.0)"#,
        ] {
            let (mut p, mut w, _) = world_of(send);
            p.step(&mut w);
            assert_eq!(
                w.agents[1].inbox.kind(),
                Some(MessageKind::Danger),
                "{send}"
            );
            assert_eq!(w.agents[1].inbox.heard(), None, "{send}");
            // The listener hears only the shared event.
            assert_eq!(
                w.agents[2].inbox.heard().map(|h| h.event),
                Some(0),
                "{send}"
            );
        }
        // chirp (5) under Mate (10).
        let (mut p, mut w, _) = world_of(r#"Send("chirp", 10.0), Send(Mate, 10.0)"#);
        p.step(&mut w);
        assert_eq!(w.agents[1].inbox.kind(), Some(MessageKind::Mate));
        assert_eq!(w.agents[1].inbox.heard(), None);
    }

    #[test]
    fn a_delivered_kind_does_not_replace_a_higher_declared_event() {
        let (mut p, mut w, ids) = world_of(r#"Send("alarm_call", 10.0)"#);
        p.step(&mut w);
        assert!(p.deliver(&mut w, ids[1], MessageKind::Obstacle));
        assert_eq!(w.agents[1].inbox.heard().map(|h| h.event), Some(0));
        assert_eq!(w.agents[1].inbox.kind(), None);
        assert!(p.deliver(&mut w, ids[1], MessageKind::Danger));
        assert_eq!(w.agents[1].inbox.heard(), None);
        assert_eq!(w.agents[1].inbox.kind(), Some(MessageKind::Danger));
        let sp = &p.species.species[0];
        assert_eq!(sp.rank(Signal::Event(0)), 25);
        assert_eq!(sp.signal_name(Signal::Event(1)), "chirp");
    }
}
