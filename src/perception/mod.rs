//! Stage 2 of the tick: perception (seed 000 §1, seed 001 vision, occlusion and perceived
//! strength, seed 002 non-spherical volume).
//!
//! For every agent, the spatial index yields candidates within its largest sensing range; each is
//! classified by the species' relations (food, predator, kin, mate, other), tested against vision
//! (sphere `v_r` limited to a cone, or a custom body-frame [`Volume`], not fully occluded by
//! obstacles: see [`occlusion`]) and smell (sphere `O_r`), given its bearing, elevation and sector,
//! and folded into a per-category [`Summary`]. Results go into lists of 64 rows each, written in
//! place (a row keeps the summaries it perceived and the percepts it kept); a list keeps its room
//! from tick to tick and reallocates only when what its rows keep changes a lot. The stage runs
//! in parallel with identical results.
//!
//! Cost: neighbors are read from a compact per-tick body record, obstacles from an
//! [`ObstacleGrid`], and the two inverse trigonometric calls of a bearing are spent only on the
//! percepts kept (and, in the pipeline, only on those a behavior can read).
//!
//! This file holds the result rows ([`Perception`]) and the stage's orchestration
//! ([`Perception::run`]): gather the tick's copies (`gather.rs`), index the obstacles, then
//! walk every perceiver in parallel (`view.rs`, `walk.rs`). A species' senses, relations and
//! reads are in `senses.rs`, the sense test in `eye.rs`, the kept percepts in `keep.rs`, the
//! summaries in `fold.rs`, the bounded kin neighborhood (the nearest `n` kin, an opt-in beside
//! the paper's metric one) in `nearest.rs`.

mod eye;
mod fold;
mod gather;
pub mod group;
mod keep;
pub mod kin;
mod nearest;
pub mod occlusion;
mod rows;
mod senses;
pub mod strength;
#[cfg(test)]
mod tests;
mod types;
mod view;
pub mod volume;
mod walk;

pub(crate) use group::SumsOut;
pub use group::{GroupAcc, GroupQueries, GroupQuery, GroupSum};
pub use occlusion::Occluders;
pub use senses::{Reads, Relations, SenseParams};
pub use strength::Strength;
use types::Stored;
pub use types::{Category, Level, Percept, Sector, Sectors, Sense, Source, Summary, MAX_SOURCES};
pub use volume::{Extent, Volume};

use crate::index::{Grid, ObstacleGrid};
use crate::world::World;
use fold::Fold;
use gather::{Body, Gathered, Tag};
use glam::{Vec3, Vec3A};
use rows::{Held, RowMask};
use view::View;

/// Most percepts a species may keep per agent ([`SenseParams::max_percepts`]).
pub const MAX_PERCEPTS: usize = 32;
/// Largest kin neighborhood a species may ask for ([`SenseParams::neighbors`]).
pub const MAX_NEIGHBORS: u32 = 4096;
/// Percepts kept per agent unless the species says otherwise.
pub const DEFAULT_PERCEPTS: usize = 16;
// Kept percepts are flagged in a `u32` bit mask.
const _: () = assert!(MAX_PERCEPTS <= 32);

