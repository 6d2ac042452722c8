//! Installing a new version of the species at a tick boundary (hot reload, between two runs of
//! the tick). Every agent keeps its position, drives, memory and random stream; its species,
//! current behavior, stack, cooldowns and cached script results are carried over by name into
//! the new version. An agent whose current behavior no longer exists falls back to its species'
//! initial behavior (seed 000 §3: the initial behavior is what a fish does when nothing else
//! applies); an agent whose species is gone is removed.

use super::Pipeline;
use crate::events::{Cause, Event};
use crate::species::{SlotKind, Species, SpeciesSet};
use crate::steering::Term;
use crate::world::{Cooldowns, SpeciesId, World};
use std::sync::Arc;

/// What installing a species set did to the agents.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Remap {
    /// Agents whose current behavior was renamed or removed and who fell back to their species'
    /// initial behavior, per species of the new set.
    pub fell_back: Vec<usize>,
    /// Agents removed because their species is not in the new set.
    pub removed: usize,
    /// The fallback transitions (cause [`Cause::Fallback`], `from` = `u16::MAX` since the old
    /// behavior has no index in the new set; the condition text names it) and the deaths (cause
    /// `"removed"`), in agent order; indices refer to the new set.
    pub events: Vec<Event>,
}

impl Remap {
    /// Total number of agents that fell back.
    pub fn fell_back_total(&self) -> usize {
        self.fell_back.iter().sum()
    }
}

/// Index in `new` of each behavior of `old`, matched by name.
fn behavior_map(old: &Species, new: &Species) -> Vec<Option<u16>> {
    old.behaviors
        .iter()
        .map(|b| new.behavior_index(&b.name))
        .collect()
}

fn carry_script_state(
    old: &Species,
    new: &Species,
    values: &[f32],
    steer: &[Vec<(f32, Term)>],
) -> (Vec<f32>, Vec<Vec<(f32, Term)>>) {
    let mut new_values = vec![0.0; new.slots.len()];
    let mut new_steer = vec![Vec::new(); new.steer_slots];
    let recipe = |i: u16| -> Option<u16> {
        let name = old.recipe_names.get(i as usize)?;
        new.recipe_names
            .iter()
            .position(|n| n == name)
            .map(|j| j as u16)
    };
    for (k, slot) in new.slots.iter().enumerate() {
        let Some((j, before)) = old
            .slots
            .iter()
            .enumerate()
            .find(|(_, s)| s.name == slot.name && s.kind == slot.kind)
        else {
            continue;
        };
        if slot.kind == SlotKind::Steer {
            let terms = steer
                .get(before.index as usize)
                .cloned()
                .unwrap_or_default();
            // Recipes are referred to by index: keep the terms only if every recipe still exists.
            let mapped: Option<Vec<(f32, Term)>> = terms
                .into_iter()
                .map(|(w, t)| match t {
                    Term::Recipe(i) => recipe(i).map(|j| (w, Term::Recipe(j))),
                    other => Some((w, other)),
                })
                .collect();
            if let Some(slot_steer) = new_steer.get_mut(slot.index as usize) {
                *slot_steer = mapped.unwrap_or_default();
            }
        } else if let Some(v) = values.get(j) {
            new_values[k] = *v;
        }
    }
    (new_values, new_steer)
}

