//! What every perceiver reads in stage 2: the tick's [`View`] (the world at the start of the
//! tick, the indexes and the gathered copies, every species' senses), and who perceives on each
//! output row, handed to the walks (`walk.rs`). Read-only: each row writes only its own share.

use super::gather::{Body, Gathered, Me, Tag};
use super::nearest::Others;
use super::walk::perceive_one;
use super::{kin, AgentOut, Reads, Relations, SenseParams};
use crate::index::{Grid, ObstacleGrid};
use crate::world::World;

/// What every perceiver reads: the world at the start of the tick, this tick's indexes and
/// gathered copies, and every species' senses.
pub(super) struct View<'a> {
    pub(super) world: &'a World,
    /// Agents' records in the agent grid's order.
    pub(super) near: &'a [Body],
    /// Their species and sex, in the same order.
    pub(super) tags: &'a [Tag],
    /// Their bounding-box diagonals, in the same order.
    pub(super) diagonals: &'a [f32],
    /// Half the largest of them: the largest bounding radius.
    pub(super) body_reach: f32,
    /// The same for the kin kernel, when a species may perceive by it.
    pub(super) lanes: Option<&'a kin::KinLanes>,
    /// Which species may perceive by the kin kernel.
    pub(super) kernel: &'a [bool],
    /// Slot of each agent in `near`.
    pub(super) slot_of: &'a [u32],
    pub(super) agents: &'a Grid,
    pub(super) food: &'a Grid,
    pub(super) obstacle_grid: &'a ObstacleGrid,
    /// What each species with a bounded kin neighborhood perceives as other than kin.
    pub(super) others: &'a Others,
    pub(super) relations: &'a Relations,
    /// Whether the output rows are in the agent grid's order (else in agent order).
    pub(super) by_grid: bool,
    /// Yaw and pitch of the agent of each row, when the rows are in the grid's order.
    pub(super) angles: &'a [[f32; 2]],
    /// Every agent's record, by agent index.
    pub(super) gathered: &'a [Gathered],
    /// Each species' senses, what its behaviors read, and the cosine bound of its vision cone
    /// (as `volume::in_cone` computes it); a species without an entry gets the defaults.
    pub(super) senses: &'a [SenseParams],
    pub(super) reads: &'a [Reads],
    pub(super) cos_mins: &'a [f32],
    pub(super) default: SenseParams,
    pub(super) everything: Reads,
    pub(super) default_cos_min: f32,
}

impl View<'_> {
    /// Whether the agent in grid slot `k` is kin to a perceiver whose relations are `row`.
    #[inline(always)]
    pub(super) fn is_kin(&self, row: &[Option<super::Category>], k: usize) -> bool {
        row.get(self.tags[k].species as usize) == Some(&Some(super::Category::Kin))
    }

    /// Perceives for the agent of row `r` into its share of the outputs.
    #[inline(always)]
    pub(super) fn perceive_row(&self, r: usize, out: AgentOut) {
        let (i, me) = self.perceiver(r);
        let me = &me;
        let s = me.tag.species as usize;
        let sense = self.senses.get(s).unwrap_or(&self.default);
        let rd = self.reads.get(s).unwrap_or(&self.everything);
        // Cosine bound of the vision cone (as `volume::in_cone` computes it).
        let cos_min = self
            .cos_mins
            .get(s)
            .copied()
            .unwrap_or(self.default_cos_min);
        // Each query's group sums go straight into its own words.
        let sums = &mut super::SumsOut::new(&rd.groups, out.sums);
        *out.count = if out.slots.is_empty() {
            perceive_one::<false>(
                i,
                me,
                self,
                sense,
                cos_min,
                rd,
                out.slots,
                out.summary,
                out.mask,
                out.reach,
                sums,
                out.kin,
            )
        } else {
            perceive_one::<true>(
                i,
                me,
                self,
                sense,
                cos_min,
                rd,
                out.slots,
                out.summary,
                out.mask,
                out.reach,
                sums,
                out.kin,
            )
        };
    }

    /// The perceiver of row `r` (its agent index), and what it reads of itself: in the grid's
    /// order from the slot-ordered copies, in agent order from its record.
    #[inline(always)]
    fn perceiver(&self, r: usize) -> (usize, Me) {
        if self.by_grid {
            let [yaw, _] = self.angles[r];
            let me = Me {
                pos: self.agents.positions()[r].into(),
                yaw,
                heading: self.near[r].heading,
                tag: self.tags[r],
            };
            (self.agents.entries()[r] as usize, me)
        } else {
            let a = &self.world.agents[r];
            let me = Me {
                pos: a.pos,
                yaw: a.yaw,
                heading: self.gathered[r].body.heading,
                tag: self.gathered[r].tag,
            };
            (r, me)
        }
    }
}