/// Per-agent perception results of one tick.
#[derive(Debug, Clone, Default)]
pub struct Perception {
    /// Kept percepts of every agent by row (see `by_grid`), [`SUMMARY_CHUNK`] rows a list: row
    /// `r`'s `counts[r]` are at `percept_at[r]` in list `r / SUMMARY_CHUNK`. A row has room for
    /// `rooms[r]` (its species' slots) while it is walked, and keeps only what it kept: a flocker
    /// with 8 slots and a rock now and then keeps a quarter of a percept on average (320 bytes a
    /// row otherwise). Each is held in 20 bytes ([`Stored`]): its size and bearing are read back
    /// by [`Perception::percepts_in`].
    percept_chunks: Vec<Vec<Stored>>,
    /// The percepts fed to rows this tick (script tests) as they were given, by row: their
    /// bearings and sizes are their own, not worked out from the world.
    fed: std::collections::BTreeMap<usize, Vec<Percept>>,
    /// Per species, the distance within which its agent percepts get their bearing
    /// ([`Reads::bearing_range`]) this tick.
    bearing_ranges: Vec<Option<f32>>,
    /// Each obstacle's size (its shape's diagonal) this tick, by index.
    obstacle_sizes: Vec<f32>,
    percept_at: Vec<u16>,
    rooms: Vec<u8>,
    counts: Vec<u16>,
    /// Summaries of every agent by row, [`SUMMARY_CHUNK`] rows a list: row `r`'s are at
    /// `held_at[r]` in list `r / SUMMARY_CHUNK`, those of the categories in `held[r]`: of what
    /// its species can perceive this tick (`row_masks[r]`, see [`rows`]), what it perceived.
    /// An empty summary is not kept (a reef fish perceives two or three of its five
    /// categories at a time: 280 bytes a row otherwise), and a kept one is held without its
    /// mean heading ([`rows::Held`]).
    summary_chunks: Vec<Vec<Held>>,
    /// The mean headings of the same summaries, in the same places, while some species reads
    /// them (`keep_headings`; scripts alone do); empty otherwise (12 bytes a summary).
    heading_chunks: Vec<Vec<Vec3>>,
    keep_headings: bool,
    held: Vec<RowMask>,
    held_at: Vec<u16>,
    row_masks: Vec<RowMask>,
    /// The mask of each species this tick.
    species_masks: Vec<RowMask>,
    /// Whether every row holds every category (while percepts are fed to agents).
    full_rows: bool,
    /// How far a bounded kin neighborhood reached this tick, by row (0 without a bound): where
    /// the agent's next walk starts. Empty while no species has a bound (4 bytes an agent
    /// nobody reads).
    reaches: Vec<f32>,
    /// Group sums of every agent by row, `sum_starts[r]..sum_starts[r + 1]` for row `r`: of
    /// each query of its species, in order, the words it folds into ([`GroupSum::pack`]; a
    /// separation keeps 16 bytes, not a whole sum's 48).
    sums: Vec<u32>,
    sum_starts: Vec<u32>,
    /// The group queries of each species this tick (how to read a row's words back).
    queries: Vec<GroupQueries>,
    /// Whether the outputs' rows are in the agent grid's order (an agent's row is then its slot,
    /// `slot_of`), not in agent order. Perceivers on the general path are walked in the grid's
    /// order when the grid indexes exactly the world's agents: perceivers next to each other in
    /// the walk are then next to each other in space, and their neighborhoods are read from
    /// cache.
    by_grid: bool,
    /// Yaw and pitch of the agent of each row at the start of the tick: when the rows are in
    /// the grid's order (the rest of what a perceiver reads of itself is in `near`, `tags` and
    /// the grid's positions), and in agent order while some row may keep percepts (their
    /// bearings are worked out from it when read).
    angles: Vec<[f32; 2]>,
    /// What a perceiver reads of each agent, gathered once per tick in the agent grid's order,
    /// so that a neighbor costs one small sequential read instead of a walk into the full agent
    /// and two `sin_cos`. Held only while some agent perceives by the walks (the kin kernel
    /// reads its lanes).
    near: Vec<Body>,
    /// Species and sex of the same agents, in the same order.
    tags: Vec<Tag>,
    /// Bounding-box diagonals of the same agents, in the same order (read for kept percepts).
    diagonals: Vec<f32>,
    /// Slot of each agent in the grid's order, by agent index (`u32::MAX` when the grid lacks
    /// it). Empty when the grid indexes exactly the agents and the rows are in agent order:
    /// the walk then reads the grid's own (`Grid::slots`).
    slot_of: Vec<u32>,
    /// What others read of each agent this tick, by agent index: the grid-order records are
    /// copied from it (reading every agent's record once, in order, on the thread that last
    /// wrote it, is cheaper than reading the records in the grid's order), and agents' passes
    /// read each other here.
    gathered: Vec<Gathered>,
    /// Each agent's position a tick before, by agent index: held only while some species
    /// keeps agent percepts (a pursuer reads its target's), empty otherwise.
    prev_pos: Vec<Vec3>,
    /// `near` again, one array per component, for the kin kernel (filled only when a species
    /// perceives by it).
    lanes: kin::KinLanes,
    /// Cosine bound of each species' vision cone, this tick.
    cos_mins: Vec<f32>,
    /// Which species may perceive by the kin kernel, this tick.
    kernel: Vec<bool>,
    /// Obstacles by cell, so a perceiver looks only at those that may be in range.
    obstacle_grid: ObstacleGrid,
    /// For each species with a bounded kin neighborhood, the agents it perceives as other
    /// than kin.
    others: nearest::Others,
}

