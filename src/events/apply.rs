//! Stage 7 of the tick, world events ([`Pipeline::apply`]): run once every agent's pass is done,
//! in agent order, so that its results do not depend on the thread count. What an agent's pass
//! left in its outcome slot that reaches beyond the agent is applied here: behavior counters,
//! transition and script-error events, messages delivered for the next tick (seed 003: danger >
//! obstacle > mate), contacts (seed 000: eating removes the food or kills the prey, mating resets
//! libido) with the script `on_event` calls they make; then the dead and the eaten food leave the
//! world and its clock advances. Events a species declares are delivered by `apply/named.rs`.

mod named;

use super::{Event, MessageKind, Signal};
use crate::decision::{scripts, Ctx};
use crate::perception::{Category, GroupQueries, Source, Summary};
use crate::species::{Contact, SpeciesSet};
use crate::tick::{More, Pipeline, Rare};
use crate::world::{HeardEvent, World};
use rhai::{Dynamic, ImmutableString, Scope};

/// The next tick's inboxes, one slot an agent, all empty until a message is sent.
fn inboxes<'a>(
    inbox: &'a mut Vec<Option<MessageKind>>,
    heard: &'a mut Vec<Option<HeardEvent>>,
    n: usize,
) -> (
    &'a mut Vec<Option<MessageKind>>,
    &'a mut Vec<Option<HeardEvent>>,
) {
    if inbox.len() != n {
        inbox.resize(n, None);
        heard.resize(n, None);
    }
    (inbox, heard)
}

