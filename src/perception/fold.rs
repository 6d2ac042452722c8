//! The one place summaries are summed and divided (stage 2, seed 000 §1's per-category
//! summaries): running sums of each category while the neighbors are walked, the kept percepts
//! offered on the way (`keep`), and the means written out at the end. The kin kernel's sums are
//! written out here too, so that every summary is divided the same way.

use super::keep::{restore_nearest, Kept, EMPTY};
use super::rows::RowMask;
use super::{Category, Percept, Sense, Summary};
use glam::Vec3A;

/// Running sums of one category, kept in 16-byte lanes while the neighbors are walked,
/// written out as a [`Summary`] at the end.
#[derive(Debug, Clone, Copy)]
pub(super) struct Acc {
    pub(super) pos: Vec3A,
    pub(super) heading: Vec3A,
    pub(super) vel: Vec3A,
    pub(super) count: u32,
    pub(super) seen: u32,
    /// Ordering key of the nearest so far (squared distance) and its distance.
    pub(super) key: f32,
    pub(super) nearest: f32,
    /// `Σ 1/d` (predators only).
    pub(super) inv_dist: f32,
}

/// Nothing summed yet.
pub(super) const ACC: Acc = Acc {
    pos: Vec3A::ZERO,
    heading: Vec3A::ZERO,
    vel: Vec3A::ZERO,
    count: 0,
    seen: 0,
    key: f32::INFINITY,
    nearest: f32::INFINITY,
    inv_dist: 0.0,
};

impl Acc {
    /// Adds one percept of sense `sense` at squared distance `key` (distance `dist()`, taken
    /// only when it is the nearest so far).
    #[inline(always)]
    pub(super) fn note(
        &mut self,
        sense: Sense,
        key: f32,
        dist: impl Fn() -> f32,
        pos: Vec3A,
        heading: Vec3A,
        vel: Vec3A,
    ) {
        self.count += 1;
        self.seen += (sense == Sense::Vision) as u32;
        if key < self.key {
            // Rare (a few times per perceiver): the square root only here.
            self.key = key;
            self.nearest = dist();
        }
        self.pos += pos;
        self.heading += heading;
        self.vel += vel;
    }

    /// The sums as a summary: means not yet divided, no nearest percept.
    #[inline(always)]
    fn summary(&self) -> Summary {
        Summary {
            count: self.count,
            seen: self.seen,
            nearest: None,
            nearest_dist: self.nearest,
            centroid: self.pos.into(),
            mean_heading: self.heading.into(),
            mean_velocity: self.vel.into(),
            inv_dist_sum: self.inv_dist,
        }
    }
}

/// Divides a summary's sums by its count: centroid, mean heading, mean velocity.
#[inline(always)]
fn divide_means(sm: &mut Summary) {
    if sm.count > 0 {
        let n = sm.count as f32;
        sm.centroid /= n;
        sm.mean_heading /= n;
        sm.mean_velocity /= n;
    }
}

/// Writes the kin kernel's sums `acc` as the kin summary in `by`; the other categories of
/// `mask` (the row's) are cleared.
#[inline(always)]
pub(super) fn kin_only(by: &mut [Summary; Category::COUNT], mask: RowMask, acc: &Acc) {
    mask.clear_but(Category::Kin, by);
    let sm = &mut by[Category::Kin as usize];
    *sm = acc.summary();
    divide_means(sm);
}

/// What one agent has perceived so far: per-category sums, kept percepts and, per category,
/// the nearest percept (kept even when nearer ones of other categories fill the slots).
/// `KEEP`: whether the agent keeps percepts at all (without, the per-percept bookkeeping
/// compiles away).
pub(super) struct Fold<'a, const KEEP: bool> {
    acc: [Acc; Category::COUNT],
    kept: Kept<'a>,
    nearest: [Percept; Category::COUNT],
    /// Categories with a percept in `nearest` (bit per category).
    offered: u8,
}

impl<'a, const KEEP: bool> Fold<'a, KEEP> {
    /// Nothing perceived yet; `slots` receive the kept percepts.
    pub(super) fn new(slots: &'a mut [Percept]) -> Self {
        Fold {
            acc: [ACC; Category::COUNT],
            kept: Kept::new(slots),
            nearest: [EMPTY; Category::COUNT],
            offered: 0,
        }
    }

    /// Writes the summaries (means, and the nearest among the kept percepts: the first of the
    /// smallest distance, mates also counting as kin), with the nearest of each category put
    /// back among the kept; returns the kept percepts (a summary's `nearest` names its slot).
    pub(super) fn finish(&mut self, summary: &mut [Summary; Category::COUNT]) -> &'a mut [Percept] {
        self.sums_into(summary);
        // Taken, not moved out of `self`: the fold stays where it is (no copy of its
        // candidates).
        let slots = std::mem::take(&mut self.kept.slots);
        let (len, best) = if KEEP {
            restore_nearest(slots, self.kept.len, summary, &self.nearest, self.offered)
        } else {
            // Nothing kept without `KEEP`.
            (0, [None; Category::COUNT])
        };
        for (sm, b) in summary.iter_mut().zip(best) {
            divide_means(sm);
            sm.nearest = b.map(|b| b.0);
        }
        &mut slots[..len]
    }

    /// Notes one percept of category `cat` at squared distance `key` (distance `dist()`),
    /// which `make(dist)` builds if it is kept.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn take(
        &mut self,
        cat: Category,
        seen: Sense,
        key: f32,
        dist: impl Fn() -> f32,
        pos: Vec3A,
        heading: Vec3A,
        vel: Vec3A,
        make: impl Fn(f32) -> Percept,
    ) {
        if KEEP {
            let d = dist();
            let nearer = key < self.acc[cat as usize].key;
            let nearer_kin = cat == Category::Mate && key < self.acc[Category::Kin as usize].key;
            if nearer || nearer_kin {
                let p = make(d);
                if nearer {
                    self.nearest[cat as usize] = p;
                    self.offered |= 1 << cat as u8;
                }
                if nearer_kin {
                    self.nearest[Category::Kin as usize] = p;
                    self.offered |= 1 << Category::Kin as u8;
                }
            }
            self.kept.offer(d, || make(d));
        }
        self.sum(cat, seen, key, dist, pos, heading, vel);
    }

    /// Notes one percept of category `cat` in the sums only (never kept).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn sum(
        &mut self,
        cat: Category,
        seen: Sense,
        key: f32,
        dist: impl Fn() -> f32,
        pos: Vec3A,
        heading: Vec3A,
        vel: Vec3A,
    ) {
        self.acc[cat as usize].note(seen, key, &dist, pos, heading, vel);
        if cat == Category::Mate {
            self.acc[Category::Kin as usize].note(seen, key, &dist, pos, heading, vel);
        }
        if cat == Category::Predator {
            self.acc[cat as usize].inv_dist += 1.0 / dist().max(1e-6);
        }
    }

    /// Replaces the kin sums by `acc` (the kin kernel's, or a plain walk's).
    #[inline(always)]
    pub(super) fn set_kin(&mut self, acc: Acc) {
        self.acc[Category::Kin as usize] = acc;
    }

    /// Writes the sums out as summaries (means not yet divided).
    fn sums_into(&self, summary: &mut [Summary; Category::COUNT]) {
        for (sm, a) in summary.iter_mut().zip(&self.acc) {
            *sm = a.summary();
        }
    }
}