/// One agent's share of the stage's output buffers.
struct AgentOut<'a> {
    slots: &'a mut [Percept],
    count: &'a mut u16,
    /// Its summaries by category: those of the categories in `mask` are written.
    summary: &'a mut [Summary; Category::COUNT],
    mask: RowMask,
    reach: &'a mut f32,
    /// Its group sums' words (see [`Perception::sums`]).
    sums: &'a mut [u32],
    /// The kin kernel's buffers, the worker's.
    kin: &'a mut kin::KinBuf,
}

/// The output buffers of agents `lo..lo + counts.len()` (`lo` a multiple of
/// [`SUMMARY_CHUNK`]).
struct Outs<'a> {
    lo: usize,
    /// The percept lists of these rows, one per [`SUMMARY_CHUNK`].
    percepts: &'a mut [Vec<Stored>],
    percept_at: &'a mut [u16],
    rooms: &'a [u8],
    counts: &'a mut [u16],
    /// The summary lists of these rows, one per [`SUMMARY_CHUNK`], and their mean headings'
    /// (kept with `keep_headings` only).
    summaries: &'a mut [Vec<Held>],
    headings: &'a mut [Vec<Vec3>],
    keep_headings: bool,
    held: &'a mut [RowMask],
    held_at: &'a mut [u16],
    masks: &'a [RowMask],
    reaches: &'a mut [f32],
    sums: &'a mut [u32],
}

/// Room for an agent's percepts (see [`Perception::percepts_in`]); a worker keeps one from
/// agent to agent.
#[derive(Debug, Clone)]
pub struct PerceptBuf([Percept; MAX_PERCEPTS]);

impl Default for PerceptBuf {
    fn default() -> Self {
        PerceptBuf([keep::EMPTY; MAX_PERCEPTS])
    }
}

/// Room for an agent's summaries by category (see [`Perception::summaries_in`]); a worker
/// keeps one from agent to agent.
#[derive(Debug, Clone)]
pub struct SummaryBuf {
    by: [Summary; Category::COUNT],
    /// The categories last written; the others are `Summary::NONE`.
    mask: RowMask,
}

impl Default for SummaryBuf {
    fn default() -> Self {
        SummaryBuf {
            by: [Summary::NONE; Category::COUNT],
            mask: RowMask::ALL,
        }
    }
}

/// Rows a task of the parallel walk takes, and rows a list of summaries or percepts holds.
const SUMMARY_CHUNK: usize = 64;

/// Makes `list` `need` long for the row about to be written in place after the rows before it.
/// Short of room, it grows by a quarter at least, but never past `most()` (what every row of its
/// chunk could hold): a list grown by doubling would hold a third more than it needs.
#[inline(always)]
fn room_for<T: Copy>(list: &mut Vec<T>, need: usize, most: impl FnOnce() -> usize, fill: T) {
    if list.len() < need {
        grow(list, need, most(), fill);
    }
}

/// [`room_for`]'s rare part.
#[cold]
fn grow<T: Copy>(list: &mut Vec<T>, need: usize, most: usize, fill: T) {
    if list.capacity() < need {
        let short = need - list.len();
        let quarter = (list.capacity() / 4).min(most.saturating_sub(list.len()));
        list.reserve_exact(short.max(quarter));
    }
    list.resize(need, fill);
}

/// Shrinks a chunk's list whose rows hold `used` entries. It keeps its room from tick to tick:
/// once it has more than `most`, down to an eighth and `spare()` more.
fn settle<T>(list: &mut Vec<T>, used: usize, most: usize, spare: impl FnOnce() -> usize) {
    if list.capacity() > most {
        list.truncate(used);
        list.shrink_to(used + used / 8 + spare());
    }
}