impl Pipeline {
    /// Stage 7: what each agent's pass produced that reaches beyond the agent (counters,
    /// transition and script-error events, messages for the next tick, contacts: meals, catches,
    /// matings, and the script `on_event` calls they make), in agent order; then removes the
    /// dead and the eaten food and advances the clock.
    pub(crate) fn apply(&mut self, world: &mut World) {
        let set = self.species.clone();
        let n = world.agents.len();
        self.taken_food.clear();
        self.taken_food.resize(world.food.len(), false);
        // The per-agent lists below are filled only in a tick that needs them (a contact, a
        // message): a world without either keeps none of them, one byte to 12 an agent each.
        self.dead.clear();
        self.mated.clear();
        self.next_inbox.clear();
        self.next_events.clear();
        self.next_payloads.clear();
        let mut named = false;
        let tick = world.tick;
        let mut delivered = false;
        // In agent order (each agent's own record was rewritten by its pass), what reaches
        // beyond the agent: counters, events, messages, contacts.
        for i in 0..n {
            let out = &mut self.outcomes[i];
            let (s, current) = (out.species as usize, out.behavior as usize);
            if let Some(row) = self.stats.behavior_ticks.get_mut(s) {
                if let Some(c) = row.get_mut(current) {
                    *c += 1;
                }
            }
            if out.rare.is_none() {
                continue;
            }
            let a = &mut world.agents[i];
            let Rare { transitions, more } = out.rare.take().map(|r| *r).unwrap_or_default();
            let More {
                contact,
                messages,
                payloads,
                error,
                explain: _,
            } = more.map(|m| *m).unwrap_or_default();
            for t in transitions.into_iter().flatten() {
                self.stats.transitions += 1;
                self.events.push(Event::Transition {
                    agent: a.id,
                    species: s as u16,
                    from: t.from,
                    to: t.to,
                    cause: t.cause,
                    // The species the agent decided by: stage 7 runs in the same tick.
                    condition: t
                        .fired()
                        .and_then(|c| set.species.get(s).and_then(|sp| c.text(sp))),
                    stack: a.mind.stack().to_vec(),
                });
            }
            if let Some(e) = error {
                self.stats.script_errors += 1;
                if !a.mind.script_error_reported {
                    a.mind.script_error_reported = true;
                    self.events.push(Event::ScriptError {
                        agent: a.id,
                        species: s as u16,
                        message: e.to_string(),
                    });
                }
            }
            let (aid, pos, sid) = (a.id, a.pos, a.species);
            for (slot, m) in messages.into_iter().enumerate() {
                let Some((signal, radius)) = m else { continue };
                let kind = match signal {
                    Signal::Kind(kind) => kind,
                    Signal::Event(e) => {
                        let given = payloads.iter().find(|(k, _)| *k == slot).map(|p| &p.1);
                        named |= self.send_event(world, &set, i, e, given, radius);
                        delivered |= named;
                        continue;
                    }
                };
                self.events.push(Event::Message {
                    from: aid,
                    kind,
                    radius,
                });
                let radius = radius.max(0.0);
                let agents = &world.agents;
                let (inbox, heard) = inboxes(&mut self.next_inbox, &mut self.next_events, n);
                let delivered = &mut delivered;
                let sp = &set.species[sid.0 as usize];
                self.agent_grid.for_each_within(pos, radius, |j, _, _| {
                    let j = j as usize;
                    if j != i && agents[j].species == sid {
                        // One slot: a declared event ranked above this kind keeps it.
                        match heard[j] {
                            Some(h) if sp.rank(Signal::Event(h.event)) > kind.rank() => {}
                            _ => {
                                heard[j] = None;
                                inbox[j] = Some(MessageKind::max_priority(inbox[j], kind));
                            }
                        }
                        *delivered = true;
                    }
                });
            }
            if let Some((contact, source)) = contact {
                self.contacts.push((i, contact, source));
            }
        }
        // Contacts once every agent's own outcome is in place, still in agent order, so that
        // what a contact does to a later agent (a mating partner's reset, its `on_event`) is
        // not overwritten by that agent's outcome.
        let contacts = std::mem::take(&mut self.contacts);
        if !contacts.is_empty() {
            self.dead.resize(n, false);
            self.mated.resize(n, false);
        }
        for &(i, contact, source) in &contacts {
            if !self.dead[i] {
                self.contact(world, &set, i, contact, source, tick);
            }
        }
        self.contacts = contacts;
        self.contacts.clear();
        // Without a message this tick or the last, every inbox is and stays empty.
        if delivered || self.delivered {
            // Filled as a message is sent: none this tick, every inbox empties.
            inboxes(&mut self.next_inbox, &mut self.next_events, n);
            for ((a, m), h) in world
                .agents
                .iter_mut()
                .zip(self.next_inbox.iter())
                .zip(self.next_events.iter())
            {
                a.inbox = crate::world::Inbox::of(*m, *h);
            }
            world.event_payloads = std::mem::take(&mut self.next_payloads);
        }
        self.delivered = delivered;
        if named {
            self.on_heard_events(world, &set, tick);
        }
        if self.dead.iter().any(|&d| d) {
            let dead = &self.dead;
            let mut k = 0;
            world.agents.retain(|_| {
                k += 1;
                !dead[k - 1]
            });
        }
        if self.taken_food.iter().any(|&t| t) {
            let taken = &self.taken_food;
            let mut k = 0;
            world.food.retain(|_| {
                k += 1;
                !taken[k - 1]
            });
        }
        world.tick += 1;
    }

