//! The streaming collector: one pass over the agents and the tick's events after every tick,
//! a pair pass every [`PAIR_INTERVAL`] ticks, counters and a few open runs per agent.
//!
//! This file holds the [`Monitor`], its per-species counters and the passes over the tick's
//! events and the sampled pairs; `track.rs` the per-agent pass (stops, frozen episodes, the pitch
//! limit, turning, obstacles) and the runs it keeps open; `place.rs` where an agent is (obstacle
//! distances and labels, what it is next to); `report.rs` the figures of a report. It reads the
//! world and events after a tick and changes nothing in them.

use super::pairs::{PairCounts, PairGrid};
use super::{
    Coincident, Spot, FLIP_SECONDS, FROZEN_SECONDS, PAIR_INTERVAL, SHORT_EPISODE_SECONDS,
    TURN_WINDOW_SECONDS,
};
use crate::events::Event;
use crate::index::ObstacleGrid;
use crate::species::{Recipe, RecipeNode, SpeciesSet};
use crate::tick::Pipeline;
use crate::world::{Obstacle, World};
use glam::Vec3;
use std::collections::BTreeMap;
use track::{close_runs, FrozenRec, Track};

mod place;
mod report;
#[cfg(test)]
mod tests;
mod track;

/// Whether a steering recipe may stop the agent on purpose: it holds a `Stop`, `Arrive`,
/// `HoldStation` or `FollowPlan` leaf. A stopped agent in any other behavior is not doing what its steering asks.
pub fn may_stop(recipe: &RecipeNode) -> bool {
    match recipe {
        RecipeNode::Priority(v) => v.iter().any(may_stop),
        RecipeNode::Blend(v) => v.iter().any(|(_, _, r)| may_stop(r)),
        RecipeNode::Script(_) => false,
        RecipeNode::Leaf(r) => recipe_may_stop(r),
    }
}

fn recipe_may_stop(r: &Recipe) -> bool {
    match r {
        Recipe::Stop | Recipe::Arrive(_) | Recipe::HoldStation(_) | Recipe::FollowPlan(_) => true,
        Recipe::Priority(v) => v.iter().any(recipe_may_stop),
        Recipe::Blend(v) => v.iter().any(|w| recipe_may_stop(&w.steer)),
        _ => false,
    }
}

/// What the monitor knows of a species, resolved once.
#[derive(Debug, Clone)]
struct SpeciesInfo {
    name: String,
    behaviors: Vec<String>,
    may_stop: Vec<bool>,
    pitch_limit: f32,
    upright: bool,
}

/// Counters of one behavior of a species.
#[derive(Debug, Clone, Default)]
struct BehaviorAcc {
    ticks: u64,
    stopped: u64,
    /// (length in ticks, start).
    longest_stop: Option<(u64, Spot)>,
    frozen_agents: u64,
    frozen_at: BTreeMap<String, u64>,
}

/// A → B seen for an agent, waiting for B → A.
#[derive(Debug, Clone)]
struct FlipAcc {
    a: u16,
    b: u16,
    count: u64,
    first: Spot,
}

/// Counters of one species.
#[derive(Debug, Clone, Default)]
struct SpeciesAcc {
    agents: u64,
    ticks: u64,
    pinned: u64,
    longest_pinned: Option<(u64, Spot)>,
    transitions: u64,
    episodes: u64,
    short: u64,
    one_tick: u64,
    first_short: Option<Spot>,
    /// By unordered behavior pair (lower index first).
    flips: BTreeMap<(u16, u16), FlipAcc>,
    turning: f64,
    net_turning: f64,
    /// (wasted rad, window start).
    worst_window: Option<(f32, Spot)>,
    neighbor_pairs: u64,
    overlapping_pairs: u64,
    /// (overlapping pairs in one sample, where).
    overlap_peak: Option<(u64, Spot)>,
    penetrating: u64,
    inside: u64,
    agents_inside: u64,
    /// (signed distance, where, obstacle): the centre closest to (or deepest in) an obstacle.
    closest: Option<(f32, Spot, Obstacle)>,
    messages: u64,
    frozen_agents: u64,
    behaviors: Vec<BehaviorAcc>,
}

