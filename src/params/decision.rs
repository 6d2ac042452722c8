//! Decision's data that species validation builds (stage 4): the focuser's set of categories
//! (seed 000 §1) and the bits of the sector and level masks of conditions (§4.3–4.4). Pure data:
//! narrowing percepts and evaluating conditions stay in [`crate::decision`], which re-exports
//! each item under its old path.

use crate::perception::{Category, Level, Sector};

/// A set of [`Category`]s, one bit each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Focus(u8);

impl Focus {
    /// Every category.
    pub const ALL: Focus = Focus((1 << Category::COUNT) - 1);

    /// The categories listed.
    pub fn of(categories: &[Category]) -> Focus {
        Focus(categories.iter().fold(0, |bits, &c| bits | Focus::bit(c)))
    }

    fn bit(c: Category) -> u8 {
        1 << c as u8
    }

    /// Whether `c` is in the set.
    #[inline]
    pub fn contains(self, c: Category) -> bool {
        self.0 & Focus::bit(c) != 0
    }
}

/// The bit of a horizontal sector in the mask of
/// [`CondNode::InSector`](crate::species::CondNode::InSector).
#[inline]
pub fn sector_bit(s: Sector) -> u8 {
    1 << s as u8
}

/// The bit of a level in the mask of
/// [`CondNode::AtLevel`](crate::species::CondNode::AtLevel).
#[inline]
pub fn level_bit(l: Level) -> u8 {
    1 << l as u8
}
