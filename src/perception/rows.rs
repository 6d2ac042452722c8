//! Stage 2's summary rows: each agent's row holds the summaries of the categories its species
//! can perceive this tick, in [`Category`] order, and no others. A plain flocker in open water
//! can perceive only kin (one summary, 44 bytes, where a row of all six is 264); a reef fish
//! with no relation that makes anything `Other` to it has no `Other` summary. What a species
//! can perceive follows from its relations, whether it eats items, and whether the world has
//! obstacles; the walks fold every category as before, and a row keeps those of its mask.
//! Of those, the stored row keeps only what the agent perceived ([`RowMask::compact`]): an
//! empty summary reads back as [`Summary::NONE`], so nothing is lost. A kept summary is held
//! as a [`Held`] (44 bytes, not 56): its mean heading apart, only where some species reads it.

use super::{Category, Relations, Summary};
use glam::Vec3;

/// A summary as a row keeps it: [`Summary`] without its mean heading (scripts alone read it;
/// it is kept beside the row where some species' script does), its nearest percept's index
/// in 2 bytes. 44 bytes, not 56: a reef fish keeps three or four.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Held {
    count: u32,
    seen: u32,
    /// `u16::MAX`: none (a row keeps at most [`super::MAX_PERCEPTS`] percepts).
    nearest: u16,
    nearest_dist: f32,
    inv_dist_sum: f32,
    centroid: Vec3,
    mean_velocity: Vec3,
}

impl Held {
    /// What stands in for the rows' room before they are written.
    pub(super) const NONE: Held = Held::new(&Summary::NONE);

    /// `s` without its mean heading.
    #[inline(always)]
    pub(super) const fn new(s: &Summary) -> Held {
        Held {
            count: s.count,
            seen: s.seen,
            nearest: match s.nearest {
                Some(k) => k,
                None => u16::MAX,
            },
            nearest_dist: s.nearest_dist,
            inv_dist_sum: s.inv_dist_sum,
            centroid: s.centroid,
            mean_velocity: s.mean_velocity,
        }
    }

    /// Index of the nearest percept, if any.
    #[inline(always)]
    pub(super) fn nearest(&self) -> Option<u16> {
        (self.nearest != u16::MAX).then_some(self.nearest)
    }

    /// The summary it holds, with mean heading `heading`.
    #[inline(always)]
    pub(super) fn summary(&self, heading: Vec3) -> Summary {
        Summary {
            count: self.count,
            seen: self.seen,
            nearest: self.nearest(),
            nearest_dist: self.nearest_dist,
            centroid: self.centroid,
            mean_heading: heading,
            mean_velocity: self.mean_velocity,
            inv_dist_sum: self.inv_dist_sum,
        }
    }
}

/// The categories a row holds, one bit per [`Category`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct RowMask(u8);

impl RowMask {
    /// Every category: what a species the stage knows nothing about gets, and every species
    /// while percepts are fed to agents (a fed percept may be of any category).
    pub(super) const ALL: RowMask = RowMask((1 << Category::COUNT) - 1);

    /// The categories species `s` can perceive: what its relations make the other species
    /// (mates are kin too), food items if it eats them, obstacles if the world has any, and kin
    /// if it perceives by the kin kernel.
    pub(super) fn of(s: usize, relations: &Relations, obstacles: bool, kernel: bool) -> Self {
        let bit = |c: Category| 1u8 << c as u8;
        let row = relations.row(s);
        // A species the relations do not list (outside `Pipeline`, whose table lists every
        // one) is "all kin" to the walks' plain paths: every category, not a guess.
        if row.is_empty() {
            return RowMask::ALL;
        }
        let mut m = 0;
        for c in row.iter().flatten() {
            m |= bit(*c);
        }
        if relations.mates(s) && m & bit(Category::Kin) != 0 {
            m |= bit(Category::Mate);
        }
        if relations.eats_items(s) {
            m |= bit(Category::Food);
        }
        if obstacles {
            m |= bit(Category::Obstacle);
        }
        if kernel {
            m |= bit(Category::Kin);
        }
        // A mate is summed as kin too.
        if m & bit(Category::Mate) != 0 {
            m |= bit(Category::Kin);
        }
        RowMask(m)
    }