/// Follows a run tick by tick and reports its [`Health`](super::Health).
///
/// ```ignore
/// let mut monitor = Monitor::new(&run.pipeline.species, run.world.dt);
/// while !run.finished() {
///     run.step();
///     monitor.observe(&run.world, &run.pipeline);
/// }
/// let health = monitor.report();
/// ```
#[derive(Debug, Clone)]
pub struct Monitor {
    dt: f32,
    /// `dt` in seconds as a decimal.
    seconds: f64,
    species: Vec<SpeciesInfo>,
    acc: Vec<SpeciesAcc>,
    tracks: Vec<Track>,
    frozen: Vec<FrozenRec>,
    last_tick: Option<u64>,
    ticks: u64,
    frozen_ticks: u64,
    short_ticks: u64,
    flip_ticks: u64,
    window_ticks: u32,
    obstacle_reach: f32,
    obstacle_grid: ObstacleGrid,
    /// With few obstacles: each active one's index, centre and bounding radius, this tick.
    obstacle_spheres: Vec<(usize, Vec3, f32)>,
    pairs: PairGrid,
    pair_counts: PairCounts,
    coincident: Coincident,
    coincident_sum: u64,
}

/// Whole ticks in `seconds`, rounded up (at least 1).
fn ticks_in(seconds: f64, dt: f64) -> u64 {
    ((seconds / dt) - 1e-6).ceil().max(1.0) as u64
}

impl Monitor {
    /// A monitor for runs of `set` with time step `dt`.
    pub fn new(set: &SpeciesSet, dt: f32) -> Monitor {
        let species: Vec<SpeciesInfo> = set
            .species
            .iter()
            .map(|s| SpeciesInfo {
                name: s.name.clone(),
                behaviors: s.behaviors.iter().map(|b| b.name.to_string()).collect(),
                may_stop: s.behaviors.iter().map(|b| may_stop(&b.steer)).collect(),
                pitch_limit: s.def.body.limits.pitch_limit(),
                upright: s.def.body.upright,
            })
            .collect();
        let acc = species
            .iter()
            .map(|s| SpeciesAcc {
                behaviors: vec![BehaviorAcc::default(); s.behaviors.len()],
                ..SpeciesAcc::default()
            })
            .collect();
        // At least 2 m: a coarse obstacle grid stays small (in cache); its lists are short anyway.
        let reach = set
            .species
            .iter()
            .map(|s| s.def.body.size.x.abs() * 0.5)
            .fold(2.0f32, f32::max);
        let dt = if dt > 0.0 && dt.is_finite() { dt } else { 0.05 };
        // The step as written in the scenario (0.05, not 0.0500000007), for exact seconds.
        let seconds = format!("{dt}").parse::<f64>().unwrap_or(dt as f64);
        Monitor {
            dt,
            seconds,
            acc,
            tracks: Vec::new(),
            frozen: Vec::new(),
            last_tick: None,
            ticks: 0,
            frozen_ticks: ticks_in(FROZEN_SECONDS, seconds),
            short_ticks: ticks_in(SHORT_EPISODE_SECONDS, seconds),
            flip_ticks: (FLIP_SECONDS / seconds + 1e-6).floor() as u64,
            window_ticks: ticks_in(TURN_WINDOW_SECONDS, seconds) as u32,
            obstacle_reach: reach,
            obstacle_grid: ObstacleGrid::new(),
            obstacle_spheres: Vec::new(),
            pairs: PairGrid::default(),
            pair_counts: PairCounts::new(species.len()),
            species,
            coincident: Coincident::default(),
            coincident_sum: 0,
        }
    }

    /// Looks at the world after a tick and at that tick's events. Calls at tick 0 (before the
    /// first step) and repeated calls for the same tick are ignored, so every caller gets the
    /// same figures.
    pub fn observe(&mut self, world: &World, pipeline: &Pipeline) {
        self.observe_events(world, &pipeline.events);
    }

