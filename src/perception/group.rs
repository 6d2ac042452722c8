//! Stage 2 of the tick: neighborhood sums for the group rules (separation and alignment of
//! seed 001, cohesion, R–A zones and Vicsek alignment of seed 003).
//!
//! Every kin an agent perceives (seen or smelt) is folded into the running sums its species'
//! group rules read, while perception walks the neighbors anyway. The rules therefore see every
//! kin perceived, not only the percepts kept, and cost O(1) in the steering stage. The sums are
//! plain accumulations in the spatial index's fixed order, so they are bit-identical whatever
//! the thread count.

use glam::{Vec3, Vec3A};

/// Most distinct group queries one species may have (more are folded from the kept percepts).
pub const MAX_GROUP_QUERIES: usize = 8;

/// What one group rule needs summed over the neighbors (kin and mates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GroupQuery {
    /// Separation: `a = Σ offset / d²` over neighbors with `1e-6 < d ≤ radius`.
    Separation {
        /// Only neighbors this close count.
        radius: f32,
    },
    /// Alignment and cohesion: `a = Σ offset`, `b = Σ velocity`, `n` = count over neighbors
    /// with `d ≤ radius`.
    Mean {
        /// Only neighbors this close count.
        radius: f32,
    },
    /// R–A zones: within `repulsion`, `n` = count, `a = −Σ w·offset / d` (d > 1e-6) and
    /// `w = Σ w`; between `repulsion` and `matching`, `b = Σ unit velocity`; between `matching`
    /// and `attraction`, `c = Σ offset / d`; `m` counts both outer zones. Each repelling
    /// neighbor's weight `w` is 1 (seed 003) or, with a `soft` band, rises from 0 at `repulsion`
    /// to 1 at `(1 − soft)·repulsion`, the rest of it (`1 − w`) still matching its heading.
    Zones {
        /// Repulsion radius r_r.
        repulsion: f32,
        /// Velocity-matching radius r_m.
        matching: f32,
        /// Attraction radius r_a.
        attraction: f32,
        /// Soft band, a fraction of r_r (0: the paper's hard zone).
        soft: f32,
    },
    /// Vicsek: `a = Σ unit velocity` over neighbors with `d ≤ radius`.
    Headings {
        /// Neighborhood radius r_n.
        radius: f32,
    },
}

/// One neighbor as the sums see it. Distances are squared: the common rules need no square
/// root, and a division only for the neighbors they weigh by distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Near {
    /// Neighbor position minus own position.
    pub offset: Vec3A,
    /// `offset.length_squared()`.
    pub d2: f32,
    /// Neighbor velocity.
    pub velocity: Vec3A,
    /// `velocity.normalize_or_zero()` where a query reads it ([`GroupQuery::reads_unit`]),
    /// else zero.
    pub unit: Vec3A,
}

impl Near {
    /// A neighbor at `offset` (squared length `d2`) moving at `velocity`; its unit velocity
    /// is computed only when `unit`.
    #[inline(always)]
    pub fn new(offset: Vec3A, d2: f32, velocity: Vec3A, unit: bool) -> Near {
        Near {
            offset,
            d2,
            velocity,
            unit: if unit {
                velocity.normalize_or_zero()
            } else {
                Vec3A::ZERO
            },
        }
    }
}

impl GroupQuery {
    /// The square of the radius beyond which [`GroupAcc::add`] folds nothing of a neighbor,
    /// computed as its test computes it.
    #[inline]
    pub fn reach2(&self) -> f32 {
        match *self {
            GroupQuery::Separation { radius }
            | GroupQuery::Mean { radius }
            | GroupQuery::Headings { radius } => radius * radius,
            GroupQuery::Zones { attraction, .. } => attraction * attraction,
        }
    }

    /// Whether the sums need each neighbor's unit velocity.
    pub fn reads_unit(&self) -> bool {
        matches!(self, GroupQuery::Zones { .. } | GroupQuery::Headings { .. })
    }

    /// How many 4-byte words its sums take in perception's output: only the fields it folds
    /// into are kept (a separation's 16 bytes, not a [`GroupSum`]'s 48).
    #[inline(always)]
    pub const fn words(&self) -> usize {
        match self {
            GroupQuery::Separation { .. } | GroupQuery::Headings { .. } => 4,
            GroupQuery::Mean { .. } => 7,
            GroupQuery::Zones { .. } => 12,
        }
    }
}