    /// Summaries in a row of this mask.
    #[inline]
    pub(super) fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Whether the row holds category `c`.
    #[inline]
    fn has(self, c: usize) -> bool {
        self.0 & (1 << c) != 0
    }

    /// Where category `c`'s summary is in the row, if it holds it.
    #[cfg(test)]
    fn slot(self, c: Category) -> Option<usize> {
        let c = c as usize;
        self.has(c)
            .then(|| (self.0 & ((1u8 << c) - 1)).count_ones() as usize)
    }

    /// The row's summaries by category, `Summary::NONE` for those it does not hold.
    /// `headings`: their mean headings, or none kept (zero).
    #[inline]
    pub(super) fn expand(self, row: &[Held], headings: &[Vec3]) -> [Summary; Category::COUNT] {
        let mut by = [Summary::NONE; Category::COUNT];
        self.fill(row, headings, &mut by);
        by
    }

    /// Writes the row's summaries into their categories' places in `by` (the others are left
    /// as they are). `headings`: their mean headings, or none kept (zero).
    #[inline]
    pub(super) fn fill(self, row: &[Held], headings: &[Vec3], by: &mut [Summary; Category::COUNT]) {
        for (k, (s, c)) in row.iter().zip(self.categories()).enumerate() {
            by[c] = s.summary(headings.get(k).copied().unwrap_or(Vec3::ZERO));
        }
    }

    /// The categories it holds, in order, as indices.
    #[inline(always)]
    fn categories(self) -> impl Iterator<Item = usize> {
        let mut m = self.0 & RowMask::ALL.0;
        std::iter::from_fn(move || {
            (m != 0).then(|| {
                let c = m.trailing_zeros() as usize;
                m &= m - 1;
                c
            })
        })
    }

    /// Calls `put` with each summary of `by` (by category) that this mask holds and that is
    /// not empty, in category order, and returns the mask of those: what the row keeps (an
    /// empty summary, bit for bit [`Summary::NONE`], is what a row that does not hold the
    /// category reads).
    #[inline(always)]
    pub(super) fn perceived(
        self,
        by: &[Summary; Category::COUNT],
        mut put: impl FnMut(&Summary),
    ) -> RowMask {
        let mut held = 0u8;
        for c in self.categories() {
            if !by[c].is_none() {
                put(&by[c]);
                held |= 1 << c;
            }
        }
        RowMask(held)
    }

    /// Clears this mask's categories in `by` but `keep`.
    #[inline(always)]
    pub(super) fn clear_but(self, keep: Category, by: &mut [Summary; Category::COUNT]) {
        for c in self.categories().filter(|&c| c != keep as usize) {
            by[c] = Summary::NONE;
        }
    }

