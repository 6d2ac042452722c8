//! Changes made to the world between ticks, outside the stages: spawning an agent (its
//! attributes and initial drives drawn from its species' distributions with its own random
//! stream), a message delivered from outside, a forced behavior change (tests and tools).

use super::Pipeline;
use crate::drives;
use crate::events::{Cause, Event, MessageKind};
use crate::species::{Draw, SexDef, SpeciesSet};
use crate::world::{Agent, AgentId, Anim, Attributes, Drives, Mind, Rng, Sex, SpeciesId, World};
use glam::Vec3;

/// A value of `d` from `rng` (a fixed value takes nothing from the stream).
fn draw(d: Draw, rng: &mut Rng) -> f32 {
    match d {
        Draw::Fixed(x) => x,
        Draw::Uniform(a, b) => rng.range(a, b),
    }
}

impl Pipeline {
    /// Spawns an agent of species `s` at `pos` heading `(yaw, pitch)`; attributes and initial
    /// drives are drawn from the species' distributions with the agent's own random stream.
    pub fn spawn(
        &mut self,
        world: &mut World,
        s: usize,
        pos: Vec3,
        yaw: f32,
        pitch: f32,
    ) -> AgentId {
        let sp = &self.species.species[s];
        let id = AgentId(world.next_agent_id);
        world.next_agent_id += 1;
        let mut rng = Rng::new(world.seed, id.0 as u64);
        let d = &**sp;
        let sex = match d.attributes.sex {
            SexDef::Random => {
                if rng.next_f32() < 0.5 {
                    Sex::Female
                } else {
                    Sex::Male
                }
            }
            SexDef::Female => Sex::Female,
            SexDef::Male => Sex::Male,
        };
        let attrs = Attributes {
            sex,
            age: draw(d.attributes.age, &mut rng),
            mass: draw(d.attributes.mass, &mut rng),
            kind: d.attributes.kind,
        };
        let mut drives = Drives {
            hunger: draw(d.drives.hunger, &mut rng),
            libido: draw(d.drives.libido, &mut rng),
            since_meal: draw(d.drives.since_meal, &mut rng),
            ..Drives::default()
        };
        // Start the meal clock where the initial hunger says (digestion: n_e·r(Δt)/n_a = 1 − H;
        // exponential: the Δt_H whose hunger is H).
        (drives.eaten, drives.since_meal) =
            drives::meal_clock_for(drives.hunger, drives.since_meal, &d.drives.params);
        // Likewise the mating clock: l(Δt_L)·(1 − H) = L.
        drives.since_mating =
            drives::since_mating_for(drives.libido, drives.hunger, &d.drives.params);
        let mut mind = Mind::new(sp.initial, sp.slots.len());
        mind.script_steer = thin_vec::thin_vec![Vec::new(); sp.steer_slots];
        mind.entered_tick = world.tick;
        let speed = 0.5 * d.body.limits.max_speed;
        let agent = Agent {
            id,
            species: SpeciesId(s as u16),
            pos,
            prev_pos: pos,
            yaw,
            pitch: pitch.clamp(-d.body.limits.pitch_limit(), d.body.limits.pitch_limit()),
            speed,
            yaw_rate: 0.0,
            pitch_rate: 0.0,
            size: d.body.size,
            drives,
            attrs,
            mind,
            anim: Anim::default(),
            rng,
            memory: sp.memory.initial.clone(),
            inbox: crate::world::Inbox::Empty,
            forward_cache: crate::world::ForwardCache::NONE,
        };
        world.agents.push(agent);
        self.events.push(Event::Spawn {
            agent: id,
            species: s as u16,
        });
        id
    }
    /// Delivers a message of `kind` to agent `id` between ticks, heard in the next tick as if a
    /// neighbour had sent it (and gone after it, like any message). `false` when the agent is
    /// not in `world`.
    pub fn deliver(&mut self, world: &mut World, id: AgentId, kind: MessageKind) -> bool {
        let Some(a) = world.agent_index(id).map(|i| &mut world.agents[i]) else {
            return false;
        };
        // One slot: a declared event ranked above this kind keeps it.
        let sp = &self.species.species[a.species.0 as usize];
        match a.inbox.heard() {
            Some(h) if sp.rank(crate::world::Signal::Event(h.event)) > kind.rank() => {}
            _ => {
                let kept = MessageKind::max_priority(a.inbox.kind(), kind);
                a.inbox = crate::world::Inbox::Kind(kept);
            }
        }
        // The tick clears every inbox it did not fill only when one was filled.
        self.delivered = true;
        true
    }
}

/// Cause of a forced behavior change (tests and tools).
pub fn force_behavior(
    world: &mut World,
    set: &SpeciesSet,
    id: AgentId,
    behavior: &str,
) -> Option<Event> {
    let i = world.agent_index(id)?;
    let a = &mut world.agents[i];
    let sp = &set.species[a.species.0 as usize];
    let to = sp.behavior_index(behavior)?;
    let from = a.mind.current;
    a.mind.current = to;
    a.mind.entered_tick = world.tick;
    Some(Event::Transition {
        agent: a.id,
        species: a.species.0,
        from,
        to,
        cause: Cause::Script,
        condition: None,
        stack: a.mind.stack().to_vec(),
    })
}