/// The running sums of one [`GroupQuery`] (what each field holds depends on the query). Kept
/// for every agent and query each tick: plain `Vec3`s (48 bytes, not the 64 of 16-byte
/// aligned vectors); each sum is the same per component either way.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroupSum {
    /// First vector sum.
    pub a: Vec3,
    /// Second vector sum.
    pub b: Vec3,
    /// Third vector sum.
    pub c: Vec3,
    /// First count.
    pub n: u32,
    /// Second count.
    pub m: u32,
    /// A weight sum (R–A zones: the repulsion weights).
    pub w: f32,
}

/// The sums of one [`GroupQuery`] while neighbors are folded in: 16-byte aligned vectors, one
/// vector add a neighbor. Stored as a [`GroupSum`] once the neighbors are done.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroupAcc {
    /// First vector sum.
    pub a: Vec3A,
    /// Second vector sum.
    pub b: Vec3A,
    /// Third vector sum.
    pub c: Vec3A,
    /// First count.
    pub n: u32,
    /// Second count.
    pub m: u32,
    /// A weight sum.
    pub w: f32,
}

impl GroupSum {
    /// Writes the fields `q` folds into to `out`, [`GroupQuery::words`] words, bit for bit.
    #[inline(always)]
    pub(crate) fn pack(&self, q: &GroupQuery, out: &mut [u32]) {
        let f = f32::to_bits;
        let (a, b, c) = (self.a, self.b, self.c);
        match q {
            GroupQuery::Separation { .. } | GroupQuery::Headings { .. } => {
                out[..4].copy_from_slice(&[f(a.x), f(a.y), f(a.z), self.n]);
            }
            GroupQuery::Mean { .. } => {
                out[..7].copy_from_slice(&[f(a.x), f(a.y), f(a.z), f(b.x), f(b.y), f(b.z), self.n])
            }
            GroupQuery::Zones { .. } => out[..12].copy_from_slice(&[
                f(a.x),
                f(a.y),
                f(a.z),
                f(b.x),
                f(b.y),
                f(b.z),
                f(c.x),
                f(c.y),
                f(c.z),
                self.n,
                self.m,
                f(self.w),
            ]),
        }
    }

    /// The sums of `q` that [`GroupSum::pack`] wrote to `words`; the fields `q` does not fold
    /// into are zero, as its fold leaves them.
    #[inline(always)]
    pub(crate) fn unpack(q: &GroupQuery, words: &[u32]) -> GroupSum {
        let f = f32::from_bits;
        let v = |w: &[u32]| Vec3::new(f(w[0]), f(w[1]), f(w[2]));
        match q {
            GroupQuery::Separation { .. } | GroupQuery::Headings { .. } => GroupSum {
                a: v(&words[..3]),
                n: words[3],
                ..GroupSum::default()
            },
            GroupQuery::Mean { .. } => GroupSum {
                a: v(&words[..3]),
                b: v(&words[3..6]),
                n: words[6],
                ..GroupSum::default()
            },
            GroupQuery::Zones { .. } => GroupSum {
                a: v(&words[..3]),
                b: v(&words[3..6]),
                c: v(&words[6..9]),
                n: words[9],
                m: words[10],
                w: f(words[11]),
            },
        }
    }
}

impl From<GroupAcc> for GroupSum {
    #[inline(always)]
    fn from(s: GroupAcc) -> GroupSum {
        GroupSum {
            a: s.a.into(),
            b: s.b.into(),
            c: s.c.into(),
            n: s.n,
            m: s.m,
            w: s.w,
        }
    }
}

impl GroupAcc {
    /// Folds one neighbor into the sums of `q`.
    #[inline(always)]
    pub fn add(&mut self, q: &GroupQuery, n: &Near) {
        match *q {
            GroupQuery::Separation { radius } => {
                // d/|d|² for 1e-6 < |d| ≤ radius.
                if n.d2 <= radius * radius && n.d2 > 1e-12 {
                    self.a += inverse_square(n.offset, n.d2);
                    self.n += 1;
                }
            }
            GroupQuery::Mean { radius } => {
                if n.d2 <= radius * radius {
                    self.a += n.offset;
                    self.b += n.velocity;
                    self.n += 1;
                }
            }
            GroupQuery::Zones {
                repulsion,
                matching,
                attraction,
                soft,
            } => {
                if n.d2 <= attraction * attraction {
                    self.add_zones(n, repulsion, matching, soft);
                }
            }
            GroupQuery::Headings { radius } => {
                if n.d2 <= radius * radius {
                    self.a += n.unit;
                    self.n += 1;
                }
            }
        }
    }
}

