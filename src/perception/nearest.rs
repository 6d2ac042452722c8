//! The bounded kin neighborhood of stage 2 ([`SenseParams::neighbors`]): a perceiver takes the
//! nearest `n` kin within range instead of every one (seed 000 §1 perceives everything within
//! `O_r`, the default).
//!
//! Why the runtime adds it: a school packs tighter as a run goes on (reef fish perceive about
//! 29 kin each at the start of a 10,000-fish run and over 100 by tick 1,500), and with the
//! paper's metric neighborhood the cost of perception grows with it. With a bound, the walk
//! takes the kin within a distance a little beyond where the perceiver's last walk found its
//! `n`, widens it (walking the wider box whole, which is rare) until it holds `n`, and selects
//! the nearest `n`, so the cost stays bounded however dense the school. Predators, food and
//! other species are still perceived within the whole range: they are walked in a grid of their
//! own, which holds only the agents a bounded species perceives as something other than kin.
//!
//! Which `n` kin: the nearest, ties broken by the grid's order; they are then folded nearest
//! first (the same ties broken the same way), so the result is the same whatever distance the
//! walk started from.

use super::gather::Tag;
use super::{Category, Relations, SenseParams};
use crate::index::Grid;
use glam::{Vec3, Vec3A};
use std::cell::RefCell;

/// The agents each bounded species perceives as something other than kin, in a grid of
/// their own (by species; empty for a species without a bound).
#[derive(Debug, Clone, Default)]
pub(super) struct Others {
    by_species: Vec<OtherGrid>,
    /// Where each agent's (by index) last walk found its nearest `n`: the next walk starts
    /// there. Only the cost depends on it (the nearest `n` are the same from any start), so a
    /// stale or missing hint after agents come and go changes no result.
    hints: Vec<f32>,
    /// Whether some species has a bound.
    any: bool,
}

/// One bounded species' others: a grid of them, and the agent grid slot of each entry.
#[derive(Debug, Clone, Default)]
pub(super) struct OtherGrid {
    grid: Grid,
    slots: Vec<u32>,
    points: Vec<Vec3>,
}

/// Whether some species of `senses` has a bounded kin neighborhood.
pub(super) fn any_bound(senses: &[SenseParams]) -> bool {
    senses.iter().any(|s| s.neighbors.is_some())
}

impl Others {
    /// Rebuilds the grids of the species with a bound from this tick's agent grid (`tags`: the
    /// species and sex of each of its slots).
    pub(super) fn update(
        &mut self,
        agents: &Grid,
        tags: &[Tag],
        senses: &[SenseParams],
        relations: &Relations,
    ) {
        self.by_species
            .resize_with(senses.len(), OtherGrid::default);
        self.any = any_bound(senses);
        let positions = agents.positions();
        for (s, (sense, others)) in senses.iter().zip(&mut self.by_species).enumerate() {
            others.slots.clear();
            others.points.clear();
            if sense.neighbors.is_none() {
                continue;
            }
            let row = relations.row(s);
            for (k, t) in tags.iter().enumerate() {
                let cat = row.get(t.species as usize).copied().flatten();
                if cat.is_some_and(|c| c != Category::Kin) {
                    others.slots.push(k as u32);
                    others.points.push(positions[k].into());
                }
            }
            // The agent grid's cells: a query then meets the others in the agent grid's order
            // (see `OtherGrid::for_each_within`).
            others
                .grid
                .rebuild_in(agents.layout(), others.points.iter().copied());
        }
    }

    /// Species `s`'s others, when it has a bound.
    pub(super) fn of(&self, s: usize) -> Option<&OtherGrid> {
        self.by_species.get(s)
    }

    /// Whether some species has a bound.
    pub(super) fn any(&self) -> bool {
        self.any
    }

    /// Where agent `i`'s last walk found its nearest `n` (0 when unknown).
    pub(super) fn hint(&self, i: usize) -> f32 {
        self.hints.get(i).copied().unwrap_or(0.0)
    }

    /// Keeps this tick's reach of each of the `n` agents (`reach(i)`) for their next walks.
    pub(super) fn keep_hints(&mut self, n: usize, reach: impl Fn(usize) -> f32) {
        self.hints.clear();
        self.hints.extend((0..n).map(reach));
    }
}

