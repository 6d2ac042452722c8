//! The streaming collector: one pass over the agents and the tick's events after every tick,
//! a pair pass every [`PAIR_INTERVAL`] ticks, counters and a few open runs per agent.

use super::pairs::{PairCounts, PairGrid};
use super::{
    ratio, BehaviorHealth, Coincident, Flip, Frozen, FrozenAt, Health, Near, Penetration,
    SpeciesHealth, Spot, FLIP_SECONDS, FORMAT, FROZEN_EXAMPLES, FROZEN_SECONDS, NEAR_OBSTACLE,
    PAIR_INTERVAL, PITCH_LIMIT_MARGIN, SHORT_EPISODE_SECONDS, STOPPED_SPEED, TOP_FLIPS,
    TURN_WINDOW_SECONDS,
};
use crate::events::Event;
use crate::index::ObstacleGrid;
use crate::species::{Recipe, RecipeNode, SpeciesSet};
use crate::tick::Pipeline;
use crate::world::{Obstacle, Shape, World};
use glam::Vec3;
use std::collections::BTreeMap;

/// Whether a steering recipe may stop the agent on purpose: it holds a `Stop`, `Arrive` or
/// `FollowPlan` leaf. A stopped agent in any other behavior is not doing what its steering asks.
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
        Recipe::Stop | Recipe::Arrive(_) | Recipe::FollowPlan(_) => true,
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

/// A frozen episode, its length updated when it ends.
#[derive(Debug, Clone)]
struct FrozenRec {
    species: u16,
    behavior: u16,
    agent: u32,
    start: u64,
    ticks: u64,
    pos: Vec3,
    near: Near,
}

/// What the monitor follows of one agent (by id).
#[derive(Debug, Clone, Default)]
struct Track {
    seen: bool,
    species: u16,
    /// Behavior at the last observation.
    behavior: u16,
    /// Current run of stopped ticks in `behavior`: first tick and length.
    stop_start: u64,
    stop_len: u64,
    /// Index in the frozen list while the stop is a frozen episode.
    frozen: Option<usize>,
    frozen_any: bool,
    frozen_in: Vec<u16>,
    /// Tick the current behavior episode started, once one started with a transition the
    /// monitor saw (the behavior an agent spawns in was not chosen: its episode is not counted).
    episode_start: Option<u64>,
    /// The last transition: (from, to, tick).
    last_switch: Option<(u16, u16, u64)>,
    transitions: u64,
    last_switch_tick: u64,
    /// Current run of ticks at the pitch limit.
    pin_start: u64,
    pin_len: u64,
    prev_forward: Vec3,
    /// Position and tick at the last observation (how far it really went).
    prev_pos: Vec3,
    prev_tick: u64,
    window_forward: Vec3,
    window_turn: f32,
    window_len: u32,
    window_tick: u64,
    inside_ever: bool,
}

/// Follows a run tick by tick and reports its [`Health`].
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

/// Up to this many obstacles, each agent tests every one (against its bounding sphere first);
/// past it, an obstacle grid lists the ones near an agent.
const SCAN_OBSTACLES: usize = 32;