impl GroupAcc {
    /// The R–A zones of a neighbor within the attraction radius, out of line (see
    /// [`inverse_square`]).
    #[inline(never)]
    fn add_zones(&mut self, n: &Near, repulsion: f32, matching: f32, soft: f32) {
        let dist = n.d2.sqrt();
        if dist < repulsion {
            self.n += 1;
            let w = if soft > 0.0 {
                ((repulsion - dist) / (soft * repulsion)).min(1.0)
            } else {
                1.0
            };
            self.w += w;
            if dist > 1e-6 {
                self.a -= n.offset * (w / dist);
            }
            if w < 1.0 {
                self.m += 1;
                self.b += n.unit * (1.0 - w);
            }
        } else if dist < matching {
            self.m += 1;
            self.b += n.unit;
        } else {
            self.m += 1;
            self.c += n.offset / dist;
        }
    }
}

/// `offset / d2`, out of line: inlined, the compiler computes it ahead of the radius test for
/// every neighbor (a division each), though separation radii usually keep few of them.
#[inline(never)]
fn inverse_square(offset: Vec3A, d2: f32) -> Vec3A {
    offset * (1.0 / d2)
}

/// Where perception writes one agent's group sums: its row's words, query after query, each
/// in its [`GroupQuery::words`] ([`GroupSum::pack`]).
pub(crate) struct SumsOut<'a> {
    queries: &'a GroupQueries,
    words: &'a mut [u32],
    /// The next query, and where its words start.
    next: usize,
    at: usize,
}

impl<'a> SumsOut<'a> {
    /// The words of an agent whose species asks `queries`.
    #[inline(always)]
    pub(crate) fn new(queries: &'a GroupQueries, words: &'a mut [u32]) -> Self {
        SumsOut {
            queries,
            words,
            next: 0,
            at: 0,
        }
    }

    /// Writes the sums of the next query.
    #[inline(always)]
    pub(crate) fn push(&mut self, s: GroupSum) {
        if let Some(q) = self.queries.get(self.next) {
            let end = self.at + q.words();
            s.pack(q, &mut self.words[self.at..end]);
            (self.next, self.at) = (self.next + 1, end);
        }
    }

    /// How many queries there are.
    #[inline(always)]
    pub(crate) fn len(&self) -> usize {
        self.queries.len()
    }
}

/// The distinct group queries of one species, in a fixed-size list (no allocation per agent).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroupQueries {
    items: [Option<GroupQuery>; MAX_GROUP_QUERIES],
    len: usize,
    unit: bool,
    /// The largest squared radius of the queries (an attraction zone's for `Zones`): a
    /// neighbor farther away is in none of them, and is not looked at query by query.
    reach2: f32,
}