    /// [`Monitor::observe`] with the tick's events given directly.
    pub fn observe_events(&mut self, world: &World, events: &[Event]) {
        let tick = world.tick;
        if tick == 0 || self.last_tick == Some(tick) {
            return;
        }
        self.last_tick = Some(tick);
        self.ticks += 1;
        if self.tracks.len() < world.next_agent_id as usize {
            self.tracks
                .resize(world.next_agent_id as usize, Track::default());
        }
        self.events(world, events, tick);
        self.agents(world, tick);
        if tick.is_multiple_of(PAIR_INTERVAL) {
            self.sample_pairs(world, tick);
        }
    }

    /// Transitions (episodes, flips), messages, deaths.
    fn events(&mut self, world: &World, events: &[Event], tick: u64) {
        // Events were produced while advancing from tick − 1 to tick; decisions stamp that tick.
        let at = tick - 1;
        for e in events {
            match e {
                Event::Transition {
                    agent,
                    species,
                    from,
                    to,
                    ..
                } => {
                    let Some(acc) = self.acc.get_mut(*species as usize) else {
                        continue;
                    };
                    acc.transitions += 1;
                    let Some(t) = self.tracks.get_mut(agent.0 as usize) else {
                        continue;
                    };
                    if !t.seen {
                        // Its first episode began before the monitor saw it.
                        continue;
                    }
                    t.transitions += 1;
                    t.last_switch_tick = at;
                    if let Some(start) = t.episode_start {
                        let len = at.saturating_sub(start);
                        acc.episodes += 1;
                        if len < self.short_ticks {
                            acc.short += 1;
                            acc.first_short.get_or_insert(Spot {
                                tick: at,
                                agent: agent.0,
                            });
                        }
                        if len <= 1 {
                            acc.one_tick += 1;
                        }
                    }
                    if let Some((a, b, t0)) = t.last_switch {
                        if a == *to && b == *from && at - t0 <= self.flip_ticks {
                            let key = (a.min(b), a.max(b));
                            acc.flips
                                .entry(key)
                                .or_insert(FlipAcc {
                                    a,
                                    b,
                                    count: 0,
                                    first: Spot {
                                        tick: t0,
                                        agent: agent.0,
                                    },
                                })
                                .count += 1;
                        }
                    }
                    t.last_switch = Some((*from, *to, at));
                    t.episode_start = Some(at);
                }
                Event::Message { from, .. } | Event::Named { from, .. } => {
                    let s = match self.tracks.get(from.0 as usize) {
                        Some(t) if t.seen => Some(t.species),
                        _ => world.agent(*from).map(|a| a.species.0),
                    };
                    if let Some(acc) = s.and_then(|s| self.acc.get_mut(s as usize)) {
                        acc.messages += 1;
                    }
                }
                Event::Death { agent, .. } => {
                    if let Some(t) = self.tracks.get_mut(agent.0 as usize) {
                        if t.seen {
                            close_runs(t, agent.0, &mut self.acc, &mut self.frozen);
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// Coincident pairs (any species) and same-species overlap, on a sampled tick.
    fn sample_pairs(&mut self, world: &World, tick: u64) {
        self.pairs.sample(&world.agents, &mut self.pair_counts);
        let c = &self.pair_counts;
        self.coincident.samples += 1;
        self.coincident_sum += c.coincident;
        if c.coincident > self.coincident.max {
            self.coincident.max = c.coincident;
            self.coincident.max_at = c.coincident_agent.map(|agent| Spot { tick, agent });
        }
        for (s, acc) in self.acc.iter_mut().enumerate() {
            acc.neighbor_pairs += c.neighbors[s];
            acc.overlapping_pairs += c.overlapping[s];
            if c.overlapping[s] > 0 && acc.overlap_peak.is_none_or(|(n, _)| c.overlapping[s] > n) {
                if let Some(agent) = c.overlap_agent[s] {
                    acc.overlap_peak = Some((c.overlapping[s], Spot { tick, agent }));
                }
            }
        }
    }
}