impl<'a> Outs<'a> {
    /// Calls `f(i, out)` for every agent, splitting the range in halves of whole chunks on
    /// rayon's pool (each agent writes only its own group sums, and its summaries and percepts
    /// after those of the rows before it in its chunk: the result does not depend on the
    /// split). `sum_starts[r]..sum_starts[r + 1]` are row `r`'s group sums.
    fn for_each(self, sum_starts: &[u32], f: &(impl Fn(usize, AgentOut) + Sync)) {
        let n = self.counts.len();
        if n == 0 {
            return;
        }
        if n <= SUMMARY_CHUNK {
            let lo = self.lo;
            let mut sums = self.sums;
            let list = &mut self.summaries[0];
            let headings = &mut self.headings[0];
            let keep_headings = self.keep_headings;
            let kept = &mut self.percepts[0];
            // Rows are written one after another, in lists that keep their room from tick to
            // tick: at first what every row could hold. The walk writes every summary of its
            // row and every percept it keeps here (none is cleared), then what it perceived is
            // kept in the lists.
            let mut row = [Summary::NONE; Category::COUNT];
            let mut slots = [keep::EMPTY; MAX_PERCEPTS];
            let masks = self.masks;
            let rooms = self.rooms;
            let most_summaries = || masks.iter().map(|m| m.len()).sum();
            let most_percepts = || rooms.iter().map(|&r| r as usize).sum();
            if list.capacity() == 0 {
                list.reserve_exact(most_summaries());
            }
            if keep_headings && headings.capacity() == 0 {
                headings.reserve_exact(most_summaries());
            }
            if kept.capacity() == 0 {
                kept.reserve_exact(most_percepts());
            }
            let (mut used, mut used_percepts) = (0, 0);
            let mut kin = kin::KinBuf::default();
            // Rows past the reaches held (none without a bound) write theirs to `spare`.
            let reaches = self.reaches.iter_mut().map(Some);
            let reaches = reaches.chain(std::iter::repeat_with(|| None));
            let rows = self.counts.iter_mut().zip(reaches).zip(masks);
            let held = self.held.iter_mut().zip(self.held_at.iter_mut());
            let percepts = self.percept_at.iter_mut().zip(rooms);
            let all = rows.zip(held).zip(percepts);
            for (k, ((((count, reach), &mask), (held, at)), (percept_at, &room))) in all.enumerate()
            {
                let i = lo + k;
                let ng = (sum_starts[i + 1] - sum_starts[i]) as usize;
                let (own_sums, rest) = std::mem::take(&mut sums).split_at_mut(ng);
                sums = rest;
                let mut spare = 0.0;
                f(
                    i,
                    AgentOut {
                        slots: &mut slots[..room as usize],
                        count,
                        summary: &mut row,
                        mask,
                        reach: reach.unwrap_or(&mut spare),
                        sums: own_sums,
                        kin: &mut kin,
                    },
                );
                // What it perceived of its categories is kept, in their order.
                let most = used + mask.len();
                room_for(list, most, most_summaries, Held::NONE);
                if keep_headings {
                    room_for(headings, most, most_summaries, Vec3::ZERO);
                }
                let mut k = used;
                *held = mask.perceived(&row, |s| {
                    list[k] = Held::new(s);
                    if keep_headings {
                        headings[k] = s.mean_heading;
                    }
                    k += 1;
                });
                *at = used as u16;
                used = k;
                let need = used_percepts + *count as usize;
                room_for(kept, need, most_percepts, Stored::new(&keep::EMPTY));
                for (p, s) in kept[used_percepts..need].iter_mut().zip(&slots) {
                    *p = Stored::new(s);
                }
                *percept_at = used_percepts as u16;
                used_percepts = need;
            }
            list.truncate(used);
            settle(list, used, used + used / 4 + Category::COUNT, || 0);
            if keep_headings {
                headings.truncate(used);
                settle(headings, used, used + used / 4 + Category::COUNT, || 0);
            } else if headings.capacity() > 0 {
                *headings = Vec::new();
            }
            // Kept percepts come and go with what is near: room for up to twice what the rows
            // keep is kept (a chunk that keeps a few more next tick does not grow its list
            // again), and when it shrinks, one more row's slots.
            kept.truncate(used_percepts);
            let widest = || rooms.iter().max().map_or(0, |&r| r as usize);
            let most = 2 * used_percepts + MAX_PERCEPTS;
            settle(kept, used_percepts, most, widest);
            return;
        }
        let chunks = n.div_ceil(SUMMARY_CHUNK);
        let mid = chunks / 2 * SUMMARY_CHUNK;
        let sum_mid = (sum_starts[self.lo + mid] - sum_starts[self.lo]) as usize;
        let (p0, p1) = self.percepts.split_at_mut(chunks / 2);
        let (pa0, pa1) = self.percept_at.split_at_mut(mid);
        let (o0, o1) = self.rooms.split_at(mid);
        let (c0, c1) = self.counts.split_at_mut(mid);
        let (s0, s1) = self.summaries.split_at_mut(chunks / 2);
        let (d0, d1) = self.headings.split_at_mut(chunks / 2);
        let (h0, h1) = self.held.split_at_mut(mid);
        let (a0, a1) = self.held_at.split_at_mut(mid);
        let (r0, r1) = self.reaches.split_at_mut(mid.min(self.reaches.len()));
        let (m0, m1) = self.masks.split_at(mid);
        let (g0, g1) = self.sums.split_at_mut(sum_mid);
        let left = Outs {
            lo: self.lo,
            percepts: p0,
            percept_at: pa0,
            rooms: o0,
            counts: c0,
            summaries: s0,
            headings: d0,
            keep_headings: self.keep_headings,
            held: h0,
            held_at: a0,
            masks: m0,
            reaches: r0,
            sums: g0,
        };
        let right = Outs {
            lo: self.lo + mid,
            percepts: p1,
            percept_at: pa1,
            rooms: o1,
            counts: c1,
            summaries: s1,
            headings: d1,
            keep_headings: self.keep_headings,
            held: h1,
            held_at: a1,
            masks: m1,
            reaches: r1,
            sums: g1,
        };
        crate::par::join(
            || left.for_each(sum_starts, f),
            || right.for_each(sum_starts, f),
        );
    }
}