impl GroupQueries {
    /// No queries.
    pub const EMPTY: GroupQueries = GroupQueries {
        items: [None; MAX_GROUP_QUERIES],
        len: 0,
        unit: false,
        reach2: 0.0,
    };
    /// An empty list.
    pub fn new() -> Self {
        Self::EMPTY
    }
    /// Adds `q` unless it is already there or the list is full.
    pub fn insert(&mut self, q: GroupQuery) {
        if self.position(&q).is_none() && self.len < MAX_GROUP_QUERIES {
            self.items[self.len] = Some(q);
            self.len += 1;
            self.unit |= q.reads_unit();
            self.reach2 = self.reach2.max(q.reach2());
        }
    }
    /// Each query with its words in `words`, a row [`SumsOut`] wrote for these queries
    /// (fewer words than the queries take: the queries they cover).
    #[inline(always)]
    pub fn packed<'q, 'w: 'q>(
        &'q self,
        mut words: &'w [u32],
    ) -> impl Iterator<Item = (&'q GroupQuery, &'w [u32])> + 'q {
        self.iter().map_while(move |q| {
            let own = words.get(..q.words())?;
            words = &words[q.words()..];
            Some((q, own))
        })
    }
    /// Query `k`, if listed.
    #[inline(always)]
    pub fn get(&self, k: usize) -> Option<&GroupQuery> {
        self.items[..self.len].get(k).and_then(Option::as_ref)
    }
    /// Index of `q`, if listed.
    #[inline]
    pub fn position(&self, q: &GroupQuery) -> Option<usize> {
        self.iter().position(|x| x == q)
    }
    /// The queries, in insertion order.
    #[inline]
    pub fn iter(&self) -> impl Iterator<Item = &GroupQuery> + '_ {
        self.items[..self.len].iter().flatten()
    }
    /// Number of queries.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }
    /// Whether there are none.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Folds one neighbor at `offset` (squared length `d2`) moving at `velocity` into `sums`
    /// (one per query, in order). Its unit velocity (a square root and a division) is computed
    /// only when a query reads it.
    #[inline(always)]
    pub fn add(&self, sums: &mut [GroupAcc], offset: Vec3A, d2: f32, velocity: Vec3A) {
        // Each query's own test would leave it out (and no unit velocity is worked out): in a
        // school, most neighbors smelt lie beyond every query's radius.
        if d2 > self.reach2 {
            return;
        }
        let near = Near::new(offset, d2, velocity, self.unit);
        for (q, s) in self.items[..self.len].iter().zip(sums) {
            if let Some(q) = q {
                s.add(q, &near);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl GroupAcc {
        fn add_one(&mut self, q: &GroupQuery, offset: Vec3A, dist: f32, velocity: Vec3A) {
            self.add(q, &Near::new(offset, dist * dist, velocity, true));
        }
    }

    #[test]
    fn a_list_folds_each_neighbor_as_its_queries_do_one_by_one() {
        // The list skips a neighbor beyond every query's radius: the sums must be those of
        // each query folded on its own, bit for bit, whatever the radii (a zone's attraction
        // radius the largest of its three), for neighbors on both sides of each radius.
        let mut rng = crate::world::Rng::new(7, 11);
        let mut skipped = 0;
        for _ in 0..400 {
            let mut r = || rng.range(0.5, 8.0);
            let (a, b, c) = (r(), r(), r());
            let mut radii = [a, b, c];
            radii.sort_by(f32::total_cmp);
            let candidates = [
                GroupQuery::Separation { radius: r() },
                GroupQuery::Mean { radius: r() },
                GroupQuery::Headings { radius: r() },
                GroupQuery::Zones {
                    repulsion: radii[0],
                    matching: radii[1],
                    attraction: radii[2],
                    soft: 0.5,
                },
            ];
            let mut list = GroupQueries::new();
            let pick = (rng.next_f32() * 16.0) as usize;
            for (k, q) in candidates.iter().enumerate() {
                if pick & (1 << k) != 0 {
                    list.insert(*q);
                }
            }
            let mut sums = [GroupAcc::default(); MAX_GROUP_QUERIES];
            let mut alone = [GroupAcc::default(); MAX_GROUP_QUERIES];
            // A neighbour at each query's reach (its squared distance is most often the
            // squared radius again: for the largest query, the list's bound itself, where a
            // `>=` for the `>` would skip it), then random ones.
            let at: Vec<f32> = list.iter().map(|q| q.reach2().sqrt()).collect();
            for k in 0..40 + at.len() {
                let mut c = || rng.range(-9.0, 9.0);
                let (offset, velocity) = match at.get(k) {
                    Some(&r) => (Vec3A::new(r, 0.0, 0.0), Vec3A::new(c(), c(), c())),
                    None => (Vec3A::new(c(), c(), c()), Vec3A::new(c(), c(), c())),
                };
                let d2 = offset.length_squared();
                list.add(&mut sums, offset, d2, velocity);
                if list.iter().all(|q| d2 > q.reach2()) {
                    skipped += 1;
                }
                for (q, s) in list.iter().zip(&mut alone) {
                    s.add(q, &Near::new(offset, d2, velocity, true));
                }
            }
            for (s, t) in sums.iter().zip(&alone).take(list.len()) {
                let bits = |g: &GroupAcc| {
                    let v = [g.a, g.b, g.c].map(|v| v.to_array().map(f32::to_bits));
                    (v, g.n, g.m, g.w.to_bits())
                };
                assert_eq!(bits(s), bits(t), "{list:?}");
            }
        }
        assert!(skipped > 1000, "{skipped}");
    }

    #[test]
    fn separation_sums_inverse_square_offsets_within_the_radius() {
        let q = GroupQuery::Separation { radius: 3.0 };
        let mut s = GroupAcc::default();
        // (2,0,0)/4 + (0,0,1)/1; the one at 4 is out of range, the coincident one has no
        // direction.
        s.add_one(&q, Vec3A::new(2.0, 0.0, 0.0), 2.0, Vec3A::ZERO);
        s.add_one(&q, Vec3A::Z, 1.0, Vec3A::ZERO);
        s.add_one(&q, Vec3A::new(4.0, 0.0, 0.0), 4.0, Vec3A::ZERO);
        s.add_one(&q, Vec3A::ZERO, 0.0, Vec3A::ZERO);
        assert_eq!(s.a, Vec3A::new(0.5, 0.0, 1.0));
        assert_eq!(s.n, 2);
    }

    #[test]
    fn zones_sort_neighbors_by_distance() {
        let q = GroupQuery::Zones {
            repulsion: 1.0,
            matching: 3.0,
            attraction: 6.0,
            soft: 0.0,
        };
        let mut s = GroupAcc::default();
        s.add_one(&q, Vec3A::new(0.5, 0.0, 0.0), 0.5, Vec3A::Z);
        s.add_one(&q, Vec3A::new(0.0, 2.0, 0.0), 2.0, Vec3A::X * 4.0);
        s.add_one(&q, Vec3A::new(0.0, 0.0, 5.0), 5.0, Vec3A::ZERO);
        s.add_one(&q, Vec3A::new(9.0, 0.0, 0.0), 9.0, Vec3A::ZERO);
        assert_eq!((s.n, s.m), (1, 2));
        assert_eq!(s.a, Vec3A::new(-1.0, 0.0, 0.0));
        assert_eq!(s.b, Vec3A::X);
        assert_eq!(s.c, Vec3A::Z);
    }

    #[test]
    fn packed_sums_read_back_bit_for_bit_in_their_words() {
        let queries = [
            GroupQuery::Separation { radius: 3.0 },
            GroupQuery::Mean { radius: 3.0 },
            GroupQuery::Headings { radius: 3.0 },
            GroupQuery::Zones {
                repulsion: 1.0,
                matching: 2.0,
                attraction: 4.0,
                soft: 0.5,
            },
        ];
        let neighbors = [
            (Vec3A::new(0.3, -0.2, 0.1), Vec3A::new(1.0, 0.5, -2.0)),
            (Vec3A::new(-1.5, 0.0, -0.25), Vec3A::new(-0.0, 3.0, 1.0)),
            (Vec3A::new(0.0, 2.5, 1.0), Vec3A::new(0.1, 0.0, 0.0)),
        ];
        for q in &queries {
            let mut acc = GroupAcc::default();
            for (offset, velocity) in neighbors {
                acc.add(
                    q,
                    &Near::new(offset, offset.length_squared(), velocity, true),
                );
            }
            let sum = GroupSum::from(acc);
            let mut words = [0xdead_beef; 12];
            sum.pack(q, &mut words);
            // Only its own words are written.
            assert!(
                words[q.words()..].iter().all(|&w| w == 0xdead_beef),
                "{q:?}"
            );
            let back = GroupSum::unpack(q, &words[..q.words()]);
            let bits = |s: &GroupSum| {
                [s.a, s.b, s.c]
                    .map(|v| v.to_array().map(f32::to_bits))
                    .concat()
                    .into_iter()
                    .chain([s.n, s.m, s.w.to_bits()])
                    .collect::<Vec<u32>>()
            };
            assert_eq!(bits(&back), bits(&sum), "{q:?}");
            assert!(sum.n > 0, "{q:?}: the test's neighbors fold into it");
        }
        // A separation's 16 bytes, not 48.
        assert_eq!(queries.map(|q| q.words()), [4, 7, 4, 12]);
        // One row of all four, written query after query and read back by query.
        let mut list = GroupQueries::new();
        queries.iter().for_each(|q| list.insert(*q));
        let sums = queries.map(|q| {
            let mut acc = GroupAcc::default();
            for (offset, velocity) in neighbors {
                acc.add(
                    &q,
                    &Near::new(offset, offset.length_squared(), velocity, true),
                );
            }
            GroupSum::from(acc)
        });
        let mut row = [0u32; 27];
        let mut out = SumsOut::new(&list, &mut row);
        sums.iter().for_each(|s| out.push(*s));
        let back: Vec<GroupSum> = list
            .packed(&row)
            .map(|(q, w)| GroupSum::unpack(q, w))
            .collect();
        assert_eq!(back, sums.to_vec());
        // A row cut short reads back only the queries it covers.
        assert_eq!(list.packed(&row[..12]).count(), 2);
    }

    #[test]
    fn queries_are_listed_once() {
        let mut qs = GroupQueries::new();
        qs.insert(GroupQuery::Mean { radius: 2.0 });
        qs.insert(GroupQuery::Headings { radius: 2.0 });
        qs.insert(GroupQuery::Mean { radius: 2.0 });
        assert_eq!(qs.len(), 2);
        assert_eq!(qs.position(&GroupQuery::Headings { radius: 2.0 }), Some(1));
        let mut acc = [GroupAcc::default(); 2];
        qs.add(&mut acc, Vec3A::X, 1.0, Vec3A::Z * 2.0);
        let sums = acc.map(GroupSum::from);
        assert_eq!(
            (sums[0].a, sums[0].b, sums[0].n),
            (Vec3::X, Vec3::Z * 2.0, 1)
        );
        assert_eq!((sums[1].a, sums[1].n), (Vec3::Z, 1));
    }
}