impl Pipeline {
    /// Installs `species` (a new version of the running species, matched by name) at a tick
    /// boundary and carries every agent of `world` over to it: species index, current behavior,
    /// stack and cooldowns by behavior name, cached script results by function name. Agents
    /// keep their position, drives, memory (carried to the new declaration:
    /// [`crate::script::memory::MemorySpec::carry`]) and random stream. Agents whose current behavior no
    /// longer exists fall back to the initial behavior; agents whose species is not in the new
    /// set are removed. Per-behavior statistics are carried over by name too.
    pub fn install_species(&mut self, world: &mut World, species: Arc<SpeciesSet>) -> Remap {
        let old = self.species.clone();
        let species_map: Vec<Option<usize>> = old
            .species
            .iter()
            .map(|s| species.index_of(&s.name))
            .collect();
        let behavior_maps: Vec<Vec<Option<u16>>> = old
            .species
            .iter()
            .zip(&species_map)
            .map(|(s, m)| m.map_or_else(Vec::new, |n| behavior_map(s, &species.species[n])))
            .collect();
        let mut remap = Remap {
            fell_back: vec![0; species.species.len()],
            ..Remap::default()
        };
        let mut keep = vec![true; world.agents.len()];
        for (i, a) in world.agents.iter_mut().enumerate() {
            let os = a.species.0 as usize;
            let Some(ns) = species_map.get(os).copied().flatten() else {
                keep[i] = false;
                remap.removed += 1;
                remap.events.push(Event::Death {
                    agent: a.id,
                    species: a.species.0,
                    cause: "removed",
                });
                continue;
            };
            let (osp, nsp) = (&old.species[os], &species.species[ns]);
            let bmap = &behavior_maps[os];
            let m = &mut a.mind;
            let from = m.current;
            match bmap.get(from as usize).copied().flatten() {
                Some(b) => m.current = b,
                None => {
                    m.current = nsp.initial;
                    m.entered_tick = world.tick;
                    remap.fell_back[ns] += 1;
                }
            }
            // What was a plain behavior may now be composed: its first part runs.
            let leaf = |b: u16| crate::species::validate::first_leaf(&nsp.behaviors, b);
            m.current = crate::species::validate::first_leaf(&nsp.behaviors, m.current);
            let depth = nsp.depth as usize;
            if m.scope_depth() != depth {
                m.track_scopes(depth, world.tick);
            }
            let stack: Vec<u16> = m
                .stack()
                .iter()
                .filter_map(|&b| bmap.get(b as usize).copied().flatten())
                .map(leaf)
                .filter(|&b| b != m.current)
                .collect();
            m.depth = 0;
            for b in stack {
                m.push(b);
            }
            // A cooldown still running is kept, even where the new version declares none.
            let running = m.cooldowns.running(world.tick);
            m.cooldowns = Cooldowns::from_pairs(
                running.filter_map(|(ob, t)| Some((bmap.get(ob as usize).copied().flatten()?, t))),
            );
            nsp.memory.carry(&mut a.memory);
            let (values, steer) = carry_script_state(osp, nsp, &m.script_values, &m.script_steer);
            m.script_values = values.into();
            m.script_steer = steer.into();
            // A new version gets its own first error report.
            m.script_error_reported = false;
            if bmap.get(from as usize).copied().flatten().is_none() {
                remap.events.push(Event::Transition {
                    agent: a.id,
                    species: ns as u16,
                    from: u16::MAX,
                    to: m.current,
                    cause: Cause::Fallback,
                    condition: Some(
                        format!("behavior \"{}\" no longer exists", osp.behavior_name(from)).into(),
                    ),
                    stack: m.stack().to_vec(),
                });
            }
            a.species = SpeciesId(ns as u16);
            a.size = nsp.body.size;
        }
        if remap.removed > 0 {
            let mut k = 0;
            world.agents.retain(|_| {
                k += 1;
                keep[k - 1]
            });
            if self.plan_targets.len() == keep.len() {
                let mut k = 0;
                self.plan_targets.retain(|_| {
                    k += 1;
                    keep[k - 1]
                });
            }
        }
        // Statistics by name.
        let old_ticks = std::mem::take(&mut self.stats.behavior_ticks);
        let mut ticks: Vec<Vec<u64>> = species
            .species
            .iter()
            .map(|s| vec![0; s.behaviors.len()])
            .collect();
        for (os, row) in old_ticks.iter().enumerate() {
            let (Some(Some(ns)), Some(bmap)) = (species_map.get(os), behavior_maps.get(os)) else {
                continue;
            };
            for (ob, &n) in row.iter().enumerate() {
                if let Some(nb) = bmap.get(ob).copied().flatten() {
                    ticks[*ns][nb as usize] += n;
                }
            }
        }
        self.stats.behavior_ticks = ticks;
        self.set_species(species);
        remap
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::normalize;
    use crate::species::load_species_str;
    use glam::Vec3;
    use std::path::Path;

    const FISH: &str = r#"Species(
    name: "fish",
    script: None,
    initial: "wander",
    behaviors: [
        Behavior(name: "graze", priority: 2, when: Above(Drive(Hunger), 0.5), done: Below(Drive(Hunger), 0.5), steer: Wander(), cooldown: 1.0),
        Behavior(name: "hide", priority: 1, when: Above(Drive(Fear), 0.9), done: Below(Drive(Fear), 0.1), steer: Wander()),
        Behavior(name: "wander", priority: 3, steer: Wander()),
    ],
)"#;