    /// Whether every category of `by` outside this mask is empty: the walks can fold only the
    /// categories a row holds.
    pub(super) fn holds_all_perceived(self, by: &[Summary; Category::COUNT]) -> bool {
        by.iter()
            .enumerate()
            .all(|(c, s)| self.has(c) || s.count == 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mask_lays_its_categories_out_in_order() {
        let mut rel = Relations::new(3);
        rel.set(0, 0, Some(Category::Kin));
        rel.set(0, 2, Some(Category::Predator));
        let m = RowMask::of(0, &rel, true, false);
        assert_eq!(m.len(), 3);
        assert_eq!(m.slot(Category::Predator), Some(0));
        assert_eq!(m.slot(Category::Kin), Some(1));
        assert_eq!(m.slot(Category::Obstacle), Some(2));
        assert_eq!(m.slot(Category::Food), None);
        assert_eq!(m.slot(Category::Other), None);
        let mut by = [Summary::NONE; Category::COUNT];
        by[Category::Kin as usize].count = 4;
        by[Category::Obstacle as usize].count = 1;
        let mut row = Vec::new();
        let kept = m.perceived(&by, |s| row.push(*s));
        assert_eq!(kept.slot(Category::Kin), Some(0));
        assert_eq!(kept.slot(Category::Obstacle), Some(1));
        assert_eq!([row[0].count, row[1].count], [4, 1]);
        assert_eq!(kept.expand(&held(&row), &[]), by);
        assert!(m.holds_all_perceived(&by));
        // A mask clears its other categories, and sees a category it does not hold.
        let mut cleared = by;
        m.clear_but(Category::Kin, &mut cleared);
        assert_eq!(cleared[Category::Kin as usize].count, 4);
        assert!(cleared[Category::Obstacle as usize].is_none());
        by[Category::Food as usize].count = 1;
        assert!(!m.holds_all_perceived(&by));
        // Mates are kin of the other sex, and summed as kin too; items make food.
        rel.set_mates(0, true);
        rel.set_eats_items(0, true);
        let m = RowMask::of(0, &rel, false, false);
        assert_eq!(m.len(), 4);
        assert!(m.slot(Category::Mate).is_some() && m.slot(Category::Food).is_some());
        assert_eq!(RowMask::of(1, &rel, false, true).len(), 1);
        assert_eq!(RowMask::ALL.len(), Category::COUNT);
        // A species the relations do not list keeps every category.
        assert_eq!(RowMask::of(7, &rel, false, false), RowMask::ALL);
    }

    #[test]
    fn a_row_keeps_what_was_perceived_in_order() {
        let mut by = [Summary::NONE; Category::COUNT];
        by[1].count = 2;
        by[4].count = 5;
        // An empty summary with another bit pattern (−0 in a sum) is kept, not lost.
        by[2].inv_dist_sum = -0.0;
        let mut row = Vec::new();
        let held = RowMask::ALL.perceived(&by, |s| row.push(*s));
        assert_eq!(held.len(), 3);
        assert_eq!([row[0].count, row[2].count], [2, 5]);
        assert!(row[1].inv_dist_sum.is_sign_negative());
        let back = held.expand(&self::held(&row), &[]);
        assert_eq!([back[1].count, back[4].count], [2, 5]);
        assert!(back[2].inv_dist_sum.is_sign_negative());
        assert!(back[0].is_none() && back[3].is_none() && back[5].is_none());
        // A row of fewer categories keeps only its own.
        let m = RowMask(0b10_1010);
        let mut row = Vec::new();
        let held = m.perceived(&by, |s| row.push(*s));
        assert_eq!(held, RowMask(0b00_0010));
        assert_eq!(row.len(), 1);
        assert_eq!(held.expand(&self::held(&row), &[])[1].count, 2);
    }

    fn held(row: &[Summary]) -> Vec<Held> {
        row.iter().map(Held::new).collect()
    }

    #[test]
    fn a_held_summary_reads_back_bit_for_bit_with_its_heading() {
        let bits = |s: &Summary| format!("{s:?}");
        let s = Summary {
            count: 7,
            seen: 3,
            nearest: Some(31),
            nearest_dist: 2.5,
            centroid: Vec3::new(1.0, -2.0, 3.0),
            mean_heading: Vec3::new(0.5, 0.25, -0.125),
            mean_velocity: Vec3::new(-4.0, 5.0, 6.0),
            inv_dist_sum: 0.75,
        };
        let h = Held::new(&s);
        assert_eq!(bits(&h.summary(s.mean_heading)), bits(&s));
        // Without its heading, the heading alone reads zero.
        let no_heading = Summary {
            mean_heading: Vec3::ZERO,
            ..s
        };
        assert_eq!(h.summary(Vec3::ZERO), no_heading);
        // No nearest, and a nearest at index 0, stay apart.
        for nearest in [None, Some(0)] {
            let s = Summary { nearest, ..s };
            assert_eq!(Held::new(&s).summary(s.mean_heading).nearest, nearest);
        }
        assert!(Held::NONE.summary(Vec3::ZERO).is_none());
        assert_eq!(std::mem::size_of::<Held>(), 44);
        // A row's headings are read in its order.
        let mut row = [Summary::NONE; 2];
        row[0].count = 1;
        row[1].count = 2;
        let by = RowMask(0b1001).expand(&held(&row), &[Vec3::X, Vec3::Y]);
        assert_eq!([by[0].mean_heading, by[3].mean_heading], [Vec3::X, Vec3::Y]);
        assert!(by[1].is_none());
    }
}