    fn contact(
        &mut self,
        world: &mut World,
        set: &SpeciesSet,
        i: usize,
        contact: Contact,
        source: Source,
        tick: u64,
    ) {
        let meal = set.species[world.agents[i].species.0 as usize]
            .drives
            .meal_size;
        match (contact, source) {
            (Contact::Eat { .. }, Source::Food(f)) => {
                let f = f as usize;
                if !self.taken_food[f] {
                    self.taken_food[f] = true;
                    let a = &mut world.agents[i];
                    a.drives.eaten += meal;
                    a.drives.since_meal = 0.0;
                    a.mind.reached = true;
                    self.stats.meals += 1;
                    self.events.push(Event::Meal {
                        agent: a.id,
                        food: world.food[f].id,
                    });
                    self.on_event(world, i, "meal", tick);
                }
            }
            (Contact::Eat { .. }, Source::Agent(j)) => {
                let j = j as usize;
                if j != i && !self.dead[j] {
                    self.dead[j] = true;
                    let (prey, prey_species) = (world.agents[j].id, world.agents[j].species.0);
                    let a = &mut world.agents[i];
                    a.drives.eaten += meal;
                    a.drives.since_meal = 0.0;
                    a.mind.reached = true;
                    self.stats.catches += 1;
                    self.events.push(Event::Catch { agent: a.id, prey });
                    self.events.push(Event::Death {
                        agent: prey,
                        species: prey_species,
                        cause: "caught",
                    });
                    self.on_event(world, i, "catch", tick);
                }
            }
            (Contact::Mate { .. }, Source::Agent(j)) => {
                let j = j as usize;
                if j != i && !self.mated[i] && !self.mated[j] && !self.dead[j] {
                    self.mated[i] = true;
                    self.mated[j] = true;
                    for k in [i, j] {
                        world.agents[k].drives.since_mating = 0.0;
                        world.agents[k].drives.libido = 0.0;
                        world.agents[k].mind.reached = true;
                    }
                    self.stats.matings += 1;
                    self.events.push(Event::Mating {
                        agent: world.agents[i].id,
                        mate: world.agents[j].id,
                    });
                    // Both partners hear of it (each may note it, e.g. to leave the other).
                    self.on_event(world, i, "mating", tick);
                    self.on_event(world, j, "mating", tick);
                }
            }
            _ => {}
        }
    }

    /// Calls the species' `on_event(kind)` for agent `i`, if it has one (sequential: events are
    /// rare).
    fn on_event(&mut self, world: &mut World, i: usize, kind: &str, tick: u64) {
        self.on_event_with(world, i, kind, None, tick);
    }

    /// Calls the species' `on_event(kind, payload)` for agent `i` (an empty map for a contact),
    /// or its `on_event(kind)` when it defines only that one.
    pub(super) fn on_event_with(
        &mut self,
        world: &mut World,
        i: usize,
        kind: &str,
        payload: Option<&crate::world::Payload>,
        tick: u64,
    ) {
        let set = self.species.clone();
        let sp = &set.species[world.agents[i].species.0 as usize];
        let (Some(script), true) = (&sp.script, sp.has_on_event || sp.has_on_event_payload) else {
            return;
        };
        let agent = world.agents[i].clone();
        // An agent perception has not seen (one born this tick) has perceived nothing yet.
        let (summaries, percepts) = if i < self.perception.len() {
            (self.perception.summaries(i), self.perception.percepts(i))
        } else {
            ([Summary::NONE; Category::COUNT], Vec::new())
        };
        let ctx = Ctx {
            world,
            perception: &self.perception,
            species: sp,
            agent: &agent,
            percepts: &percepts,
            summaries: &summaries,
            group_queries: &GroupQueries::EMPTY,
            group_sums: &[],
            tick,
            dt: world.dt,
        };
        let s = agent.species.0 as usize;
        let view = scripts::view_of(
            &ctx,
            &agent.mind,
            &self.species_names[s],
            &self.behavior_names[s][agent.mind.current as usize],
        );
        let mut this = Dynamic::from(view);
        let mut scope = Scope::new();
        let r: Result<Dynamic, _> = crate::script::with_tick(&self.script_clock, || {
            if sp.has_on_event_payload {
                let map = payload.map(crate::script::events::payload_map);
                script.call_args(
                    &mut scope,
                    &mut this,
                    "on_event",
                    (ImmutableString::from(kind), map.unwrap_or_default()),
                )
            } else {
                script.call_args(
                    &mut scope,
                    &mut this,
                    "on_event",
                    (ImmutableString::from(kind),),
                )
            }
        });
        match r {
            Ok(_) => {
                if let Some(v) = this.try_cast::<crate::script::AgentView>() {
                    scripts::write_back(&v, &mut world.agents[i]);
                }
            }
            Err(e) => {
                self.stats.script_errors += 1;
                let a = &mut world.agents[i];
                if !a.mind.script_error_reported {
                    a.mind.script_error_reported = true;
                    self.events.push(Event::ScriptError {
                        agent: a.id,
                        species: s as u16,
                        message: e.diagnostic.to_string(),
                    });
                }
            }
        }
    }
}
