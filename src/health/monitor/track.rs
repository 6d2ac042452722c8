//! The monitor's per-agent pass after every tick, and the runs it keeps open per agent: stopped
//! ticks in one behavior (frozen episodes), ticks at the pitch limit, turning over windows,
//! closeness to obstacles.

use super::place::{near, place_of, signed_distance};
use super::{Monitor, SpeciesAcc};
use crate::health::{NextTo, Spot, PITCH_LIMIT_MARGIN, STOPPED_SPEED};
use crate::world::{Obstacle, World};
use glam::Vec3;

/// A frozen episode, its length updated when it ends.
#[derive(Debug, Clone)]
pub(super) struct FrozenRec {
    pub(super) species: u16,
    pub(super) behavior: u16,
    pub(super) agent: u32,
    pub(super) start: u64,
    pub(super) ticks: u64,
    pub(super) pos: Vec3,
    pub(super) near: NextTo,
}

/// What the monitor follows of one agent (by id).
#[derive(Debug, Clone, Default)]
pub(super) struct Track {
    pub(super) seen: bool,
    pub(super) species: u16,
    /// Behavior at the last observation.
    pub(super) behavior: u16,
    /// Current run of stopped ticks in `behavior`: first tick and length.
    pub(super) stop_start: u64,
    pub(super) stop_len: u64,
    /// Index in the frozen list while the stop is a frozen episode.
    pub(super) frozen: Option<usize>,
    pub(super) frozen_any: bool,
    pub(super) frozen_in: Vec<u16>,
    /// Tick the current behavior episode started, once one started with a transition the
    /// monitor saw (the behavior an agent spawns in was not chosen: its episode is not counted).
    pub(super) episode_start: Option<u64>,
    /// The last transition: (from, to, tick).
    pub(super) last_switch: Option<(u16, u16, u64)>,
    pub(super) transitions: u64,
    pub(super) last_switch_tick: u64,
    /// Current run of ticks at the pitch limit.
    pub(super) pin_start: u64,
    pub(super) pin_len: u64,
    pub(super) prev_forward: Vec3,
    /// Position and tick at the last observation (how far it really went).
    pub(super) prev_pos: Vec3,
    pub(super) prev_tick: u64,
    pub(super) window_forward: Vec3,
    pub(super) window_turn: f32,
    pub(super) window_len: u32,
    pub(super) window_tick: u64,
    pub(super) inside_ever: bool,
}

/// Up to this many obstacles, each agent tests every one (against its bounding sphere first);
/// past it, an obstacle grid lists the ones near an agent.
pub(super) const SCAN_OBSTACLES: usize = 32;

/// Angle (rad) between two unit vectors, accurate for small angles too.
#[inline]
fn angle(a: Vec3, b: Vec3) -> f32 {
    crate::frame::atan2(a.cross(b).length(), a.dot(b))
}

/// Keeps the larger of `slot` and `(len, spot)` (the earlier one on ties).
fn keep_longest(slot: &mut Option<(u64, Spot)>, len: u64, spot: Spot) {
    if slot.is_none_or(|(l, _)| len > l) {
        *slot = Some((len, spot));
    }
}

impl Monitor {
    /// Per agent: stops, frozen episodes, the pitch limit, turning, obstacles.
    pub(super) fn agents(&mut self, world: &World, tick: u64) {
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
}

/// Ends the agent's open runs (a stop, a stretch at the pitch limit).
pub(super) fn close_runs(t: &mut Track, id: u32, acc: &mut [SpeciesAcc], frozen: &mut [FrozenRec]) {
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