impl Perception {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Makes every row hold every category from the next run on (`Pipeline` does while it
    /// feeds percepts, which may be of any category, to agents), or again only those each
    /// species can perceive.
    pub fn set_full_rows(&mut self, yes: bool) {
        self.full_rows = yes;
    }

    /// Row of agent `i`'s outputs.
    #[inline]
    fn row(&self, i: usize) -> usize {
        if self.by_grid {
            self.slot_of[i] as usize
        } else {
            i
        }
    }

    /// Percepts of agent `i`: the nearest [`SenseParams::max_percepts`], and the nearest of each
    /// category; none when its species reads no individual percept. A copy: see
    /// [`Perception::percepts_in`].
    pub fn percepts(&self, i: usize) -> Vec<Percept> {
        let mut buf = PerceptBuf::default();
        self.percepts_in(i, &mut buf).to_vec()
    }

    /// [`Perception::percepts`] into `buf`. Each is read back from its 20 bytes: its size is
    /// its source's (the agent's as perception saw it, an obstacle's, 0 for food), and its
    /// bearing and elevation are worked out from its offset and the perceiver's heading at the
    /// start of the tick where the species reads them (within [`Reads::bearing_range`], every
    /// obstacle, each category's nearest; 0 elsewhere), as the walk would have.
    #[inline]
    pub fn percepts_in<'a>(&self, i: usize, buf: &'a mut PerceptBuf) -> &'a [Percept] {
        let r = self.row(i);
        let n = self.counts[r] as usize;
        if n == 0 {
            return &[];
        }
        if !self.fed.is_empty() {
            if let Some(fed) = self.fed.get(&r) {
                buf.0[..fed.len()].copy_from_slice(fed);
                return &buf.0[..fed.len()];
            }
        }
        let at = self.percept_at[r] as usize;
        let stored = &self.percept_chunks[r / SUMMARY_CHUNK][at..at + n];
        let out = &mut buf.0[..n];
        for (p, s) in out.iter_mut().zip(stored) {
            let size = match s.source() {
                Source::Agent(j) => self.gathered.get(j as usize).map_or(0.0, |g| g.diagonal),
                Source::Obstacle(k) => self.obstacle_sizes.get(k as usize).copied().unwrap_or(0.0),
                Source::Food(_) | Source::Injected => 0.0,
            };
            *p = s.percept(size);
        }
        // The slots that are some category's nearest, as the summaries name them.
        let (row, _, _) = self.summary_row_at(r);
        let nearest = row
            .iter()
            .filter_map(Held::nearest)
            .fold(0u32, |m, k| m | 1 << k);
        // By agent (the agent pass reads `gathered` in its order already).
        let species = self.gathered[i].tag.species;
        let range = self.bearing_ranges.get(species as usize).copied().flatten();
        let [yaw, pitch] = self.angles[r];
        keep::bearings(out, nearest, range, yaw, pitch);
        out
    }

    /// Obstacles (indices into `World::obstacles`, active or not) that may be near `p`: every
    /// obstacle within the perception reach of the tick of any point of `p`'s grid cell.
    #[inline]
    pub fn obstacles_near(&self, p: Vec3) -> &[u32] {
        self.obstacle_grid.near(p)
    }

    /// Summaries of agent `i`, indexed by [`Category`].
    #[inline]
    pub fn summaries(&self, i: usize) -> [Summary; Category::COUNT] {
        let (row, headings, mask) = self.summary_row(i);
        mask.expand(row, headings)
    }

    /// Agent `i`'s row of summaries, their mean headings (none where no species reads them)
    /// and the categories it holds.
    #[inline]
    fn summary_row(&self, i: usize) -> (&[Held], &[Vec3], RowMask) {
        self.summary_row_at(self.row(i))
    }

    /// [`Perception::summary_row`] of row `r`.
    #[inline]
    fn summary_row_at(&self, r: usize) -> (&[Held], &[Vec3], RowMask) {
        let held = self.held[r];
        let at = self.held_at[r] as usize;
        let c = r / SUMMARY_CHUNK;
        let row = &self.summary_chunks[c][at..at + held.len()];
        let headings = match self.heading_chunks.get(c) {
            Some(h) if self.keep_headings => &h[at..at + held.len()],
            _ => &[],
        };
        (row, headings, held)
    }

    /// [`Perception::summaries`] into `buf`, whose categories the row does not hold stay empty
    /// from the last agent of the same kind (a boid's pass writes its kin summary alone).
    #[inline]
    pub fn summaries_in<'a>(
        &'a self,
        i: usize,
        buf: &'a mut SummaryBuf,
    ) -> &'a [Summary; Category::COUNT] {
        let (row, headings, mask) = self.summary_row(i);
        if buf.mask != mask {
            buf.by = [Summary::NONE; Category::COUNT];
            buf.mask = mask;
        }
        mask.fill(row, headings, &mut buf.by);
        &buf.by
    }

    /// Group sums of agent `i` as the row keeps them: of each query of its species'
    /// [`Reads::groups`], in order, the words it folds into ([`crate::ctx::Ctx::group`] reads
    /// one back).
    #[inline]
    pub fn group_words(&self, i: usize) -> &[u32] {
        let r = self.row(i);
        &self.sums[self.sum_starts[r] as usize..self.sum_starts[r + 1] as usize]
    }

    /// Group sums of agent `i`, one per query of its species' [`Reads::groups`], in order.
    pub fn group_sums(&self, i: usize) -> Vec<GroupSum> {
        let words = self.group_words(i);
        if words.is_empty() {
            return Vec::new();
        }
        let s = self.gathered[i].tag.species as usize;
        let queries = self.queries.get(s).unwrap_or(&GroupQueries::EMPTY);
        queries
            .packed(words)
            .map(|(q, own)| GroupSum::unpack(q, own))
            .collect()
    }

    /// Velocity of agent `i` at the start of the tick ([`crate::world::Agent::velocity`], bit
    /// for bit), as its neighbors saw it.
    #[inline]
    pub fn velocity(&self, i: usize) -> Option<Vec3> {
        self.gathered.get(i).map(|g| g.body.velocity())
    }

    /// Radius of the bounding sphere of agent `i` ([`crate::world::Agent::radius`]), as
    /// perception saw it.
    #[inline]
    pub fn radius(&self, i: usize) -> Option<f32> {
        self.gathered.get(i).map(|g| g.diagonal * 0.5)
    }

    /// Position of agent `i` a tick before the start of this one
    /// ([`crate::world::Agent::prev_pos`]); `None` too when no species keeps agent percepts
    /// this tick (only a percept of agent `i` leads to asking).
    #[inline]
    pub fn prev_pos(&self, i: usize) -> Option<Vec3> {
        self.prev_pos.get(i).copied()
    }

    /// Summaries the rows may hold: those of the categories their species can perceive.
    #[cfg(test)]
    fn row_room(&self) -> usize {
        self.row_masks.iter().map(|m| m.len()).sum()
    }

    /// Summaries the rows hold.
    #[cfg(test)]
    fn summaries_held(&self) -> usize {
        self.summary_chunks.iter().map(Vec::len).sum()
    }

    /// Room for percepts in the rows' lists, and the slots the rows had while walked.
    #[cfg(test)]
    fn percept_room(&self) -> [usize; 2] {
        let room = self.percept_chunks.iter().map(Vec::capacity).sum();
        [room, self.rooms.iter().map(|&r| r as usize).sum()]
    }

    /// Number of agents perceived for.
    pub fn len(&self) -> usize {
        self.counts.len()
    }

    /// Whether there are no results.
    pub fn is_empty(&self) -> bool {
        self.counts.is_empty()
    }

    /// Runs perception for every agent of `world`. `senses[s]` are species `s`'s senses. Every
    /// agent keeps its percepts, each with its bearing and elevation. `agents` is the grid of
    /// the agents' positions (entry `i` at `world.agents[i].pos`), `food` that of the food's.
    pub fn run(
        &mut self,
        world: &World,
        agents: &Grid,
        food: &Grid,
        senses: &[SenseParams],
        relations: &Relations,
    ) {
        self.run_selective(world, agents, food, senses, relations, &[]);
    }

    /// Like [`Perception::run`], but does for species `s` only what `reads[s]` says it reads:
    /// percepts kept or not, bearings (two inverse trigonometric calls per percept) only within
    /// a range, group sums. A species without an entry gets [`Reads::default`].
    pub fn run_selective(
        &mut self,
        world: &World,
        agents: &Grid,
        food: &Grid,
        senses: &[SenseParams],
        relations: &Relations,
        reads: &[Reads],
    ) {
        let default = SenseParams::default();
        let unsensed = self.gather(world, agents, senses, relations, reads);
        let kernel = self.kernel.iter().any(|&k| k);
        let near = &self.near[..];
        let diagonals = &self.diagonals[..];
        // How far beyond its range a perceiver must look for a body whose edge may be in range
        // (seed 001's "any part", `Extent::AnyPart`).
        let body_reach = diagonals.iter().fold(0.0f32, |m, &d| m.max(d)) * 0.5;
        let lanes = (kernel && self.lanes.len() == agents.positions().len()).then_some(&self.lanes);
        let reach = senses
            .iter()
            .chain(unsensed.then_some(&default))
            .map(|s| s.query_radius())
            .fold(0.0, f32::max);
        self.obstacle_grid
            .update(world.bounds, reach, &world.obstacles);
        self.others.update(agents, &self.tags, senses, relations);
        let view = View {
            world,
            near,
            tags: &self.tags,
            diagonals,
            body_reach,
            lanes,
            kernel: &self.kernel,
            // The grid's own inverse where no copy is kept (see `slot_of`).
            slot_of: if self.slot_of.len() == self.gathered.len() {
                &self.slot_of
            } else {
                agents.slots()
            },
            agents,
            food,
            obstacle_grid: &self.obstacle_grid,
            others: &self.others,
            relations,
            by_grid: self.by_grid,
            angles: &self.angles,
            gathered: &self.gathered,
            senses,
            reads,
            cos_mins: &self.cos_mins,
            default,
            everything: Reads::default(),
            default_cos_min: eye::cos_min(default.vision_half_angle),
        };
        let outs = Outs {
            lo: 0,
            percepts: &mut self.percept_chunks,
            percept_at: &mut self.percept_at,
            rooms: &self.rooms,
            counts: &mut self.counts,
            summaries: &mut self.summary_chunks,
            headings: &mut self.heading_chunks,
            keep_headings: self.keep_headings,
            held: &mut self.held,
            held_at: &mut self.held_at,
            masks: &self.row_masks,
            reaches: &mut self.reaches,
            sums: &mut self.sums,
        };
        outs.for_each(&self.sum_starts, &|r, out| view.perceive_row(r, out));
        // Each agent's reach, by agent, for its next walk (rows are in the grid's order, which
        // changes every tick).
        if self.others.any() {
            let n = self.counts.len();
            let reaches = &self.reaches;
            let row = |i: usize| {
                if self.by_grid {
                    self.slot_of[i] as usize
                } else {
                    i
                }
            };
            self.others.keep_hints(n, |i| reaches[row(i)]);
        }
    }

    /// Replaces what agent `i` (at `pos`) perceived this tick by `percepts` (the nearest
    /// [`MAX_PERCEPTS`] kept) and rebuilds its summaries from them, as the stage would have.
    /// Agent percepts carry no heading or velocity, so their means are zero. The summaries of
    /// categories the row does not hold are not kept: see [`Perception::set_full_rows`].
    pub fn inject(&mut self, i: usize, pos: Vec3, percepts: &[Percept]) {
        if i >= self.counts.len() {
            return;
        }
        let i = self.row(i);
        let mut room = [keep::EMPTY; MAX_PERCEPTS];
        let slots = &mut room[..self.rooms[i] as usize];
        // Fed percepts stand for no object of the world: no neighbor for the group rules.
        let sums = self.sum_starts[i] as usize..self.sum_starts[i + 1] as usize;
        self.sums[sums].fill(0);
        // Folded as perception folds what it perceives (no heading or velocity: their means
        // are zero), the nearest of each category kept.
        let mut fold = Fold::<true>::new(slots);
        for p in percepts {
            let at = Vec3A::from(pos + p.offset);
            let d = p.dist;
            fold.take(
                p.category(),
                p.sense(),
                d,
                || d,
                at,
                Vec3A::ZERO,
                Vec3A::ZERO,
                |_| *p,
            );
        }
        let mut by = [Summary::NONE; Category::COUNT];
        let kept = fold.finish(&mut by);
        // The row's percepts and summaries replace its old ones in its chunk's lists; the rows
        // after it in the lists move by the difference.
        let c = i / SUMMARY_CHUNK;
        let end = ((c + 1) * SUMMARY_CHUNK).min(self.held.len());
        let old = self.counts[i] as usize;
        replace_row(
            &mut self.percept_chunks[c],
            &mut self.percept_at[i..end],
            old,
            kept.iter().map(Stored::new),
        );
        self.counts[i] = kept.len() as u16;
        // Read back as given (their bearings and sizes are their own).
        self.fed.insert(i, kept.to_vec());
        let mask = self.row_masks[i];
        let mut row = [Summary::NONE; Category::COUNT];
        let mut k = 0;
        let held = mask.perceived(&by, |s| {
            row[k] = *s;
            k += 1;
        });
        let old = self.held[i].len();
        let new = &row[..k];
        if self.keep_headings {
            // Moved with the summaries (the row's starts are moved once, below).
            let mut starts = self.held_at[i..end].to_vec();
            let headings = new.iter().map(|s| s.mean_heading);
            replace_row(&mut self.heading_chunks[c], &mut starts, old, headings);
        }
        replace_row(
            &mut self.summary_chunks[c],
            &mut self.held_at[i..end],
            old,
            new.iter().map(Held::new),
        );
        self.held[i] = held;
    }
}

/// Replaces the `old` entries of a row by `new` in its chunk's `list`. `starts` are where that
/// row and the rows after it in the chunk start; the later ones move by the difference.
fn replace_row<T>(
    list: &mut Vec<T>,
    starts: &mut [u16],
    old: usize,
    new: impl ExactSizeIterator<Item = T>,
) {
    let at = starts[0] as usize;
    let len = new.len();
    list.splice(at..at + old, new);
    for a in &mut starts[1..] {
        *a = (*a as usize + len).wrapping_sub(old) as u16;
    }
}