impl OtherGrid {
    /// Calls `visit(agent grid slot, position, squared distance)` for every other within
    /// `radius` of `here`, in the agent grid's order.
    #[inline]
    pub(super) fn for_each_within(
        &self,
        here: Vec3,
        radius: f32,
        mut visit: impl FnMut(usize, Vec3A, f32),
    ) {
        if self.slots.is_empty() {
            return;
        }
        let entries = self.grid.entries();
        // The fold takes the others in the agent grid's order, and a query meets them in it:
        // the grid has the agent grid's cells, its entries of a cell are in ascending order of
        // agent slot (they were listed so), and a query walks cells in ascending order, as the
        // agent grid's slots run.
        let mut last = None;
        self.grid.for_each_slot_within(here, radius, |k, p, d2| {
            let slot = self.slots[entries[k] as usize];
            debug_assert!(last < Some(slot), "others out of the agent grid's order");
            last = Some(slot);
            visit(slot as usize, p, d2);
        });
    }
}

thread_local! {
    /// The kin candidates of the bounded walk on this thread, as [`key`]s.
    static KEYS: RefCell<Vec<u64>> = const { RefCell::new(Vec::new()) };
}

/// Runs `f` with this thread's buffer `cell`, emptied (a perceiver's walk never nests
/// another's: the buffer is free, or a fresh one serves).
fn with_buffer<T: 'static, R>(
    cell: &'static std::thread::LocalKey<RefCell<Vec<T>>>,
    f: impl FnOnce(&mut Vec<T>) -> R,
) -> R {
    cell.with(|s| match s.try_borrow_mut() {
        Ok(mut v) => {
            v.clear();
            f(&mut v)
        }
        Err(_) => f(&mut Vec::new()),
    })
}

/// First box of the outward walk without a hint, as a share of the range; each next box is
/// `GROWTH` times wider, the last one the range itself.
const FIRST_BOX: f32 = 0.25;
const GROWTH: f32 = 1.25;

/// One perceiver's query: the nearest `n` kin within `radius` of `here`, leaving out slot `me`.
pub(super) struct KinQuery {
    pub(super) here: Vec3,
    pub(super) radius: f32,
    pub(super) me: usize,
    pub(super) n: usize,
}

/// Calls `visit(slot, position, squared distance)` for the nearest `q.n` kin (`is_kin(slot)`)
/// of the query in `agents`, nearest first (ties in the grid's order), starting a little beyond
/// `hint` (where the agent's last walk found its `n`; 0 when unknown); returns where this walk
/// found them (the range when fewer are within it).
#[inline]
pub(super) fn nearest_kin(
    agents: &Grid,
    q: KinQuery,
    hint: f32,
    is_kin: impl Fn(usize) -> bool,
    mut visit: impl FnMut(usize, Vec3A, f32),
) -> f32 {
    let KinQuery {
        here,
        radius,
        me,
        n,
    } = q;
    if n == 0 || radius.is_nan() || radius < 0.0 {
        return 0.0;
    }
    with_buffer(&KEYS, |keys| {
        let mut found = false;
        // Neighbors move little in a tick: a little beyond last tick's reach mostly suffices.
        let start = if hint > 0.0 {
            hint * 1.02
        } else {
            radius * FIRST_BOX
        };
        let mut h = start.min(radius);
        loop {
            // Only the kin within `h` are candidates (about half of what the box's cells hold):
            // a hair inside `h` below the range, so that rounding of the squared distances
            // cannot take one the box missed.
            let cut = if h >= radius {
                radius * radius
            } else {
                (h * 0.99999) * (h * 0.99999)
            };
            keys.clear();
            agents.for_each_slot_within(here, h, |k, _, d2| {
                if d2 <= cut && k != me && is_kin(k) {
                    keys.push(key(d2, k));
                }
            });
            // Every kin within the cut is in: once `n` of them are, they are the nearest `n`.
            if keys.len() >= n {
                found = true;
                break;
            }
            if h >= radius {
                break;
            }
            // Too few: a wider box, walked whole (rare once the hint is known).
            h = (h * GROWTH).min(radius);
        }
        // Distance first, then slot (keys are unique): the `n` nearest with ties in the grid's
        // order, nearest first, so the kept percepts fill with the nearest at once and the rest
        // are turned away by one compare each. The candidates are few (a little over `n` once
        // the hint is known): sorting them all costs less than selecting, then sorting `n`.
        keys.sort_unstable();
        keys.truncate(n);
        let reach = match keys.last() {
            Some(&c) if found => f32::from_bits((c >> 32) as u32).sqrt(),
            _ => radius,
        };
        let positions = agents.positions();
        for &c in keys.iter() {
            let k = c as u32 as usize;
            visit(k, positions[k], f32::from_bits((c >> 32) as u32));
        }
        reach
    })
}

/// A candidate as one integer that orders by squared distance, then by grid slot: a
/// non-negative float's bits order as the float does, so the selection and the sort compare
/// plain integers.
#[inline(always)]
fn key(d2: f32, slot: usize) -> u64 {
    ((d2.to_bits() as u64) << 32) | slot as u64
}