    fn set(texts: &[&str]) -> Arc<SpeciesSet> {
        let root = normalize(Path::new("."));
        let species = texts
            .iter()
            .map(|t| {
                Arc::new(
                    load_species_str(Path::new("fish.ron"), t, &root, &Default::default())
                        .unwrap_or_else(|e| panic!("{e}")),
                )
            })
            .collect();
        Arc::new(SpeciesSet::new(species).unwrap_or_else(|e| panic!("{e}")))
    }

    fn world_with(p: &mut Pipeline, n: usize) -> World {
        let bounds = crate::world::Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
        let mut w = World::new(bounds, 0.05, 7);
        for i in 0..n {
            p.spawn(&mut w, 0, Vec3::new(i as f32, 0.0, 0.0), 0.0, 0.0);
        }
        w
    }

    #[test]
    fn cooldown_lists_follow_the_version_and_a_running_one_is_kept() {
        let mut p = Pipeline::new(set(&[FISH]));
        let mut w = world_with(&mut p, 2);
        // "graze" has a cooldown; none is held before one starts.
        assert!(w.agents[0].mind.cooldowns.is_empty());
        w.tick = 40;
        w.agents[0].mind.cooldowns = Cooldowns::from_pairs([(2, 70), (1, 40)]);
        w.agents[1].mind.cooldowns = Cooldowns::from_pairs([(0, 40)]);
        // A version without cooldowns: a cooldown still running is kept; those that ran out
        // at tick 40 are dropped.
        let plain = FISH.replace(", cooldown: 1.0", "");
        p.install_species(&mut w, set(&[&plain]));
        assert_eq!(w.agents[0].mind.cooldowns, Cooldowns::from_pairs([(2, 70)]));
        assert!(!w.agents[0].mind.cooldowns.ready(2, 69));
        assert!(w.agents[0].mind.cooldowns.ready(2, 70));
        assert!(w.agents[1].mind.cooldowns.is_empty());
        let fresh = world_with(&mut p, 1);
        assert!(fresh.agents[0].mind.cooldowns.is_empty());
    }

