//! The percepts an agent keeps in its slots (stage 2; the room its row has while walked): the
//! nearest ones, as many as its species keeps, and always the nearest of each category, even
//! when nearer percepts of other categories fill the slots. Works on percepts already built;
//! reads nothing of the world.

use super::{Category, Percept, Sense, Source, Summary, MAX_PERCEPTS};
use glam::{Vec3, Vec4};

/// An unused percept slot.
pub(super) const EMPTY: Percept = Percept::new(
    Source::Food(0),
    Category::Other,
    Sense::Smell,
    Vec3::ZERO,
    0.0,
    0.0,
);

/// The nearest percepts of one agent, as many as it has slots: appends while there is room,
/// else replaces the farthest when nearer. The farthest slot (the first one of the largest
/// distance) is remembered between offers and looked for again only after a replacement.
pub(super) struct Kept<'a> {
    pub(super) slots: &'a mut [Percept],
    /// Distances of `slots`, contiguous for the search of the farthest; −∞ past the slots.
    dists: [f32; MAX_PERCEPTS],
    pub(super) len: usize,
    /// The first slot of the largest distance, when `far_valid`.
    far: usize,
    far_valid: bool,
    /// The largest distance (when `far_valid`) or an upper bound of it.
    bound: f32,
}

impl<'a> Kept<'a> {
    /// Nothing kept yet; `slots` receive the kept percepts.
    pub(super) fn new(slots: &'a mut [Percept]) -> Self {
        Kept {
            slots,
            dists: [f32::NEG_INFINITY; MAX_PERCEPTS],
            len: 0,
            far: 0,
            far_valid: false,
            bound: f32::INFINITY,
        }
    }

    /// The first slot of the largest distance, once every slot is used (distances are finite:
    /// positions are kept inside the world bounds; a NaN one, which only an injected percept
    /// can have, is never the largest).
    #[inline]
    fn find_far(&mut self) {
        // Four lanes at a time: a running maximum, then a mask of the slots equal to it (a
        // replacement in a school calls this every few candidates). Only the chunks that hold
        // slots are read (entries past them are −∞).
        let used = self.slots.len().div_ceil(4) * 4;
        let d = &self.dists[..used.min(MAX_PERCEPTS)];
        let mut m = Vec4::NEG_INFINITY;
        for c in d.chunks_exact(4) {
            let c = Vec4::from_slice(c);
            // `c > m` lane by lane, not `max`: a NaN never gets in.
            m = Vec4::select(c.cmpgt(m), c, m);
        }
        let m01 = if m.y > m.x { m.y } else { m.x };
        let m23 = if m.w > m.z { m.w } else { m.z };
        let max = Vec4::splat(if m23 > m01 { m23 } else { m01 });
        let mut mask = 0u32;
        for (j, c) in d.chunks_exact(4).enumerate() {
            mask |= Vec4::from_slice(c).cmpeq(max).bitmask() << (4 * j);
        }
        self.far = (mask.trailing_zeros() as usize).min(self.len.saturating_sub(1));
    }

    /// Offers the percept `make()` builds, at distance `dist`; `make` runs only when it is kept.
    /// After a replacement the farthest slot is looked for again only when an offer could beat
    /// the distance just replaced (an upper bound of the new largest one).
    #[inline(always)]
    pub(super) fn offer(&mut self, dist: f32, make: impl FnOnce() -> Percept) {
        let cap = self.slots.len();
        if self.len < cap {
            self.slots[self.len] = make();
            self.dists[self.len] = dist;
            self.len += 1;
            if self.len == cap {
                self.find_far();
                self.bound = self.dists[self.far];
                self.far_valid = true;
            }
            return;
        }
        if cap == 0 || dist >= self.bound {
            return;
        }
        if !self.far_valid {
            self.find_far();
            self.bound = self.dists[self.far];
            self.far_valid = true;
            if dist >= self.bound {
                return;
            }
        }
        // `far` is the first slot of the largest distance, and `dist` is nearer.
        self.slots[self.far] = make();
        self.dists[self.far] = dist;
        self.far_valid = false;
    }
}

/// Puts back the nearest percept of each category (`candidates`, by category; the summaries
/// give the counts and nearest distances) that nearer percepts of other categories pushed out of
/// `slots[..len]`, in place of the farthest percept that is nobody's nearest; returns the new
/// length and the nearest kept of each category. Only categories in `offered` (a bit per
/// category) have a candidate. With at least [`Category::COUNT`] slots every category perceived keeps its nearest.
pub(super) fn restore_nearest(
    slots: &mut [Percept],
    mut len: usize,
    summary: &[Summary; Category::COUNT],
    candidates: &[Percept; Category::COUNT],
    offered: u8,
) -> (usize, [Option<(u16, f32)>; Category::COUNT]) {
    const ORDER: [Category; Category::COUNT] = [
        Category::Food,
        Category::Predator,
        Category::Mate,
        Category::Kin,
        Category::Obstacle,
        Category::Other,
    ];
    let mut best = nearest_kept(&slots[..len]);
    for c in ORDER {
        let sm = &summary[c as usize];
        // Categories folded without percepts (kin of a species that reads none) stay so.
        if sm.count == 0
            || offered & (1 << c as u8) == 0
            || best[c as usize].is_some_and(|(_, d)| d <= sm.nearest_dist)
        {
            continue;
        }
        if len < slots.len() {
            slots[len] = candidates[c as usize];
            len += 1;
        } else {
            let protected = best.iter().flatten().fold(0u32, |m, &(k, _)| m | 1 << k);
            let far = (0..len).filter(|&k| protected & (1 << k) == 0).fold(
                None,
                |f: Option<usize>, k| match f {
                    Some(f) if slots[f].dist >= slots[k].dist => Some(f),
                    _ => Some(k),
                },
            );
            match far {
                Some(k) => slots[k] = candidates[c as usize],
                None => continue,
            }
        }
        best = nearest_kept(&slots[..len]);
    }
    (len, best)
}