/// Angle (rad) between two unit vectors, accurate for small angles too.
#[inline]
fn angle(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Signed distance from `p` to the surface of `shape` (negative inside).
pub(super) fn signed_distance(shape: &Shape, p: Vec3) -> f32 {
    match shape {
        Shape::Sphere { center, radius } => (p - *center).length() - radius,
        Shape::Box(b) => {
            let q = (p - b.center()).abs() - b.size() * 0.5;
            q.max(Vec3::ZERO).length() + q.max_element().min(0.0)
        }
        Shape::Cylinder {
            base,
            radius,
            height,
        } => {
            // Outside the side and outside the height, as a box's two axes.
            let ring = (p.x - base.x).hypot(p.z - base.z) - radius;
            let y = (p.y - (base.y + height * 0.5)).abs() - height * 0.5;
            let q = glam::Vec2::new(ring, y);
            q.max(glam::Vec2::ZERO).length() + q.max_element().min(0.0)
        }
    }
}

/// "sphere 2", "box 4".
pub(super) fn obstacle_label(o: &Obstacle) -> String {
    match o.shape {
        Shape::Sphere { .. } => format!("sphere {}", o.id),
        Shape::Box(_) => format!("box {}", o.id),
        Shape::Cylinder { .. } => format!("cylinder {}", o.id),
    }
}

/// Label of a frozen agent's place for counting: the obstacle, or open water.
fn place_of(near: &Near) -> String {
    match near {
        Near::Obstacle { label, .. } => label.clone(),
        _ => "open water".to_string(),
    }
}

/// Keeps the larger of `slot` and `(len, spot)` (the earlier one on ties).
fn keep_longest(slot: &mut Option<(u64, Spot)>, len: u64, spot: Spot) {
    if slot.is_none_or(|(l, _)| len > l) {
        *slot = Some((len, spot));
    }
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
                Event::Message { from, .. } => {
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

    /// Per agent: stops, frozen episodes, the pitch limit, turning, obstacles.
    fn agents(&mut self, world: &World, tick: u64) {
        // A few obstacles are scanned (bounding spheres first); many go through a grid.
        let scan = world.obstacles.len() <= SCAN_OBSTACLES;
        self.obstacle_spheres.clear();
        if scan {
            self.obstacle_spheres.extend(
                world
                    .obstacles
                    .iter()
                    .enumerate()
                    .filter(|(_, o)| o.active)
                    .map(|(k, o)| (k, o.shape.center(), o.shape.bounding_radius())),
            );
        } else {
            self.obstacle_grid
                .update(world.bounds, self.obstacle_reach, &world.obstacles);
        }
        for (i, a) in world.agents.iter().enumerate() {
            let s = a.species.0 as usize;
            let (Some(info), Some(acc)) = (self.species.get(s), self.acc.get_mut(s)) else {
                continue;
            };
            let Some(t) = self.tracks.get_mut(a.id.0 as usize) else {
                continue;
            };
            let b = a.mind.current;
            let forward = a.forward();
            let here = Spot {
                tick,
                agent: a.id.0,
            };
            if !t.seen {
                *t = Track {
                    seen: true,
                    species: s as u16,
                    behavior: b,
                    prev_forward: forward,
                    prev_pos: a.pos,
                    prev_tick: tick,
                    window_forward: forward,
                    window_tick: tick,
                    ..Track::default()
                };
                acc.agents += 1;
            }
            acc.ticks += 1;
            // Stops and frozen episodes: a run is stopped ticks in one behavior.
            // Stopped by its speed, or by how far it went since the last tick: a body swimming
            // full speed into a wall of the world or a crowd goes nowhere, and looks frozen.
            let went = if t.prev_tick + 1 == tick && self.dt > 0.0 {
                (a.pos - t.prev_pos).length() / self.dt
            } else {
                f32::INFINITY
            };
            t.prev_pos = a.pos;
            t.prev_tick = tick;
            let stopped = a.speed.abs() < STOPPED_SPEED || went < STOPPED_SPEED;
            if t.stop_len > 0 && (!stopped || t.behavior != b) {
                close_stop(t, a.id.0, acc, &mut self.frozen);
            }
            t.behavior = b;
            if let Some(ba) = acc.behaviors.get_mut(b as usize) {
                ba.ticks += 1;
                if stopped {
                    ba.stopped += 1;
                    if t.stop_len == 0 {
                        t.stop_start = tick;
                    }
                    t.stop_len += 1;
                    let must_move = !info.may_stop.get(b as usize).copied().unwrap_or(true);
                    if must_move && t.stop_len == self.frozen_ticks {
                        let near = near(world, i, &self.species);
                        let place = place_of(&near);
                        if !t.frozen_in.contains(&b) {
                            t.frozen_in.push(b);
                            ba.frozen_agents += 1;
                            *ba.frozen_at.entry(place).or_insert(0) += 1;
                        }
                        if !t.frozen_any {
                            t.frozen_any = true;
                            acc.frozen_agents += 1;
                        }
                        t.frozen = Some(self.frozen.len());
                        self.frozen.push(FrozenRec {
                            species: s as u16,
                            behavior: b,
                            agent: a.id.0,
                            start: t.stop_start,
                            ticks: t.stop_len,
                            pos: a.pos,
                            near,
                        });
                    }
                }
            }
            // The pitch limit.
            if a.pitch.abs() >= info.pitch_limit - PITCH_LIMIT_MARGIN {
                acc.pinned += 1;
                if t.pin_len == 0 {
                    t.pin_start = tick;
                }
                t.pin_len += 1;
            } else if t.pin_len > 0 {
                close_pin(t, a.id.0, acc);
            }
            // Turning over windows of TURN_WINDOW_SECONDS.
            if t.window_tick != tick {
                t.window_turn += angle(t.prev_forward, forward);
                t.window_len += 1;
                if t.window_len >= self.window_ticks {
                    let net = angle(t.window_forward, forward);
                    acc.turning += t.window_turn as f64;
                    acc.net_turning += net as f64;
                    let wasted = t.window_turn - net;
                    if acc.worst_window.is_none_or(|(w, _)| wasted > w) {
                        acc.worst_window = Some((
                            wasted,
                            Spot {
                                tick: t.window_tick,
                                agent: a.id.0,
                            },
                        ));
                    }
                    t.window_forward = forward;
                    t.window_turn = 0.0;
                    t.window_len = 0;
                    t.window_tick = tick;
                }
            }
            t.prev_forward = forward;
            // Obstacles: inside, or closer to the surface than half the body width.
            let half = a.size.x.abs() * 0.5;
            let mut deepest: Option<(f32, Obstacle)> = None;
            let mut each = |o: &Obstacle| {
                if !o.active {
                    return;
                }
                let d = signed_distance(&o.shape, a.pos);
                if d < half && deepest.is_none_or(|(x, _)| d < x) {
                    deepest = Some((d, *o));
                }
            };
            if scan {
                for &(k, c, r) in &self.obstacle_spheres {
                    let reach = r + half;
                    if (a.pos - c).length_squared() < reach * reach {
                        each(&world.obstacles[k]);
                    }
                }
            } else if half <= self.obstacle_reach {
                for &k in self.obstacle_grid.near(a.pos) {
                    each(&world.obstacles[k as usize]);
                }
            } else {
                world.obstacles.iter().for_each(each);
            }
            if let Some((d, o)) = deepest {
                acc.penetrating += 1;
                if d < 0.0 {
                    acc.inside += 1;
                    if !t.inside_ever {
                        t.inside_ever = true;
                        acc.agents_inside += 1;
                    }
                }
                if acc.closest.is_none_or(|(x, _, _)| d < x) {
                    acc.closest = Some((d, here, o));
                }
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

    /// The figures so far (episodes still going count up to the last tick observed).
    pub fn report(&self) -> Health {
        let mut m = self.clone();
        for (id, t) in m.tracks.iter_mut().enumerate() {
            if t.seen {
                close_runs(t, id as u32, &mut m.acc, &mut m.frozen);
            }
        }
        let dt = m.seconds;
        let species = m
            .species
            .iter()
            .zip(&m.acc)
            .enumerate()
            .map(|(s, (info, acc))| m.species_health(s, info, acc, dt))
            .collect();
        let c = &m.coincident;
        Health {
            format: FORMAT,
            dt: m.dt,
            ticks: m.ticks,
            pair_interval: PAIR_INTERVAL,
            species,
            coincident: Coincident {
                mean: ratio(m.coincident_sum as f64, c.samples as f64),
                ..c.clone()
            },
        }
    }

    fn species_health(
        &self,
        s: usize,
        info: &SpeciesInfo,
        acc: &SpeciesAcc,
        dt: f64,
    ) -> SpeciesHealth {
        let seconds = acc.ticks as f64 * dt;
        let mut frozen: Vec<&FrozenRec> = self
            .frozen
            .iter()
            .filter(|f| f.species as usize == s)
            .collect();
        frozen.sort_by(|a, b| b.ticks.cmp(&a.ticks).then(a.start.cmp(&b.start)));
        let behaviors: Vec<BehaviorHealth> = info
            .behaviors
            .iter()
            .zip(&acc.behaviors)
            .enumerate()
            .map(|(b, (name, ba))| {
                let mut at: Vec<FrozenAt> = ba
                    .frozen_at
                    .iter()
                    .map(|(place, n)| FrozenAt {
                        place: place.clone(),
                        agents: *n,
                    })
                    .collect();
                at.sort_by_key(|x| std::cmp::Reverse(x.agents));
                BehaviorHealth {
                    name: name.clone(),
                    may_stop: info.may_stop[b],
                    agent_ticks: ba.ticks,
                    stopped_share: ratio(ba.stopped as f64, ba.ticks as f64),
                    longest_stop: ba.longest_stop.map(|x| x.1),
                    frozen_agents: ba.frozen_agents,
                    frozen_at: at,
                    longest_frozen: frozen.iter().find(|f| f.behavior as usize == b).map(|f| {
                        Spot {
                            tick: f.start,
                            agent: f.agent,
                        }
                    }),
                }
            })
            .collect();
        let (moving_ticks, moving_stopped) = info
            .may_stop
            .iter()
            .zip(&acc.behaviors)
            .filter(|(m, _)| !**m)
            .fold((0u64, 0u64), |(n, k), (_, ba)| {
                (n + ba.ticks, k + ba.stopped)
            });
        let mut flips: Vec<&FlipAcc> = acc.flips.values().collect();
        flips.sort_by(|x, y| y.count.cmp(&x.count).then(x.first.tick.cmp(&y.first.tick)));
        let name = |b: u16| {
            info.behaviors
                .get(b as usize)
                .cloned()
                .unwrap_or_else(|| "?".into())
        };
        let most_switches_at = self
            .tracks
            .iter()
            .enumerate()
            .filter(|(_, t)| t.seen && t.species as usize == s && t.transitions > 0)
            .max_by(|(i, x), (j, y)| x.transitions.cmp(&y.transitions).then(j.cmp(i)))
            .map(|(i, t)| Spot {
                tick: t.last_switch_tick,
                agent: i as u32,
            });
        SpeciesHealth {
            name: info.name.clone(),
            agents: acc.agents,
            agent_ticks: acc.ticks,
            stopped_share: ratio(moving_stopped as f64, moving_ticks as f64),
            frozen_agents: acc.frozen_agents,
            frozen_episodes: frozen.len() as u64,
            pitch_limit_share: ratio(acc.pinned as f64, acc.ticks as f64),
            upright: info.upright,
            pitch_limit_at: acc.longest_pinned.map(|x| x.1),
            transitions: acc.transitions,
            switch_rate: ratio(acc.transitions as f64, seconds),
            most_switches_at,
            episodes: acc.episodes,
            short_episode_share: ratio(acc.short as f64, acc.episodes as f64),
            one_tick_share: ratio(acc.one_tick as f64, acc.episodes as f64),
            short_episode_at: acc.first_short,
            flips: flips
                .into_iter()
                .take(TOP_FLIPS)
                .map(|f| Flip {
                    a: name(f.a),
                    b: name(f.b),
                    count: f.count,
                    first: f.first,
                })
                .collect(),
            turning: acc.turning,
            net_turning: acc.net_turning,
            turning_waste: (acc.net_turning > 0.0).then(|| acc.turning / acc.net_turning),
            turning_waste_at: acc.worst_window.map(|x| x.1),
            neighbor_pairs: acc.neighbor_pairs,
            overlapping_pairs: acc.overlapping_pairs,
            overlap_share: ratio(acc.overlapping_pairs as f64, acc.neighbor_pairs as f64),
            overlap_at: acc.overlap_peak.map(|x| x.1),
            obstacles: Penetration {
                agent_ticks: acc.penetrating,
                inside_ticks: acc.inside,
                agents_inside: acc.agents_inside,
                closest: acc.closest.map(|x| x.0),
                closest_at: acc.closest.map(|x| x.1),
                closest_obstacle: acc.closest.map(|x| obstacle_label(&x.2)),
            },
            messages: acc.messages,
            messages_per_agent_second: ratio(acc.messages as f64, seconds),
            behaviors,
            frozen: frozen
                .into_iter()
                .take(FROZEN_EXAMPLES)
                .map(|f| Frozen {
                    agent: f.agent,
                    behavior: name(f.behavior),
                    start_tick: f.start,
                    seconds: f.ticks as f64 * dt,
                    pos: f.pos,
                    near: f.near.clone(),
                })
                .collect(),
        }
    }
}

/// Ends the agent's open runs (a stop, a stretch at the pitch limit).
fn close_runs(t: &mut Track, id: u32, acc: &mut [SpeciesAcc], frozen: &mut [FrozenRec]) {
    let Some(acc) = acc.get_mut(t.species as usize) else {
        return;
    };
    close_stop(t, id, acc, frozen);
    close_pin(t, id, acc);
}

fn close_stop(t: &mut Track, id: u32, acc: &mut SpeciesAcc, frozen: &mut [FrozenRec]) {
    if t.stop_len == 0 {
        return;
    }
    if let Some(ba) = acc.behaviors.get_mut(t.behavior as usize) {
        keep_longest(
            &mut ba.longest_stop,
            t.stop_len,
            Spot {
                tick: t.stop_start,
                agent: id,
            },
        );
    }
    if let Some(k) = t.frozen.take() {
        frozen[k].ticks = t.stop_len;
    }
    t.stop_len = 0;
}

fn close_pin(t: &mut Track, id: u32, acc: &mut SpeciesAcc) {
    if t.pin_len == 0 {
        return;
    }
    keep_longest(
        &mut acc.longest_pinned,
        t.pin_len,
        Spot {
            tick: t.pin_start,
            agent: id,
        },
    );
    t.pin_len = 0;
}

/// What agent `i` is next to: the nearest active obstacle within [`NEAR_OBSTACLE`] of its
/// centre, else the nearest other agent.
fn near(world: &World, i: usize, species: &[SpeciesInfo]) -> Near {
    let p = world.agents[i].pos;
    let obstacle = world
        .obstacles
        .iter()
        .filter(|o| o.active)
        .map(|o| (signed_distance(&o.shape, p).max(0.0), o))
        .filter(|(d, _)| *d <= NEAR_OBSTACLE)
        .min_by(|x, y| x.0.total_cmp(&y.0));
    if let Some((distance, o)) = obstacle {
        return Near::Obstacle {
            id: o.id,
            label: obstacle_label(o),
            distance,
        };
    }
    world
        .agents
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != i)
        .map(|(_, b)| ((b.pos - p).length(), b))
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map_or(Near::Nothing, |(distance, b)| Near::Agent {
            id: b.id.0,
            species: species
                .get(b.species.0 as usize)
                .map_or_else(|| "?".to_string(), |s| s.name.clone()),
            distance,
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::events::MessageKind;
    use crate::health::Figure;
    use crate::scenario::normalize;
    use crate::species::{load_species_str, Species};
    use crate::world::{Aabb, AgentId};
    use std::path::Path;
    use std::sync::Arc;

    fn species(name: &str) -> Species {
        let text = format!(
            r#"Species(
    name: "{name}",
    script: None,
    drives: (native: false),
    initial: "swim",
    behaviors: [
        Behavior(name: "swim", priority: 2, steer: Priority([AvoidStatic(), Cruise(speed: 1.0)])),
        Behavior(name: "rest", priority: 2, when: Above(Speed, 100.0), steer: Priority([AvoidStatic(), Stop])),
        Behavior(name: "dart", priority: 2, when: Above(Speed, 200.0), steer: Blend([(w: 1.0, steer: Arrive(target: Point(0.0, 0.0, 0.0)))])),
    ],
)"#
        );
        load_species_str(
            Path::new("fish.ron"),
            &text,
            &normalize(Path::new(".")),
            &Default::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"))
    }

    /// A hand-built world: agents placed and moved by the test, ticks counted by hand.
    struct Rig {
        world: World,
        pipe: Pipeline,
        monitor: Monitor,
    }

    const SWIM: u16 = 0;
    const REST: u16 = 1;
    const DT: f32 = 0.05;

    impl Rig {
        fn new(names: &[&str]) -> Rig {
            let set = SpeciesSet::new(names.iter().map(|n| Arc::new(species(n))).collect())
                .unwrap_or_else(|e| panic!("{e}"));
            let monitor = Monitor::new(&set, DT);
            Rig {
                world: World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), DT, 1),
                pipe: Pipeline::new(Arc::new(set)),
                monitor,
            }
        }

        /// Adds an agent of species `s` at `pos`, heading +Z at speed 1.
        fn add(&mut self, s: usize, pos: Vec3) -> usize {
            self.pipe.spawn(&mut self.world, s, pos, 0.0, 0.0);
            let a = self.world.agents.last_mut().unwrap();
            a.speed = 1.0;
            self.world.agents.len() - 1
        }

        fn agent(&mut self, i: usize) -> &mut crate::world::Agent {
            &mut self.world.agents[i]
        }

        /// One tick with these events.
        fn tick(&mut self, events: &[Event]) {
            self.world.tick += 1;
            self.monitor.observe_events(&self.world, events);
        }

        fn health(&self) -> Health {
            self.monitor.report()
        }
    }

    fn transition(agent: u32, from: u16, to: u16) -> Event {
        Event::Transition {
            agent: AgentId(agent),
            species: 0,
            from,
            to,
            cause: crate::events::Cause::Activated,
            condition: None,
            stack: Vec::new(),
        }
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn may_stop_looks_through_the_recipe_tree() {
        let sp = species("fish");
        let flags: Vec<bool> = sp.behaviors.iter().map(|b| may_stop(&b.steer)).collect();
        assert_eq!(flags, [false, true, true]);
    }

    #[test]
    fn a_body_that_goes_nowhere_is_stopped_whatever_its_speed() {
        let mut r = Rig::new(&["fish"]);
        // Full speed into a wall of the world for 6 s: it never moves.
        let pinned = r.add(0, Vec3::new(50.0, 0.0, 0.0));
        let free = r.add(0, Vec3::new(0.0, 0.0, 0.0));
        for _ in 1..=120u64 {
            r.agent(pinned).speed = 2.0;
            r.agent(free).speed = 2.0;
            r.agent(free).pos.z += 2.0 * DT;
            r.tick(&[]);
        }
        let h = r.health();
        let s = &h.species[0];
        // The first observation has nothing to compare with: 119 of 240 agent-ticks stopped.
        assert!(
            close(s.stopped_share, 119.0 / 240.0, 1e-12),
            "{}",
            s.stopped_share
        );
        assert_eq!(s.frozen_agents, 1);
    }

    #[test]
    fn stopped_six_seconds_is_frozen_four_is_not() {
        let mut r = Rig::new(&["fish"]);
        r.world.add_obstacle(Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 3.0),
            radius: 1.0,
        });
        let long = r.add(0, Vec3::ZERO); // stopped 7 s in swim
        let short = r.add(0, Vec3::new(20.0, 0.0, 0.0)); // stopped 4 s, then swims
        let resting = r.add(0, Vec3::new(-20.0, 0.0, 0.0)); // stopped 7 s in rest: allowed
        let edge = r.add(0, Vec3::new(0.0, 20.0, 0.0)); // stopped 99 ticks, then 100 ticks
        r.agent(resting).mind.current = REST;
        for t in 1..=140u64 {
            r.agent(long).speed = 0.0;
            r.agent(short).speed = if t <= 80 { 0.01 } else { 1.0 };
            r.agent(resting).speed = 0.0;
            r.agent(edge).speed = if t <= 99 || (101..=200).contains(&t) {
                0.0
            } else {
                1.0
            };
            // Bodies go as far as their speed takes them.
            for id in [long, short, resting, edge] {
                let a = r.agent(id);
                a.pos.x += a.speed * DT;
            }
            r.tick(&[]);
        }
        let h = r.health();
        let s = &h.species[0];
        // Stopped in swim: 140 + 80 + (99 + 40) of 3 × 140 agent-ticks.
        let swim = &s.behaviors[SWIM as usize];
        assert!(!swim.may_stop && s.behaviors[REST as usize].may_stop);
        assert_eq!(swim.agent_ticks, 420);
        assert!(close(swim.stopped_share, 359.0 / 420.0, 1e-12));
        assert!(close(s.stopped_share, 359.0 / 420.0, 1e-12));
        assert_eq!(s.behaviors[REST as usize].stopped_share, 1.0);
        // Only the 7-s stop is frozen: 4 s and 99 ticks (4.95 s) are not, the resting one may.
        assert_eq!(s.frozen_agents, 1);
        assert_eq!(swim.frozen_agents, 1);
        assert_eq!(s.behaviors[REST as usize].frozen_agents, 0);
        let f = &s.frozen[0];
        assert_eq!((f.agent, f.start_tick, f.behavior.as_str()), (0, 1, "swim"));
        assert!(close(f.seconds, 7.0, 1e-9));
        assert_eq!(
            f.near,
            Near::Obstacle {
                id: 0,
                label: "sphere 0".into(),
                distance: 2.0
            }
        );
        assert_eq!(swim.frozen_at[0].place, "sphere 0");
        let w = h.warnings();
        let frozen = w.iter().find(|w| w.figure == Figure::Frozen).unwrap();
        assert_eq!(
            frozen.message,
            "fish: 1 agent stopped ≥ 5 s in swim, at sphere 0"
        );
        assert_eq!((frozen.tick, frozen.agent), (Some(1), Some(0)));
        assert!(w.iter().any(|w| w.figure == Figure::Stopped));
    }

    #[test]
    fn a_stop_of_exactly_five_seconds_freezes_and_ends_at_death() {
        let mut r = Rig::new(&["fish"]);
        let a = r.add(0, Vec3::ZERO);
        let b = r.add(0, Vec3::new(3.0, 0.0, 0.0));
        for _ in 0..100 {
            r.agent(a).speed = 0.0;
            r.tick(&[]);
        }
        let id = r.world.agents[a].id;
        r.world.agents.remove(a);
        r.tick(&[Event::Death {
            agent: id,
            species: 0,
            cause: "caught",
        }]);
        let _ = b;
        let h = r.health();
        let f = &h.species[0].frozen[0];
        assert!(close(f.seconds, 5.0, 1e-9), "{f:?}");
        // No obstacle: the nearest agent.
        assert_eq!(
            f.near,
            Near::Agent {
                id: 1,
                species: "fish".into(),
                distance: 3.0
            }
        );
        assert_eq!(h.species[0].behaviors[0].frozen_at[0].place, "open water");
    }

    #[test]
    fn pitch_limit_share_counts_ticks_at_the_limit() {
        let mut r = Rig::new(&["fish"]);
        let a = r.add(0, Vec3::ZERO);
        let limit = r.pipe.species.species[0].def.body.limits.pitch_limit();
        for t in 1..=100u64 {
            // 30 ticks at the limit, 70 just outside the margin.
            r.agent(a).pitch = if (41..=70).contains(&t) {
                -limit
            } else {
                limit - 0.02
            };
            r.tick(&[]);
        }
        let s = &r.health().species[0];
        assert!(close(s.pitch_limit_share, 0.3, 1e-12));
        assert_eq!(s.pitch_limit_at, Some(Spot { tick: 41, agent: 0 }));
    }

    #[test]
    fn switches_short_episodes_and_flips() {
        let mut r = Rig::new(&["fish"]);
        r.add(0, Vec3::ZERO);
        r.add(0, Vec3::new(5.0, 0.0, 0.0));
        // Agent 0 switches during the steps from ticks 10, 14, 40 and 41 (seen after ticks 11,
        // 15, 41, 42): episodes 10–14 (short, flips back), 14–40, 40–41 (one tick, short, flips
        // back); the one it spawned in (0–10) was not chosen and is not counted.
        for t in 1..=100u64 {
            let events: Vec<Event> = match t {
                11 => vec![transition(0, SWIM, REST)],
                15 => vec![transition(0, REST, SWIM)],
                41 => vec![transition(0, SWIM, REST)],
                42 => vec![transition(0, REST, SWIM)],
                _ => vec![],
            };
            r.tick(&events);
        }
        let h = r.health();
        let s = &h.species[0];
        assert_eq!(s.transitions, 4);
        // 4 transitions over 2 agents × 5 s.
        assert!(close(s.switch_rate, 0.4, 1e-12));
        assert_eq!(s.episodes, 3);
        assert!(close(s.short_episode_share, 2.0 / 3.0, 1e-12));
        assert!(close(s.one_tick_share, 1.0 / 3.0, 1e-12));
        assert_eq!(s.short_episode_at, Some(Spot { tick: 14, agent: 0 }));
        assert_eq!(s.flips.len(), 1);
        let f = &s.flips[0];
        assert_eq!((f.a.as_str(), f.b.as_str(), f.count), ("swim", "rest", 2));
        assert_eq!(f.first, Spot { tick: 10, agent: 0 });
        assert_eq!(s.most_switches_at, Some(Spot { tick: 41, agent: 0 }));
        // Three episodes are too few to call flicker: no warning until there are 20.
        let w = h.warnings();
        assert!(!s.judged(Figure::ShortEpisodes));
        assert!(
            !w.iter().any(|w| w.figure == Figure::ShortEpisodes),
            "{w:?}"
        );
        assert!(!w.iter().any(|w| w.figure == Figure::SwitchRate), "{w:?}");
        let mut many = h.clone();
        many.species[0].episodes = crate::health::MIN_EPISODES;
        assert!(many
            .warnings()
            .iter()
            .any(|w| w.figure == Figure::ShortEpisodes
                && w.message.contains(
                    "67% of 20 behavior episodes shorter than 0.5 s, 33% a single tick"
                )));
    }

    #[test]
    fn a_flip_needs_the_reverse_within_half_a_second() {
        let mut r = Rig::new(&["fish"]);
        r.add(0, Vec3::ZERO);
        for t in 1..=60u64 {
            let events: Vec<Event> = match t {
                11 => vec![transition(0, SWIM, REST)],
                // 11 ticks later: 0.55 s, not a flip.
                22 => vec![transition(0, REST, SWIM)],
                // 13 ticks later again, then A → B → C, no flip either.
                35 => vec![transition(0, SWIM, REST)],
                36 => vec![transition(0, REST, 2)],
                _ => vec![],
            };
            r.tick(&events);
        }
        let s = &r.health().species[0];
        assert!(s.flips.is_empty(), "{:?}", s.flips);
        assert_eq!(s.switch_rate, 4.0 / 3.0);
    }

    #[test]
    fn turning_waste_is_one_for_a_steady_turn_and_large_for_a_zigzag() {
        let run = |yaw: &dyn Fn(u64) -> f32| {
            let mut r = Rig::new(&["fish"]);
            let a = r.add(0, Vec3::ZERO);
            for t in 1..=41u64 {
                r.agent(a).yaw = yaw(t);
                r.tick(&[]);
            }
            r.health().species[0].clone()
        };
        let steady = run(&|t| 0.05 * t as f32);
        // Two windows of 20 ticks, each turning 1 rad toward the new heading.
        assert!(close(steady.turning, 2.0, 1e-4), "{}", steady.turning);
        assert!(close(steady.turning_waste.unwrap(), 1.0, 1e-4));
        // Left-right-left on a slow drift: 10 × 0.21 + 10 × 0.19 = 4 rad of turning for 0.2 rad
        // of heading change per window.
        let zigzag = run(&|t| 0.01 * t as f32 + if t % 2 == 1 { 0.2 } else { 0.0 });
        assert!(close(zigzag.turning, 8.0, 1e-3), "{}", zigzag.turning);
        assert!(close(zigzag.net_turning, 0.4, 1e-4));
        assert!(close(zigzag.turning_waste.unwrap(), 20.0, 0.01));
        assert_eq!(zigzag.turning_waste_at, Some(Spot { tick: 1, agent: 0 }));
        let straight = run(&|_| 0.3);
        assert_eq!(straight.turning_waste, None);
    }

    #[test]
    fn pairs_coincide_and_overlap() {
        let mut r = Rig::new(&["fish", "eel"]);
        // Fish are 0.2 wide and 1 long: neighbors within 2, overlapping within 0.18.
        r.add(0, Vec3::new(0.0, 5.0, 0.0));
        r.add(0, Vec3::new(0.0, 5.0, 0.01));
        r.add(0, Vec3::new(0.0, 5.0, 1.0));
        r.add(0, Vec3::new(0.0, 5.0, 10.0));
        r.add(1, Vec3::new(0.0, 5.0, 0.015));
        for _ in 0..10 {
            r.tick(&[]);
        }
        let h = r.health();
        // Two samples (ticks 5 and 10), each: fish 0–1, fish 0–eel, fish 1–eel coincide;
        // fish pairs 0–1, 0–2, 1–2 are neighbors, 0–1 overlaps.
        assert_eq!(h.coincident.samples, 2);
        assert_eq!((h.coincident.max, h.coincident.mean), (3, 3.0));
        assert_eq!(h.coincident.max_at, Some(Spot { tick: 5, agent: 0 }));
        let fish = h.species("fish").unwrap();
        assert_eq!((fish.neighbor_pairs, fish.overlapping_pairs), (6, 2));
        assert!(close(fish.overlap_share, 1.0 / 3.0, 1e-12));
        let eel = h.species("eel").unwrap();
        assert_eq!((eel.neighbor_pairs, eel.overlap_share), (0, 0.0));
    }

    #[test]
    fn the_pair_grid_finds_what_a_scan_finds() {
        let mut r = Rig::new(&["fish", "eel"]);
        let mut rng = crate::world::Rng::new(9, 0);
        for k in 0..400 {
            let p = Vec3::new(
                rng.range(-6.0, 6.0),
                rng.range(-3.0, 3.0),
                rng.range(-6.0, 6.0),
            );
            let i = r.add(k % 2, p);
            if k.is_multiple_of(7) {
                // Some exact duplicates; some eels three times longer, so that eels look
                // three cells out in a grid sized for fish.
                r.agent(i).pos = Vec3::ZERO;
                if k % 2 == 1 {
                    r.agent(i).size.z = 3.0;
                }
            }
        }
        let mut grid = PairGrid::default();
        let mut counts = PairCounts::new(2);
        grid.sample(&r.world.agents, &mut counts);
        let (c, n, o) = super::super::pairs::brute_force(&r.world.agents, 2);
        assert_eq!(counts.coincident, c);
        assert_eq!(counts.neighbors, n);
        assert_eq!(counts.overlapping, o);
        assert!(c > 0 && o.iter().all(|&x| x > 0));
    }

    #[test]
    fn agents_inside_or_against_obstacles() {
        // With a few obstacles (each tested), and with many (through the grid): the same.
        let few = obstacle_case(0);
        let many = obstacle_case(2 * SCAN_OBSTACLES);
        assert_eq!(few, many);
        let h = few;
        let o = &h.species[0].obstacles;
        assert_eq!(
            (o.agent_ticks, o.inside_ticks, o.agents_inside),
            (30, 20, 2)
        );
        assert!(close(o.closest.unwrap() as f64, -1.5, 1e-6));
        assert_eq!(o.closest_obstacle.as_deref(), Some("sphere 0"));
        assert_eq!(o.closest_at, Some(Spot { tick: 1, agent: 0 }));
        let w = h.warnings();
        let pen = w
            .iter()
            .find(|w| w.figure == Figure::ObstaclePenetration)
            .unwrap();
        assert!(
            pen.message.starts_with(
                "fish: 30 agent-ticks inside an obstacle or within half a body width of it"
            ),
            "{}",
            pen.message
        );
        assert!(pen
            .message
            .contains("20 inside, 2 agents ever inside; deepest 1.50 inside sphere 0"));
    }

    /// Five fish among a sphere, a box and a removed sphere, plus `far` small rocks out of
    /// their way, for ten ticks.
    fn obstacle_case(far: usize) -> Health {
        let mut r = Rig::new(&["fish"]);
        r.world.add_obstacle(Shape::Sphere {
            center: Vec3::new(0.0, 5.0, 0.0),
            radius: 2.0,
        });
        r.world.add_obstacle(Shape::Box(Aabb::new(
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(12.0, 2.0, 2.0),
        )));
        let gone = r.world.add_obstacle(Shape::Sphere {
            center: Vec3::new(-10.0, 5.0, 0.0),
            radius: 2.0,
        });
        r.world.obstacles[gone as usize].active = false;
        // Fish are 0.2 wide: within 0.1 of a surface is against it.
        r.add(0, Vec3::new(0.0, 5.0, 0.5)); // inside the sphere, 1.5 deep
        r.add(0, Vec3::new(0.0, 5.0, 2.05)); // against it
        r.add(0, Vec3::new(0.0, 5.0, 3.0)); // clear
        r.add(0, Vec3::new(11.0, 1.0, 1.95)); // inside the box, near a face
        r.add(0, Vec3::new(-10.0, 5.0, 0.0)); // inside a removed sphere: clear
        for k in 0..far {
            r.world.add_obstacle(Shape::Sphere {
                center: Vec3::new(-40.0 + k as f32, 40.0, 40.0),
                radius: 0.3,
            });
        }
        for _ in 0..10 {
            r.tick(&[]);
        }
        r.health()
    }

    #[test]
    fn signed_distance_of_boxes_and_spheres() {
        let b = Shape::Box(Aabb::new(Vec3::ZERO, Vec3::new(4.0, 2.0, 2.0)));
        assert!(close(
            signed_distance(&b, Vec3::new(1.0, 1.0, 1.0)) as f64,
            -1.0,
            1e-6
        ));
        assert!(close(
            signed_distance(&b, Vec3::new(3.8, 1.0, 1.0)) as f64,
            -0.2,
            1e-6
        ));
        assert!(close(
            signed_distance(&b, Vec3::new(7.0, 6.0, 1.0)) as f64,
            5.0,
            1e-6
        ));
        let s = Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        };
        assert!(close(
            signed_distance(&s, Vec3::new(0.0, 0.25, 0.0)) as f64,
            -0.75,
            1e-6
        ));
    }

    #[test]
    fn messages_per_agent_second() {
        let mut r = Rig::new(&["fish"]);
        r.add(0, Vec3::ZERO);
        r.add(0, Vec3::X * 4.0);
        let msg = Event::Message {
            from: AgentId(1),
            kind: MessageKind::Danger,
            radius: 5.0,
        };
        for t in 1..=20u64 {
            r.tick(if t.is_multiple_of(5) {
                std::slice::from_ref(&msg)
            } else {
                &[]
            });
        }
        // 4 messages over 2 agents × 1 s.
        assert!(close(
            r.health().species[0].messages_per_agent_second,
            2.0,
            1e-12
        ));
    }

    #[test]
    fn tick_zero_and_repeated_ticks_are_not_counted() {
        let mut r = Rig::new(&["fish"]);
        r.add(0, Vec3::ZERO);
        r.monitor.observe_events(&r.world, &[]);
        r.tick(&[]);
        r.monitor.observe_events(&r.world, &[]);
        let h = r.health();
        assert_eq!((h.ticks, h.species[0].agent_ticks), (1, 1));
    }

    #[test]
    fn the_report_reads_back_from_json() {
        let mut r = Rig::new(&["fish"]);
        r.world.add_obstacle(Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        });
        let a = r.add(0, Vec3::ZERO);
        for t in 1..=130u64 {
            r.agent(a).speed = 0.0;
            r.tick(&if t == 3 {
                vec![transition(0, SWIM, REST)]
            } else {
                vec![]
            });
            r.agent(a).mind.current = SWIM;
        }
        let h = r.health();
        let json = h.to_json();
        assert!(json["warnings"].as_array().is_some_and(|w| !w.is_empty()));
        let back: Health = serde_json::from_value(json).unwrap();
        assert_eq!(back, h);
    }
}
