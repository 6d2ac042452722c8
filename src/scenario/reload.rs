//! A new version of a running scenario, swapped in at a tick boundary (hot reload): the species
//! are carried over by name ([`Pipeline::install_species`]), species the new version adds are
//! spawned from its groups, and the world-level settings that may change while running
//! (obstacles, current, bounds, timed events, food) follow the new definition. The fixed time
//! step may not change: the run's clock is counted in ticks of it.

use super::{Run, Scenario};
use crate::load::{locate, locate_key, Diagnostic};
use crate::sim::Sim;
use crate::tick::{Pipeline, Remap};
use crate::world::Obstacle;

/// What swapping in a new version of a scenario did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScenarioReload {
    /// What happened to the agents of species that were already running.
    pub remap: Remap,
    /// Species the new version added, with the number of agents spawned for each.
    pub spawned: Vec<(String, usize)>,
}

impl Run {
    /// A copy of this run (same world, scenario and clocks, fresh pipeline buffers) for trying a
    /// new version out without touching the run itself.
    pub fn fork(&self) -> Run {
        Run {
            scenario: self.scenario.clone(),
            sim: Sim::from_parts(
                self.sim.world.clone(),
                Pipeline::new(self.sim.pipeline.species.clone()),
                self.sim.squads.fork(),
            ),
            total_ticks: self.total_ticks,
            next_event: self.next_event,
            food_rng: self.food_rng,
            food_debt: self.food_debt,
            scenario_events: Vec::new(),
            group_spans: self.group_spans.clone(),
        }
    }

    /// Checks that `new` may replace the running scenario (same time step).
    pub fn check_reload(&self, new: &Scenario) -> Result<(), Diagnostic> {
        if new.def.dt.to_bits() != self.scenario.def.dt.to_bits() {
            let (l, c, _) = locate(&new.text, "dt", 0).unwrap_or((0, 0, 0));
            return Err(Diagnostic::new(
                &new.file,
                l,
                c,
                format!(
                    "`dt` cannot change while the scenario runs ({} s → {} s): restart to use it",
                    self.scenario.def.dt, new.def.dt
                ),
                Some(&new.text),
            ));
        }
        self.check_counts(new)
    }

    /// Refuses a new `count` for a group that is already running: its agents were numbered
    /// into the agent grid at spawn and drawn from the group's stream, so adding or removing
    /// some mid-run would be a new run. Groups are matched by name (their species when
    /// unnamed) and order among the groups of that name.
    fn check_counts(&self, new: &Scenario) -> Result<(), Diagnostic> {
        let old = &self.scenario.def.groups;
        let mut count_at = locate(&new.text, "groups", 0).map_or(0, |x| x.2);
        for (k, g) in new.def.groups.iter().enumerate() {
            // Each group writes one `count`: the k-th after `groups` is this group's.
            let at = locate_key(&new.text, "count", count_at);
            count_at = at.map_or(count_at, |x| x.2 + 1);
            let name = g.group_name();
            let nth = new.def.groups[..k]
                .iter()
                .filter(|x| x.group_name() == name)
                .count();
            let Some(before) = old.iter().filter(|x| x.group_name() == name).nth(nth) else {
                continue;
            };
            let running = self.scenario.species.index_of(&before.species).is_some();
            if running && before.species == g.species && before.count != g.count {
                let (l, c, _) = at.unwrap_or((0, 0, 0));
                return Err(Diagnostic::new(
                    &new.file,
                    l,
                    c,
                    format!(
                        "group `{name}` count {} → {}: restart to apply (agents cannot join or \
                         leave a group that is running)",
                        before.count, g.count
                    ),
                    Some(&new.text),
                ));
            }
        }
        Ok(())
    }

    /// Swaps in `new` at the current tick boundary. Agents keep their state (see
    /// [`Pipeline::install_species`]); groups of species the new version adds are spawned now.
    pub fn reload(&mut self, new: Scenario) -> Result<ScenarioReload, Diagnostic> {
        self.check_reload(&new)?;
        let old = std::mem::replace(&mut self.scenario, new);
        let def = &self.scenario.def;
        let remap = self
            .sim
            .pipeline
            .install_species(&mut self.sim.world, self.scenario.species.clone());
        // World-level settings that follow the file (each only when the file changed it, so that
        // what timed events did stays done).
        if def.obstacles != old.def.obstacles {
            let before = std::mem::take(&mut self.sim.world.obstacles);
            for (i, ob) in def.obstacles.iter().enumerate() {
                let shape = ob.shape();
                self.sim.world.obstacles.push(Obstacle {
                    id: i as u32,
                    shape,
                    active: before.get(i).is_none_or(|o| o.active),
                });
            }
        }
        if def.current != old.def.current {
            self.sim.world.current = def.current;
        }
        if def.bounds != old.def.bounds {
            self.sim.world.bounds = def.bounds;
        }
        if def.events != old.def.events {
            // Events already due by the last tick count as done.
            let done_by = self.sim.world.time() as f32 - self.sim.world.dt * 0.5;
            self.next_event = def
                .events
                .iter()
                .position(|e| e.at > done_by)
                .unwrap_or(def.events.len());
        }
        let mut spawned = Vec::new();
        let added: Vec<String> = self
            .scenario
            .species
            .species
            .iter()
            .filter(|s| old.species.index_of(&s.name).is_none())
            .map(|s| s.name.clone())
            .collect();
        let groups = self.scenario.def.groups.clone();
        for name in added {
            let before = self.sim.world.agents.len();
            for (k, g) in groups.iter().enumerate() {
                if g.species == name {
                    self.spawn_group(g, 2000 + k as u64);
                }
            }
            spawned.push((name, self.sim.world.agents.len() - before));
        }
        Ok(ScenarioReload { remap, spawned })
    }
}