/// For each category, the first kept slot of the smallest distance (mates also count as kin).
fn nearest_kept(slots: &[Percept]) -> [Option<(u16, f32)>; Category::COUNT] {
    let mut best: [Option<(u16, f32)>; Category::COUNT] = [None; Category::COUNT];
    for (k, p) in slots.iter().enumerate() {
        let mut offer = |c: usize| {
            if best[c].is_none_or(|(_, d)| p.dist < d) {
                best[c] = Some((k as u16, p.dist));
            }
        };
        offer(p.category() as usize);
        if p.category() == Category::Mate {
            offer(Category::Kin as usize);
        }
    }
    best
}

/// Bearing and elevation (a pure function of the offset and the perceiver's yaw and pitch) for
/// the percepts kept, or only for those the species reads: within its bearing range `range`,
/// obstacles, and each category's nearest (`nearest`: a bit per slot). `None`: every one.
#[inline(always)]
pub(super) fn bearings(
    slots: &mut [Percept],
    nearest: u32,
    range: Option<f32>,
    yaw: f32,
    pitch: f32,
) {
    for (k, p) in slots.iter_mut().enumerate() {
        let wanted = match range {
            None => true,
            Some(r) => nearest & (1 << k) != 0 || p.category() == Category::Obstacle || p.dist <= r,
        };
        if wanted {
            (p.bearing, p.elevation) = crate::frame::bearing_elevation(yaw, pitch, p.offset);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::Rng;

    /// The search of the farthest slot one slot at a time, as it was before it took four.
    fn far_one_by_one(d: &[f32], len: usize) -> usize {
        let mut m = [f32::NEG_INFINITY; 4];
        for c in d.chunks_exact(4) {
            for l in 0..4 {
                m[l] = if c[l] > m[l] { c[l] } else { m[l] };
            }
        }
        let m01 = if m[1] > m[0] { m[1] } else { m[0] };
        let m23 = if m[3] > m[2] { m[3] } else { m[2] };
        let max = if m23 > m01 { m23 } else { m01 };
        let mut mask = 0u32;
        for (k, &x) in d.iter().enumerate() {
            mask |= ((x == max) as u32) << k;
        }
        (mask.trailing_zeros() as usize).min(len.saturating_sub(1))
    }

    #[test]
    fn the_farthest_slot_is_the_one_slot_at_a_times_for_any_distances() {
        // NaN (an injected percept may have one), ±0, ±∞ and ties among the distances.
        let pool = [
            0.0,
            -0.0,
            0.5,
            1.0,
            1.0,
            2.5,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            7.0,
        ];
        let mut rng = Rng::new(17, 4);
        for round in 0..20_000 {
            let cap = 1 + round % MAX_PERCEPTS;
            let mut slots = vec![EMPTY; cap];
            let mut kept = Kept::new(&mut slots);
            kept.len = cap;
            for k in 0..cap {
                kept.dists[k] = pool[(rng.next_f32() * pool.len() as f32) as usize % pool.len()];
            }
            kept.find_far();
            let used = (cap.div_ceil(4) * 4).min(MAX_PERCEPTS);
            let want = far_one_by_one(&kept.dists[..used], cap);
            assert_eq!(kept.far, want, "{:?}", &kept.dists[..cap]);
        }
    }

    #[test]
    fn kept_slots_are_those_of_replacing_the_first_farthest_one_by_one() {
        // Against the plain rule: append while there is room, then a nearer offer takes the
        // place of the first slot of the largest distance. Distances from a small set, so
        // that ties are common and the choice among them shows.
        let mut rng = Rng::new(3, 9);
        for round in 0..600 {
            let cap = [1, 3, 6, 8, 13, 16, 31, 32][round % 8];
            let mut slots = vec![EMPTY; cap];
            let mut kept = Kept::new(&mut slots);
            let mut want: Vec<(f32, u32)> = Vec::new();
            for id in 0..(rng.next_f32() * 120.0) as u32 {
                let dist = (rng.next_f32() * 12.0).floor() * 0.5;
                let p = Percept::new(
                    Source::Agent(id),
                    Category::Kin,
                    Sense::Vision,
                    Vec3::ZERO,
                    dist,
                    0.0,
                );
                kept.offer(dist, || p);
                if want.len() < cap {
                    want.push((dist, id));
                } else {
                    let max = want.iter().map(|w| w.0).fold(f32::NEG_INFINITY, f32::max);
                    if dist < max {
                        let far = want.iter().position(|w| w.0 == max).unwrap_or(0);
                        want[far] = (dist, id);
                    }
                }
            }
            let len = kept.len;
            let got: Vec<(f32, Source)> =
                slots[..len].iter().map(|p| (p.dist, p.source())).collect();
            let want: Vec<(f32, Source)> =
                want.iter().map(|&(d, id)| (d, Source::Agent(id))).collect();
            assert_eq!(got, want, "round {round}, {cap} slots");
        }
    }
}