    #[test]
    fn renamed_current_behavior_falls_back_and_others_keep_theirs() {
        let mut p = Pipeline::new(set(&[FISH]));
        let mut w = world_with(&mut p, 3);
        w.tick = 40;
        // Agent 0 grazes with "hide" stacked under it... (hide is higher, so stack wander instead).
        let graze = 0;
        let wander = 2;
        w.agents[0].mind.current = graze;
        w.agents[0].mind.push(wander);
        w.agents[0].mind.entered_tick = 12;
        w.agents[0].mind.cooldowns = Cooldowns::from_pairs([(0, 99), (2, 80)]);
        w.agents[1].mind.current = wander;
        w.agents[1].mind.entered_tick = 30;
        w.agents[1].mind.cooldowns = Cooldowns::from_pairs([(0, 55)]);
        w.agents[2].drives.hunger = 0.77;
        let before: Vec<_> = w.agents.iter().map(|a| (a.pos, a.drives)).collect();
        // New version: "graze" renamed to "feed" and moved last; "wander" now first.
        let renamed = FISH
            .replace("name: \"graze\"", "name: \"feed\"")
            .replace(
                "        Behavior(name: \"wander\", priority: 3, steer: Wander()),\n",
                "",
            )
            .replace(
                "behaviors: [\n",
                "behaviors: [\n        Behavior(name: \"wander\", priority: 3, steer: Wander()),\n",
            );
        let new = set(&[&renamed]);
        assert_eq!(new.species[0].behavior_index("wander"), Some(0));
        assert_eq!(new.species[0].behavior_index("feed"), Some(1));
        let r = p.install_species(&mut w, new);
        assert_eq!(r.fell_back, vec![1]);
        assert_eq!(r.removed, 0);
        let a0 = &w.agents[0].mind;
        assert_eq!(
            a0.current, 0,
            "fell back to the initial behavior, wander (now index 0)"
        );
        assert_eq!(a0.entered_tick, 40);
        // Its stacked "wander" is the current behavior now: dropped from the stack.
        assert_eq!(a0.stack(), &[] as &[u16]);
        // The renamed behavior's cooldown is lost, wander's (was index 2, now 0) is kept.
        assert_eq!(a0.cooldowns, Cooldowns::from_pairs([(0, 80)]));
        let a1 = &w.agents[1].mind;
        assert_eq!((a1.current, a1.entered_tick), (0, 30));
        assert!(a1.cooldowns.is_empty());
        assert_eq!(
            w.agents
                .iter()
                .map(|a| (a.pos, a.drives))
                .collect::<Vec<_>>(),
            before
        );
        assert!(matches!(
            r.events[..],
            [Event::Transition {
                cause: Cause::Fallback,
                to: 0,
                ..
            }]
        ));
    }

    #[test]
    fn cooldowns_and_stack_follow_their_behavior_names() {
        let mut p = Pipeline::new(set(&[FISH]));
        let mut w = world_with(&mut p, 1);
        let m = &mut w.agents[0].mind;
        m.current = 1; // hide
        m.push(0); // graze, interrupted
        m.cooldowns = Cooldowns::from_pairs([(0, 10), (1, 20), (2, 30)]);
        // Reverse the declaration order: graze 2, hide 1, wander 0.
        let reversed = r#"Species(
    name: "fish",
    initial: "wander",
    behaviors: [
        Behavior(name: "wander", priority: 3, steer: Wander()),
        Behavior(name: "hide", priority: 1, when: Above(Drive(Fear), 0.9), done: Below(Drive(Fear), 0.1), steer: Wander()),
        Behavior(name: "graze", priority: 2, when: Above(Drive(Hunger), 0.3), done: Below(Drive(Hunger), 0.3), steer: Wander()),
    ],
)"#;
        let r = p.install_species(&mut w, set(&[reversed]));
        assert_eq!(r.fell_back_total(), 0);
        let m = &w.agents[0].mind;
        assert_eq!(m.current, 1);
        assert_eq!(m.stack(), &[2]);
        assert_eq!(
            m.cooldowns,
            Cooldowns::from_pairs([(0, 30), (1, 20), (2, 10)])
        );
    }

    #[test]
    fn agents_of_a_species_no_longer_loaded_are_removed_and_indices_follow_names() {
        let crab = FISH.replace("\"fish\"", "\"crab\"");
        let mut p = Pipeline::new(set(&[FISH, &crab]));
        let mut w = world_with(&mut p, 2);
        p.spawn(&mut w, 1, Vec3::ZERO, 0.0, 0.0);
        p.stats.behavior_ticks[1][2] = 5;
        // New set: crab first, fish gone.
        let r = p.install_species(&mut w, set(&[&crab]));
        assert_eq!(r.removed, 2);
        assert_eq!(w.agents.len(), 1);
        assert_eq!(w.agents[0].species, SpeciesId(0));
        assert_eq!(w.agents[0].id.0, 2);
        assert_eq!(p.stats.behavior_ticks, vec![vec![0, 0, 5]]);
        assert_eq!(
            r.events
                .iter()
                .filter(|e| matches!(
                    e,
                    Event::Death {
                        cause: "removed",
                        ..
                    }
                ))
                .count(),
            2
        );
    }
}
