//! Formation-aware A* for the leader, seed 004 ("improved A*": `f = K1·(g + h) + K2·FM`).
//!
//! Not a tick stage: path planning, run when a team is given a goal. The grid is 8-connected; a
//! diagonal step needs both side cells free (no corner cutting), which is what makes every single
//! step of a path pass the supercover line-of-sight test used by smoothing.
//!
//! The evaluation follows the source with one reading made explicit. `FM(n) = 1 / Σ aᵢ`, where
//! `aᵢ = 1` when follower `i`'s slot in the team's *primary* formation (the first of its list),
//! with the leader at `n` facing along the move into `n`, is a free cell inside the grid. The
//! source's `f(n) = K1·(g(n) + h(n)) + K2·FM(n)` is applied with `FM` summed along the path, each
//! step weighted by its length, so the search minimises the well-defined cost
//! `Σ len · (K1·cost + K2·FM)` and stays exact (a node-local `FM` only reorders expansion and can
//! be outvoted by a few cells of path length). The heuristic is the octile distance times the
//! cheapest possible step, `K1·min cost + K2·FM_min`, so it is admissible and consistent.
//!
//! **When a search "finds no path"** (the source relaxes `K2 −= step, K1 += step` and searches
//! again). Read literally, a node is refused only where `1/Σ aᵢ` is infinite (no follower fits),
//! and that does not depend on the weights while `K2 > 0`: every relaxed search then fails exactly
//! like the first, and only the last step, `K2 = 0`, can ever succeed. The engine therefore reads
//! K2 also as the share of the followers that must stand in a free slot: with the leader at `n`,
//! the formation the team takes there (the primary, or when the formation may change any other of
//! the list) must place at least `⌈K2·N⌉` of the `N` followers, and at least one while `K2 > 0`
//! ([`required_free`]). So `K2 = 0.9` keeps the whole formation (for fewer than 10 followers),
//! each relaxation tolerates a tenth more followers out of their slots, and an intermediate step
//! succeeds where the team fits that well. `keep_share: false` (a squad's `planning`) is the
//! literal form: one follower in a free slot is enough at any `K2 > 0`.
//!
//! The all-blocked case (`Σ aᵢ = 0`, where `1/Σ aᵢ` is infinite): when the formation may change
//! and another formation of the list places enough followers there, the step costs the finite
//! penalty `fm_broken` ([`FM_BROKEN`] by default); otherwise the node is infeasible while `K2 > 0`
//! (the source's infinite `f`) and free of formation cost when `K2 = 0`. When the formation may
//! not change (`may_change = false`), a node is feasible only where every follower's slot is
//! free: the formation is kept everywhere or the plan fails. The start cell is exempt: the team is
//! where it is.
//!
//! **Weighted mode** (not in the source). On slope-cost terrain the cheapest possible step is far
//! below the typical one, so the octile bound is loose and the exact search expands most of the
//! map (a 1024² plan took ~110 ms). `search_weight: ε > 1` orders nodes by `g + ε·h` (weighted
//! A*, no reopening): the plan's score is at most ε times the best and usually within a few
//! percent of it, for a fraction of the nodes; ε = 1, the default, is the source's exact search.

use super::shape::{to_world, Formation, FormationError};
use crate::terrain::{Cell, CostGrid};
use glam::Vec2;
use serde::{Deserialize, Serialize};

/// Formation cost of a step where no follower fits its primary slot but another formation of the
/// list still places enough of them: twice that of a step where a single follower fits. The
/// source leaves `1/Σ aᵢ` infinite there; a squad's `planning.fm_broken` overrides it.
pub const FM_BROKEN: f32 = 2.0;

/// The largest heuristic weight accepted: beyond it the search is close to greedy best-first
/// and the score bound says little.
pub const MAX_SEARCH_WEIGHT: f32 = 10.0;

/// The source's relaxation step: `K2 −= 0.1, K1 += 0.1` after a failed search.
pub const RELAX_STEP: f32 = 0.1;

/// Planning constants of seed 004 a scenario's squad may override (`planning: (…)`), with the
/// source's values as defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlanningParams {
    /// How much K2 drops and K1 rises per relaxation (source: 0.1).
    pub relax_step: f32,
    /// Formation cost of a step where no follower fits the primary formation but another of the
    /// list places enough of them (the source's `1/Σ aᵢ` is infinite there).
    pub fm_broken: f32,
    /// Whether K2 is also the share of followers that must fit (see the module notes); `false` is
    /// the literal reading, under which only `K2 = 0` can rescue a failed search.
    pub keep_share: bool,
    /// `(K1, K2)` of the task class "must not change" (source: 0.05, 0.95).
    pub must_keep: ClassFactors,
    /// `(K1, K2)` of the task class "may change rarely" (source: 0.1, 0.9).
    pub may_change_rarely: ClassFactors,
    /// `(K1, K2)` of the task class "shortest path first" (source: 0.9, 0.1).
    pub shortest_first: ClassFactors,
    /// Heuristic weight ε ≥ 1 (not in the source, which is exact: 1). The search orders nodes by
    /// `g + ε·h`: a plan then scores at most ε times the best one, and is found expanding fewer
    /// nodes on terrain where the octile bound is loose (slope costs). See [`SEARCH_WEIGHT_FAST`].
    pub search_weight: f32,
}

/// The path factor K1 and formation factor K2 of a task class.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClassFactors {
    /// Path factor K1, in (0, 1].
    pub k1: f32,
    /// Formation factor K2, in [0, 1].
    pub k2: f32,
}

impl Default for PlanningParams {
    fn default() -> Self {
        PlanningParams {
            relax_step: RELAX_STEP,
            fm_broken: FM_BROKEN,
            keep_share: true,
            must_keep: ClassFactors { k1: 0.05, k2: 0.95 },
            may_change_rarely: ClassFactors { k1: 0.1, k2: 0.9 },
            shortest_first: ClassFactors { k1: 0.9, k2: 0.1 },
            search_weight: 1.0,
        }
    }
}

/// A heuristic weight for fast plans on slope-cost terrain: on the workload of `shoal bench plan`
/// it expands a quarter of the exact search's nodes for 5.5 % more path score (figures in
/// `docs/squads.md`); the bound is 1.25× in the worst case.
pub const SEARCH_WEIGHT_FAST: f32 = 1.25;

/// The 8 move directions `(dcol, drow)`, clockwise from east; a heading index is an index here.
pub const DIRS: [(i32, i32); 8] = [
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
];

/// The task classes of the source, which set the path factor K1, the formation factor K2 and
/// whether the formation may change.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum TaskClass {
    /// The formation must not change: `K1 = 0.05, K2 = 0.95`, no relaxation.
    MustKeep,
    /// The formation may change, but rarely: `K1 = 0.1, K2 = 0.9`.
    #[default]
    MayChangeRarely,
    /// Shortest path first, formation secondary: `K1 = 0.9, K2 = 0.1`.
    ShortestFirst,
    /// Explicit constants.
    Custom {
        /// Path factor, in (0, 1].
        k1: f32,
        /// Formation factor, in [0, 1].
        k2: f32,
        /// Whether the formation may change (and the weights relax when no path is found).
        may_change: bool,
    },
}

impl TaskClass {
    /// The weights this class starts from with the source's constants (relaxation step 0.1).
    pub fn weights(&self) -> Weights {
        self.weights_with(&PlanningParams::default())
    }

    /// The weights this class starts from with the constants of `p`.
    pub fn weights_with(&self, p: &PlanningParams) -> Weights {
        let (k1, k2, may_change) = match *self {
            TaskClass::MustKeep => (p.must_keep.k1, p.must_keep.k2, false),
            TaskClass::MayChangeRarely => (p.may_change_rarely.k1, p.may_change_rarely.k2, true),
            TaskClass::ShortestFirst => (p.shortest_first.k1, p.shortest_first.k2, true),
            TaskClass::Custom { k1, k2, may_change } => (k1, k2, may_change),
        };
        Weights {
            k1,
            k2,
            may_change,
            step: p.relax_step,
            fm_broken: p.fm_broken,
            keep_share: p.keep_share,
            search_weight: p.search_weight,
        }
    }
}

/// The factors of one search and how they relax after a failed one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Weights {
    /// Path factor K1.
    pub k1: f32,
    /// Formation factor K2.
    pub k2: f32,
    /// Whether the formation may change; also whether the weights relax after a failure.
    pub may_change: bool,
    /// How much K2 drops and K1 rises per relaxation.
    pub step: f32,
    /// Formation cost of a step where no follower fits the primary formation ([`FM_BROKEN`]).
    pub fm_broken: f32,
    /// Whether K2 is also the share of followers that must fit ([`required_free`]).
    pub keep_share: bool,
    /// Heuristic weight ε ≥ 1 ([`PlanningParams::search_weight`]); 1 is the exact search.
    pub search_weight: f32,
}

impl Default for Weights {
    /// The source's "may change rarely" class.
    fn default() -> Self {
        TaskClass::MayChangeRarely.weights()
    }
}

impl Weights {
    /// Checks the ranges: `0 < K1 ≤ 1`, `0 ≤ K2 ≤ 1`, `0 < step ≤ 1`, `1 ≤ fm_broken` finite,
    /// `1 ≤ search_weight ≤ 10`.
    pub fn validate(self) -> Result<Weights, FormationError> {
        let ok = (1.0..=MAX_SEARCH_WEIGHT).contains(&self.search_weight)
            && self.k1 > 0.0
            && self.k1 <= 1.0
            && (0.0..=1.0).contains(&self.k2)
            && self.step > 0.0
            && self.step <= 1.0
            && self.fm_broken.is_finite()
            && self.fm_broken >= 1.0;
        if ok {
            Ok(self)
        } else {
            Err(FormationError::BadWeights {
                k1: self.k1,
                k2: self.k2,
                step: self.step,
                fm_broken: self.fm_broken,
                search_weight: self.search_weight,
            })
        }
    }

    /// The next weights after a failed search: `K2 −= step` (not below 0), `K1 += step` (not
    /// above 1), rounded to 1e-6 so the sequence reads 0.1/0.9, 0.2/0.8, … exactly. `None` when
    /// the formation may not change or K2 is already 0.
    pub fn relaxed(&self) -> Option<Weights> {
        if !self.may_change || self.k2 <= 0.0 {
            return None;
        }
        let round = |v: f64| ((v * 1e6).round() / 1e6) as f32;
        Some(Weights {
            k1: round((f64::from(self.k1) + f64::from(self.step)).min(1.0)),
            k2: round((f64::from(self.k2) - f64::from(self.step)).max(0.0)),
            ..*self
        })
    }
}

/// `FM(n) = 1 / Σ aᵢ` for `free = Σ aᵢ` followers in a free slot; `None` (infinite) when none is.
#[inline]
pub fn formation_measure(free: usize) -> Option<f32> {
    (free > 0).then(|| 1.0 / free as f32)
}

/// How many of `followers` must stand in a free slot of the formation taken at a node for the
/// node to be feasible under formation factor `k2`: none when `k2 ≤ 0`; otherwise `⌈k2·N⌉` and
/// at least one when `share` (the engine's reading, see the module notes), one when not.
pub fn required_free(k2: f32, followers: usize, share: bool) -> usize {
    if k2 <= 0.0 || followers == 0 {
        return 0;
    }
    if !share {
        return 1;
    }
    // The tolerance keeps 0.7·10 (6.9999…) or 0.6·5 (3.0000001) in f32 at 7 and 3.
    let need = (f64::from(k2) * followers as f64 - 1e-4).ceil().max(1.0);
    (need as usize).min(followers)
}

/// The path part of one step's score, `len · K1 · cost` (`K1·g` summed step by step).
#[inline]
pub fn path_term(len: f32, k1: f32, cost: f32) -> f32 {
    len * k1 * cost
}

/// The formation part of one step's score, `len · K2 · FM`.
#[inline]
pub fn formation_term(len: f32, k2: f32, fm: f32) -> f32 {
    len * k2 * fm
}

/// The FM a step into a node costs, from the free slots of the primary formation (`primary`) and
/// the most any other allowed formation places (`best_other`), with `need` from
/// [`required_free`]; `None` when the node is infeasible. A node where the primary places no
/// follower but another formation places enough costs `fm_broken`.
#[inline]
pub fn step_fm(primary: usize, best_other: usize, need: usize, fm_broken: f32) -> Option<f32> {
    if primary >= need {
        return Some(formation_measure(primary).unwrap_or(fm_broken));
    }
    (best_other >= need).then(|| formation_measure(primary).unwrap_or(fm_broken))
}

/// Cell offsets `(dcol, drow)` of each follower's slot for each of the 8 headings.
#[derive(Debug, Clone, PartialEq)]
pub struct SlotOffsets {
    per_dir: [Vec<(i32, i32)>; 8],
}

impl SlotOffsets {
    /// The followers' (every member but `leader`) slot cells of `formation` relative to the
    /// leader's cell, for each heading of [`DIRS`].
    pub fn new(formation: &Formation, leader: usize, cell_size: f32) -> Self {
        SlotOffsets {
            per_dir: std::array::from_fn(|d| {
                let (dx, dz) = DIRS[d];
                Self::for_heading(
                    formation,
                    leader,
                    cell_size,
                    Vec2::new(dx as f32, dz as f32),
                )
            }),
        }
    }

    /// The followers' slot cells relative to the leader's for an arbitrary heading: the cell
    /// holding the slot when the leader stands at a cell centre.
    pub fn for_heading(
        formation: &Formation,
        leader: usize,
        cell_size: f32,
        heading: Vec2,
    ) -> Vec<(i32, i32)> {
        (0..formation.len())
            .filter(|&i| i != leader)
            .map(|i| {
                let w = to_world(formation.offset(i, leader), heading) / cell_size;
                ((w.x + 0.5).floor() as i32, (w.y + 0.5).floor() as i32)
            })
            .collect()
    }

    /// Offsets for heading index `dir`.
    pub fn dir(&self, dir: usize) -> &[(i32, i32)] {
        &self.per_dir[dir]
    }
}

/// How many of `offsets` are free cells when the leader stands on `cell`.
pub fn free_slots(grid: &CostGrid, cell: Cell, offsets: &[(i32, i32)]) -> usize {
    offsets
        .iter()
        .filter(|&&(dx, dz)| {
            !grid.is_blocked(
                cell.col as i64 + i64::from(dx),
                cell.row as i64 + i64::from(dz),
            )
        })
        .count()
}

/// The formations of a team laid on a grid: slot offsets per heading for each formation of the
/// list (primary first).
#[derive(Debug, Clone)]
pub struct GridFormations<'a> {
    /// The formations, primary (widest, preferred) first.
    pub formations: &'a [Formation],
    /// The leader's member index.
    pub leader: usize,
    /// Cell size of the grid they are laid on.
    pub cell_size: f32,
    /// Slot offsets of each formation.
    pub tables: Vec<SlotOffsets>,
}

impl<'a> GridFormations<'a> {
    /// Precomputes the slot offsets of every formation for every heading.
    pub fn new(formations: &'a [Formation], leader: usize, cell_size: f32) -> Self {
        GridFormations {
            formations,
            leader,
            cell_size,
            tables: formations
                .iter()
                .map(|f| SlotOffsets::new(f, leader, cell_size))
                .collect(),
        }
    }

    /// Number of followers (members other than the leader).
    pub fn followers(&self) -> usize {
        self.formations
            .first()
            .map_or(0, |f| f.len().saturating_sub(1))
    }

    /// The formation the team takes with the leader on `cell`, and whether all its slots are
    /// free: the first (widest) formation of the list whose slots are all free, or failing that
    /// the one placing the most followers (earliest on ties). Only the primary when the
    /// formation may not change. `slots(j)` gives formation `j`'s offsets for the heading.
    pub fn choose<'s>(
        &self,
        grid: &CostGrid,
        cell: Cell,
        may_change: bool,
        slots: impl Fn(usize) -> std::borrow::Cow<'s, [(i32, i32)]>,
    ) -> (usize, bool) {
        self.choose_from(grid, cell, may_change, 0, slots)
    }

    /// [`GridFormations::choose`] among the formations from index `first` on (a place where a
    /// wider one was found to put a member's way through a wall, see [`crate::formation`]);
    /// `first` is capped at the last formation, and ignored when the formation may not change.
    pub fn choose_from<'s>(
        &self,
        grid: &CostGrid,
        cell: Cell,
        may_change: bool,
        first: usize,
        slots: impl Fn(usize) -> std::borrow::Cow<'s, [(i32, i32)]>,
    ) -> (usize, bool) {
        let n = self.followers();
        let count = if may_change { self.formations.len() } else { 1 };
        let first = first.min(count.saturating_sub(1));
        let mut best = (first, usize::MAX);
        for j in first..count {
            let free = free_slots(grid, cell, &slots(j));
            if free == n {
                return (j, true);
            }
            if best.1 == usize::MAX || free > best.1 {
                best = (j, free);
            }
        }
        (best.0, false)
    }
}

/// A leader path found by one search.
#[derive(Debug, Clone, PartialEq)]
pub struct LeaderSearch {
    /// Cells from start to goal.
    pub cells: Vec<Cell>,
    /// Terrain cost: `Σ step length (cells) × cost of the cell entered`.
    pub cost: f32,
    /// The minimised score `Σ len · (K1·cost + K2·FM)`.
    pub score: f32,
    /// Nodes expanded.
    pub expanded: usize,
}

/// A monotone priority queue over `u64` keys (a radix heap): pushes are O(1), and a pop moves
/// each element down a bucket at most 64 times over its life. Keys below the last one popped
/// are raised to it, which only float rounding can cause under a consistent heuristic (and the
/// inflated heuristic of a weighted search, ε > 1).
#[derive(Debug)]
struct RadixHeap {
    last: u64,
    len: usize,
    /// Bit `b` set when bucket `b` may be non-empty.
    used: u128,
    buckets: Vec<Vec<(u64, u32)>>,
}

impl Default for RadixHeap {
    fn default() -> Self {
        RadixHeap {
            last: 0,
            len: 0,
            used: 0,
            buckets: (0..65).map(|_| Vec::new()).collect(),
        }
    }
}

impl RadixHeap {
    fn clear(&mut self) {
        self.last = 0;
        self.len = 0;
        self.used = 0;
        self.buckets.iter_mut().for_each(Vec::clear);
    }

    #[inline]
    fn bucket(last: u64, key: u64) -> usize {
        64 - (key ^ last).leading_zeros() as usize
    }

    #[inline]
    fn push(&mut self, key: u64, idx: u32) {
        let key = key.max(self.last);
        let b = Self::bucket(self.last, key);
        self.buckets[b].push((key, idx));
        self.used |= 1 << b;
        self.len += 1;
    }

    fn pop(&mut self) -> Option<u32> {
        if self.len == 0 {
            return None;
        }
        if self.buckets[0].is_empty() {
            self.used &= !1;
            let i = self.used.trailing_zeros() as usize;
            let mut moved = std::mem::take(&mut self.buckets[i]);
            self.used &= !(1 << i);
            self.last = moved.iter().map(|e| e.0).min().unwrap_or(self.last);
            for e in moved.drain(..) {
                let b = Self::bucket(self.last, e.0);
                self.buckets[b].push(e);
                self.used |= 1 << b;
            }
            self.buckets[i] = moved;
        }
        self.len -= 1;
        self.buckets[0].pop().map(|e| e.1)
    }
}

/// Per-cell search state: `g`, and a tag holding the generation (high 28 bits), a closed bit
/// and the heading of the step into the cell (low 3 bits).
#[derive(Debug, Clone, Copy, Default)]
struct NodeState {
    g: f32,
    tag: u32,
}

/// The largest grid side a search handles (cells are packed as two 16-bit halves in the queue).
pub const MAX_SIDE: usize = 1 << 16;

#[inline]
fn pack(col: usize, row: usize) -> u32 {
    (col as u32 & 0xFFFF) | ((row as u32) << 16)
}

const CLOSED: u32 = 0b1000;
const DIR_MASK: u32 = 0b0111;
const GEN_SHIFT: u32 = 4;

/// Reusable search buffers: a flat per-cell array stamped with a generation, so a new search
/// clears nothing, and a radix heap.
#[derive(Debug, Default)]
pub struct Planner {
    nodes: Vec<NodeState>,
    generation: u32,
    heap: RadixHeap,
}

/// Linearised slot offsets of one formation for one heading, with their bounding box.
struct DirSlots {
    delta: Vec<isize>,
    offsets: Vec<(i32, i32)>,
    min: (i32, i32),
    max: (i32, i32),
}

impl DirSlots {
    fn new(offsets: &[(i32, i32)], cols: usize) -> Self {
        let mut min = (0, 0);
        let mut max = (0, 0);
        for &(dx, dz) in offsets {
            min = (min.0.min(dx), min.1.min(dz));
            max = (max.0.max(dx), max.1.max(dz));
        }
        DirSlots {
            delta: offsets
                .iter()
                .map(|&(dx, dz)| dz as isize * cols as isize + dx as isize)
                .collect(),
            offsets: offsets.to_vec(),
            min,
            max,
        }
    }

    #[inline]
    fn free(&self, grid: &CostGrid, idx: usize, col: usize, row: usize) -> usize {
        // In i64: an offset may be as large as i32 allows (a formation far wider than the grid),
        // and an i32 sum would wrap past the bounds test into an index outside the grid.
        let (c, r) = (col as i64, row as i64);
        if c + i64::from(self.min.0) >= 0
            && r + i64::from(self.min.1) >= 0
            && c + i64::from(self.max.0) < grid.cols as i64
            && r + i64::from(self.max.1) < grid.rows as i64
        {
            let base = idx as isize;
            self.delta
                .iter()
                .filter(|&&d| !grid.blocked[(base + d) as usize])
                .count()
        } else {
            self.offsets
                .iter()
                .filter(|&&(dx, dz)| !grid.is_blocked(c + i64::from(dx), r + i64::from(dz)))
                .count()
        }
    }
}

impl Planner {
    /// Empty buffers; they grow to the largest grid searched.
    pub fn new() -> Self {
        Planner::default()
    }

    fn prepare(&mut self, n: usize) {
        if self.nodes.len() < n {
            self.nodes.resize(n, NodeState::default());
        }
        self.generation += 1;
        if self.generation >= 1 << (32 - GEN_SHIFT) {
            self.nodes.iter_mut().for_each(|s| s.tag = 0);
            self.generation = 1;
        }
        self.heap.clear();
    }

    /// One formation-aware A* search from `start` to `goal` with the factors of `w` (its step is
    /// not used); `None` when no feasible path exists under them. `w.may_change` selects the rule
    /// for slots that do not fit (see the module notes).
    pub fn search(
        &mut self,
        grid: &CostGrid,
        start: Cell,
        goal: Cell,
        team: &GridFormations<'_>,
        w: Weights,
    ) -> Option<LeaderSearch> {
        let (k1, k2, may_change) = (w.k1, w.k2, w.may_change);
        let (cols, rows) = (grid.cols, grid.rows);
        assert!(
            cols <= MAX_SIDE && rows <= MAX_SIDE,
            "grids are at most {MAX_SIDE} cells a side"
        );
        let n = cols * rows;
        self.prepare(n);
        let gen = self.generation;
        let (si, gi) = (grid.index(start), grid.index(goal));
        if grid.blocked[gi] {
            return None;
        }

        let followers = team.followers();
        let strict = !may_change;
        let need_fm = followers > 0 && (k2 > 0.0 || strict);
        let alternatives = if may_change { team.tables.len() } else { 1 };
        let slots: Vec<[DirSlots; 8]> = team.tables[..alternatives.max(1).min(team.tables.len())]
            .iter()
            .map(|t| std::array::from_fn(|d| DirSlots::new(t.dir(d), cols)))
            .collect();
        let fm_min = if followers > 0 {
            1.0 / followers as f32
        } else {
            0.0
        };
        // ε = 1 keeps the source's exact search; ε > 1 inflates the consistent bound, so keys
        // can fall below the last one popped (the heap raises them) and a closed node is not
        // reopened: the standard weighted A*, whose score stays within ε of the best.
        let h_rate = w.search_weight * (k1 * grid.min_cost() + k2 * fm_min);
        let need = required_free(k2, followers, w.keep_share);
        let fm_broken = w.fm_broken;
        let (gc, gr) = (goal.col as i32, goal.row as i32);
        let octile = |c: i32, r: i32| {
            let (dx, dz) = ((c - gc).abs() as f32, (r - gr).abs() as f32);
            dx.max(dz) + (std::f32::consts::SQRT_2 - 1.0) * dx.min(dz)
        };
        let key = |f: f32, h: f32| (u64::from(f.to_bits()) << 32) | u64::from(h.to_bits());
        let deltas: [isize; 8] = DIRS.map(|(dx, dz)| dz as isize * cols as isize + dx as isize);

        // FM of entering cell `j` (at `col`, `row`) heading `d`; None when infeasible.
        let fm = |j: usize, col: usize, row: usize, d: usize| -> Option<f32> {
            let free = slots[0][d].free(grid, j, col, row);
            if strict {
                return (free == followers).then_some(fm_min);
            }
            if k2 <= 0.0 {
                return Some(0.0);
            }
            if free >= need {
                return step_fm(free, 0, need, fm_broken);
            }
            let mut other = 0;
            for s in &slots[1..] {
                other = other.max(s[d].free(grid, j, col, row));
                if other >= need {
                    break;
                }
            }
            step_fm(free, other, need, fm_broken)
        };

        let tag = gen << GEN_SHIFT;
        let nodes = &mut self.nodes;
        nodes[si] = NodeState { g: 0.0, tag };
        let h0 = h_rate * octile(start.col as i32, start.row as i32);
        self.heap.push(key(h0, h0), pack(start.col, start.row));
        let mut expanded = 0usize;
        let mut found = false;
        while let Some(packed) = self.heap.pop() {
            let (c, r) = ((packed & 0xFFFF) as usize, (packed >> 16) as usize);
            let i = r * cols + c;
            if nodes[i].tag & CLOSED != 0 {
                continue;
            }
            nodes[i].tag |= CLOSED;
            expanded += 1;
            if i == gi {
                found = true;
                break;
            }
            let gcur = nodes[i].g;
            let interior = c > 0 && r > 0 && c + 1 < cols && r + 1 < rows;
            for (d, &(dx, dz)) in DIRS.iter().enumerate() {
                let (nc, nr) = (c as i32 + dx, r as i32 + dz);
                if !interior && (nc < 0 || nr < 0 || nc >= cols as i32 || nr >= rows as i32) {
                    continue;
                }
                let j = (i as isize + deltas[d]) as usize;
                if grid.blocked[j] {
                    continue;
                }
                let diagonal = dx != 0 && dz != 0;
                if diagonal
                    && (grid.blocked[(i as isize + dx as isize) as usize]
                        || grid.blocked[(i as isize + dz as isize * cols as isize) as usize])
                {
                    continue;
                }
                let node = nodes[j];
                let seen = node.tag >> GEN_SHIFT == gen;
                if seen && node.tag & CLOSED != 0 {
                    continue;
                }
                let len = if diagonal {
                    std::f32::consts::SQRT_2
                } else {
                    1.0
                };
                let base = gcur + path_term(len, k1, grid.cost[j]);
                if seen && base + formation_term(len, k2, fm_min) >= node.g {
                    continue;
                }
                let term = if need_fm {
                    match fm(j, nc as usize, nr as usize, d) {
                        Some(v) => formation_term(len, k2, v),
                        None => continue,
                    }
                } else {
                    0.0
                };
                let ng = base + term;
                if seen && ng >= node.g {
                    continue;
                }
                nodes[j] = NodeState {
                    g: ng,
                    tag: tag | d as u32,
                };
                let h = h_rate * octile(nc, nr);
                self.heap
                    .push(key(ng + h, h), pack(nc as usize, nr as usize));
            }
        }
        if !found {
            return None;
        }

        let mut cells = vec![goal];
        let mut i = gi;
        while i != si {
            let d = (nodes[i].tag & DIR_MASK) as usize;
            i = (i as isize - deltas[d]) as usize;
            cells.push(grid.cell_at(i));
        }
        cells.reverse();
        let cost = cells
            .windows(2)
            .map(|w| {
                let diagonal = w[0].col != w[1].col && w[0].row != w[1].row;
                let len = if diagonal {
                    std::f32::consts::SQRT_2
                } else {
                    1.0
                };
                len * grid.cost[grid.index(w[1])]
            })
            .sum();
        Some(LeaderSearch {
            cells,
            cost,
            score: nodes[gi].g,
            expanded,
        })
    }
}

/// Heading index of the step from `a` to the adjacent cell `b`.
pub fn dir_between(a: Cell, b: Cell) -> Option<usize> {
    let d = (b.col as i32 - a.col as i32, b.row as i32 - a.row as i32);
    DIRS.iter().position(|&x| x == d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formation::shape::FormationShape;
    use proptest::prelude::*;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;

    /// Plain Dijkstra with the same moves and step costs, as a reference.
    fn dijkstra(grid: &CostGrid, start: Cell, goal: Cell) -> Option<f64> {
        let n = grid.cols * grid.rows;
        let mut dist = vec![f64::INFINITY; n];
        let mut heap = BinaryHeap::new();
        dist[grid.index(start)] = 0.0;
        heap.push(Reverse(((0.0f64).to_bits(), grid.index(start))));
        while let Some(Reverse((dbits, i))) = heap.pop() {
            let d = f64::from_bits(dbits);
            if d > dist[i] {
                continue;
            }
            if i == grid.index(goal) {
                return Some(d);
            }
            let (c, r) = ((i % grid.cols) as i64, (i / grid.cols) as i64);
            for (dx, dz) in DIRS {
                let (nc, nr) = (c + i64::from(dx), r + i64::from(dz));
                if grid.is_blocked(nc, nr) {
                    continue;
                }
                if dx != 0
                    && dz != 0
                    && (grid.is_blocked(c + i64::from(dx), r)
                        || grid.is_blocked(c, r + i64::from(dz)))
                {
                    continue;
                }
                let j = nr as usize * grid.cols + nc as usize;
                let len = if dx != 0 && dz != 0 {
                    std::f64::consts::SQRT_2
                } else {
                    1.0
                };
                let nd = d + len * f64::from(grid.cost[j]);
                if nd < dist[j] {
                    dist[j] = nd;
                    heap.push(Reverse((nd.to_bits(), j)));
                }
            }
        }
        None
    }

    #[test]
    fn slots_far_outside_the_grid_count_as_blocked() {
        // Offsets as wide as i32 allows: a sum in i32 would wrap past the bounds test.
        let grid = CostGrid::open(8, 8, 1.0, Vec2::ZERO);
        for offsets in [
            vec![(i32::MAX, 0), (1, 0)],
            vec![(0, i32::MAX), (i32::MIN, 0)],
            vec![(i32::MAX, i32::MAX)],
        ] {
            let slots = DirSlots::new(&offsets, grid.cols);
            for (col, row) in [(0, 0), (7, 7), (3, 4)] {
                let free = slots.free(&grid, row * grid.cols + col, col, row);
                let expected = offsets
                    .iter()
                    .filter(|&&(dx, dz)| {
                        !grid.is_blocked(col as i64 + i64::from(dx), row as i64 + i64::from(dz))
                    })
                    .count();
                assert_eq!(free, expected);
            }
        }
    }

    fn random_grid(cols: usize, rows: usize, seed: u64, density: f32) -> CostGrid {
        let mut rng = crate::terrain::SplitMix64::new(seed);
        let mut g = CostGrid::open(cols, rows, 1.0, Vec2::ZERO);
        for i in 0..cols * rows {
            g.blocked[i] = rng.next_f32() < density;
            g.cost[i] = 1.0 + (rng.next_f32() * 4.0).floor();
        }
        g
    }

    /// The grid's opposite corners, unblocked: the start and goal of the random-grid searches.
    fn open_corners(grid: &mut CostGrid) -> (Cell, Cell) {
        let (start, goal) = (Cell::new(0, 0), Cell::new(grid.cols - 1, grid.rows - 1));
        for c in [start, goal] {
            let i = grid.index(c);
            grid.blocked[i] = false;
        }
        (start, goal)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]
        #[test]
        fn with_k2_zero_the_cost_equals_dijkstra(
            cols in 2usize..24, rows in 2usize..24, seed in any::<u64>(), density in 0.0f32..0.45,
            members in 1usize..6
        ) {
            let mut grid = random_grid(cols, rows, seed, density);
            let (start, goal) = open_corners(&mut grid);
            let f = [Formation::new(&FormationShape::Wedge, members, 1.0).unwrap()];
            let team = GridFormations::new(&f, 0, 1.0);
            let mut p = Planner::new();
            let found = p.search(&grid, start, goal, &team, Weights { k1: 1.0, k2: 0.0, ..Weights::default() });
            let reference = dijkstra(&grid, start, goal);
            match (found, reference) {
                (None, None) => {}
                (Some(s), Some(d)) => {
                    prop_assert!((f64::from(s.cost) - d).abs() <= 1e-3 * d.max(1.0), "A* {} vs Dijkstra {}", s.cost, d);
                    prop_assert!((s.score - s.cost).abs() <= 1e-3 * s.cost.max(1.0));
                    prop_assert_eq!(s.cells[0], start);
                    prop_assert_eq!(*s.cells.last().unwrap(), goal);
                    for w in s.cells.windows(2) {
                        prop_assert!(grid.clear_line(w[0], w[1]));
                    }
                    // Reusing the buffers gives the same answer.
                    let again = p.search(&grid, start, goal, &team, Weights { k1: 0.5, k2: 0.0, ..Weights::default() }).unwrap();
                    prop_assert!((again.cost - s.cost).abs() <= 1e-3 * s.cost.max(1.0));
                }
                (a, b) => prop_assert!(false, "A* {:?} vs Dijkstra {:?}", a.map(|s| s.cost), b),
            }
        }

        #[test]
        fn a_weighted_search_scores_within_its_weight_of_the_exact_one(
            cols in 2usize..32, rows in 2usize..32, seed in any::<u64>(), density in 0.0f32..0.4,
            members in 1usize..6, k2 in 0.0f32..0.95, weight in 1.0f32..3.0
        ) {
            let mut grid = random_grid(cols, rows, seed, density);
            let (start, goal) = open_corners(&mut grid);
            let f = [
                Formation::new(&FormationShape::Wedge, members, 1.0).unwrap(),
                Formation::new(&FormationShape::Column, members, 1.0).unwrap(),
            ];
            let team = GridFormations::new(&f, 0, 1.0);
            let exact = Weights { k1: 1.0 - k2, k2, ..Weights::default() };
            let weighted = Weights { search_weight: weight, ..exact };
            let mut p = Planner::new();
            let best = p.search(&grid, start, goal, &team, exact);
            let fast = p.search(&grid, start, goal, &team, weighted);
            match (best, fast) {
                (None, None) => {}
                (Some(b), Some(w)) => {
                    prop_assert!(w.score >= b.score * (1.0 - 1e-4), "weighted {} below exact {}", w.score, b.score);
                    prop_assert!(w.score <= weight * b.score * (1.0 + 1e-4) + 1e-4, "weighted {} above {} × exact {}", w.score, weight, b.score);
                    prop_assert_eq!(w.cells[0], start);
                    prop_assert_eq!(*w.cells.last().unwrap(), goal);
                }
                (b, w) => prop_assert!(false, "exact {:?} vs weighted {:?}", b.map(|s| s.score), w.map(|s| s.score)),
            }
        }
    }

    #[test]
    fn weights_relax_in_tenths_down_to_zero() {
        let mut w = TaskClass::MayChangeRarely.weights();
        let mut seq = vec![(w.k1, w.k2)];
        while let Some(n) = w.relaxed() {
            w = n;
            seq.push((w.k1, w.k2));
        }
        assert_eq!(
            seq,
            vec![
                (0.1, 0.9),
                (0.2, 0.8),
                (0.3, 0.7),
                (0.4, 0.6),
                (0.5, 0.5),
                (0.6, 0.4),
                (0.7, 0.3),
                (0.8, 0.2),
                (0.9, 0.1),
                (1.0, 0.0)
            ]
        );
        assert_eq!(TaskClass::MustKeep.weights().relaxed(), None);
        let s = TaskClass::ShortestFirst.weights().relaxed().unwrap();
        assert_eq!((s.k1, s.k2), (1.0, 0.0));
        assert!(TaskClass::Custom {
            k1: 0.0,
            k2: 0.5,
            may_change: true
        }
        .weights()
        .validate()
        .is_err());
    }

    #[test]
    fn formation_measure_is_one_over_the_free_slots() {
        assert_eq!(formation_measure(0), None);
        assert_eq!(formation_measure(1), Some(1.0));
        assert_eq!(formation_measure(4), Some(0.25));
        assert_eq!(formation_measure(5), Some(0.2));
    }

    #[test]
    fn the_share_that_must_fit_follows_k2() {
        // ⌈K2·N⌉, at least 1 while K2 > 0: 0.9·4 = 3.6 → 4, 0.8·4 = 3.2 → 4, 0.7·4 = 2.8 → 3,
        // 0.6·4 = 2.4 → 3, 0.5·4 = 2, 0.3·4 = 1.2 → 2, 0.1·4 = 0.4 → 1, 0.05·4 = 0.2 → 1.
        let need = |k2: f32| required_free(k2, 4, true);
        let seq: Vec<usize> = [0.9, 0.8, 0.7, 0.6, 0.5, 0.3, 0.1, 0.05, 0.0]
            .map(need)
            .to_vec();
        assert_eq!(seq, vec![4, 4, 3, 3, 2, 2, 1, 1, 0]);
        // f32 products just above or below a whole number: 0.7·10 = 6.9999… → 7, 0.6·5 → 3.
        assert_eq!(required_free(0.7, 10, true), 7);
        assert_eq!(required_free(0.6, 5, true), 3);
        assert_eq!(required_free(1.0, 4, true), 4);
        assert_eq!(required_free(0.95, 4, true), 4);
        // The literal reading: one follower at any K2 > 0; none without followers.
        assert_eq!(required_free(0.9, 4, false), 1);
        assert_eq!(required_free(0.0, 4, false), 0);
        assert_eq!(required_free(0.9, 0, true), 0);
        assert_eq!(required_free(-0.1, 4, true), 0);
    }

    #[test]
    fn step_scores_are_length_times_the_weighted_terms() {
        // √2 · 0.1 · 3 = 0.42426407; 2 · 0.9 · 0.25 = 0.45.
        assert!((path_term(std::f32::consts::SQRT_2, 0.1, 3.0) - 0.424_264_07).abs() < 1e-6);
        assert!((formation_term(2.0, 0.9, 0.25) - 0.45).abs() < 1e-6);
        assert_eq!(path_term(1.0, 1.0, 5.0), 5.0);
        assert_eq!(formation_term(1.0, 0.5, 3.0), 1.5);
    }

    #[test]
    fn step_fm_follows_the_primary_and_falls_back_on_other_formations() {
        // Primary places enough: 1/Σaᵢ.
        assert_eq!(step_fm(4, 0, 4, 2.0), Some(0.25));
        assert_eq!(step_fm(2, 0, 2, 2.0), Some(0.5));
        // Primary too few (1 < 2) but another formation places 4: still 1/1 for the primary.
        assert_eq!(step_fm(1, 4, 2, 2.0), Some(1.0));
        // Primary none, another enough: fm_broken.
        assert_eq!(step_fm(0, 4, 2, 2.0), Some(2.0));
        assert_eq!(step_fm(0, 2, 2, 3.5), Some(3.5));
        // Nobody places enough: infeasible.
        assert_eq!(step_fm(1, 1, 2, 2.0), None);
        assert_eq!(step_fm(0, 0, 1, 2.0), None);
        assert_eq!(step_fm(3, 3, 4, 2.0), None);
        // Nothing needed (K2 = 0): any node.
        assert_eq!(step_fm(0, 0, 0, 2.0), Some(2.0));
    }

    #[test]
    fn the_search_minimises_the_sum_of_weighted_step_scores() {
        // Open 7×5 grid, a line of 3 (spacing 1) from (0, 2) east to (4, 2): 4 steps, both
        // followers free (rows 1 and 3), FM = 1/2: 4 · (0.1·1 + 0.9·0.5) = 4 · 0.55 = 2.2.
        let grid = CostGrid::open(7, 5, 1.0, Vec2::ZERO);
        let line = [Formation::new(&FormationShape::Line, 3, 1.0).unwrap()];
        let team = GridFormations::new(&line, 0, 1.0);
        let w = TaskClass::MayChangeRarely.weights();
        let s = Planner::new()
            .search(&grid, Cell::new(0, 2), Cell::new(4, 2), &team, w)
            .unwrap();
        assert_eq!(s.cells.len(), 5);
        assert!((s.score - 2.2).abs() < 1e-5, "{}", s.score);
        assert!((s.cost - 4.0).abs() < 1e-6);
        // A 5×1 strip with a line and a column: heading east the line's followers are off the
        // grid (0 free), the column's behind; with one follower enough (literal reading) every
        // step costs fm_broken: 4 · (0.1·1 + 0.9·2) = 7.6, and with fm_broken = 3,
        // 4 · (0.1 + 0.9·3) = 11.2.
        let strip = CostGrid::open(5, 1, 1.0, Vec2::ZERO);
        let two = [
            Formation::new(&FormationShape::Line, 3, 1.0).unwrap(),
            Formation::new(&FormationShape::Column, 3, 1.0).unwrap(),
        ];
        let team = GridFormations::new(&two, 0, 1.0);
        let literal = Weights {
            keep_share: false,
            ..w
        };
        let s = Planner::new()
            .search(&strip, Cell::new(0, 0), Cell::new(4, 0), &team, literal)
            .unwrap();
        assert!((s.score - 7.6).abs() < 1e-5, "{}", s.score);
        let s = Planner::new()
            .search(
                &strip,
                Cell::new(0, 0),
                Cell::new(4, 0),
                &team,
                Weights {
                    fm_broken: 3.0,
                    ..literal
                },
            )
            .unwrap();
        assert!((s.score - 11.2).abs() < 1e-5, "{}", s.score);
        // With the share rule (⌈0.9·2⌉ = 2 must fit), the cell next to the start holds one
        // column follower only: no path at K2 = 0.9; at K2 = 0.5 one is enough again.
        assert!(Planner::new()
            .search(&strip, Cell::new(0, 0), Cell::new(4, 0), &team, w)
            .is_none());
        let half = Weights {
            k1: 0.5,
            k2: 0.5,
            ..w
        };
        let s = Planner::new()
            .search(&strip, Cell::new(0, 0), Cell::new(4, 0), &team, half)
            .unwrap();
        // 4 · (0.5·1 + 0.5·2) = 6.
        assert!((s.score - 6.0).abs() < 1e-5, "{}", s.score);
    }

    #[test]
    fn relaxation_clamps_at_the_bounds_and_uses_its_step() {
        let w = Weights {
            k1: 0.8,
            k2: 0.2,
            step: 0.25,
            ..Weights::default()
        };
        let r = w.relaxed().unwrap();
        // 0.8 + 0.25 = 1.05 → 1; 0.2 − 0.25 = −0.05 → 0.
        assert_eq!((r.k1, r.k2), (1.0, 0.0));
        assert_eq!(r.relaxed(), None);
        let w = Weights {
            k1: 0.3,
            k2: 0.6,
            step: 0.25,
            ..Weights::default()
        };
        let r = w.relaxed().unwrap();
        assert_eq!((r.k1, r.k2), (0.55, 0.35));
        assert_eq!(
            Weights {
                may_change: false,
                ..w
            }
            .relaxed(),
            None
        );
        // K2 just above zero still relaxes once.
        let tiny = Weights {
            k1: 0.99,
            k2: 0.01,
            ..Weights::default()
        };
        assert_eq!(tiny.relaxed().map(|r| (r.k1, r.k2)), Some((1.0, 0.0)));
    }

    #[test]
    fn weights_come_from_the_planning_constants() {
        let p = PlanningParams {
            relax_step: 0.2,
            fm_broken: 4.0,
            keep_share: false,
            must_keep: ClassFactors { k1: 0.01, k2: 0.99 },
            may_change_rarely: ClassFactors { k1: 0.3, k2: 0.7 },
            shortest_first: ClassFactors { k1: 0.8, k2: 0.2 },
            search_weight: 1.25,
        };
        let w = TaskClass::MayChangeRarely.weights_with(&p);
        assert_eq!((w.k1, w.k2, w.step, w.fm_broken), (0.3, 0.7, 0.2, 4.0));
        assert_eq!(w.search_weight, 1.25);
        assert_eq!(w.relaxed().map(|r| r.search_weight), Some(1.25));
        assert_eq!(TaskClass::MustKeep.weights().search_weight, 1.0);
        for bad in [0.99, 10.5, f32::NAN] {
            assert!(
                Weights {
                    search_weight: bad,
                    ..w
                }
                .validate()
                .is_err(),
                "{bad}"
            );
        }
        assert!(Weights {
            search_weight: 10.0,
            ..w
        }
        .validate()
        .is_ok());
        assert!(!w.keep_share && w.may_change);
        let w = TaskClass::MustKeep.weights_with(&p);
        assert_eq!((w.k1, w.k2, w.may_change), (0.01, 0.99, false));
        let w = TaskClass::ShortestFirst.weights_with(&p);
        assert_eq!((w.k1, w.k2, w.may_change), (0.8, 0.2, true));
        let d = TaskClass::MustKeep.weights();
        assert_eq!((d.k1, d.k2, d.step, d.fm_broken), (0.05, 0.95, 0.1, 2.0));
        assert!(d.keep_share);
        assert!(Weights {
            fm_broken: 0.5,
            ..d
        }
        .validate()
        .is_err());
        assert!(Weights {
            fm_broken: f32::INFINITY,
            ..d
        }
        .validate()
        .is_err());
        assert!(Weights { step: 0.0, ..d }.validate().is_err());
        assert!(Weights { step: 1.0, ..d }.validate().is_ok());
    }

    #[test]
    fn choosing_from_a_floor_skips_the_wider_formations() {
        // A line and a column of 3 (spacing 1) facing east on a 5 × 3 grid; the leader at (2, 1).
        let grid = CostGrid::open(5, 3, 1.0, Vec2::ZERO);
        let f = [
            Formation::new(&FormationShape::Line, 3, 1.0).unwrap(),
            Formation::new(&FormationShape::Column, 3, 1.0).unwrap(),
        ];
        let team = GridFormations::new(&f, 0, 1.0);
        let slots = |j: usize| std::borrow::Cow::Borrowed(team.tables[j].dir(0));
        let c = Cell::new(2, 1);
        assert_eq!(team.choose(&grid, c, true, slots), (0, true));
        assert_eq!(team.choose_from(&grid, c, true, 1, slots), (1, true));
        // Past the list: the last formation; not allowed to change: the primary.
        assert_eq!(team.choose_from(&grid, c, true, 9, slots), (1, true));
        assert_eq!(team.choose_from(&grid, c, false, 1, slots), (0, true));
        // At (2, 0) the line's left slot (2, −1) is off the grid; the column's (1, 0), (0, 0)
        // fit. At (1, 0) the column's (−1, 0) is off the grid too: each places 1, the earliest
        // is taken unless the floor excludes it. At (0, 0) the line places 1, the column none.
        assert_eq!(team.choose(&grid, Cell::new(2, 0), true, slots), (1, true));
        assert_eq!(team.choose(&grid, Cell::new(1, 0), true, slots), (0, false));
        assert_eq!(
            team.choose_from(&grid, Cell::new(1, 0), true, 1, slots),
            (1, false)
        );
        assert_eq!(team.choose(&grid, Cell::new(0, 0), true, slots), (0, false));
        assert_eq!(
            team.choose_from(&grid, Cell::new(0, 0), true, 1, slots),
            (1, false)
        );
        // With (1, 1) blocked the line places none at (1, 0), the column 1: the column.
        let mut walled = grid.clone();
        let i = walled.index(Cell::new(1, 1));
        walled.blocked[i] = true;
        assert_eq!(
            team.choose(&walled, Cell::new(1, 0), true, slots),
            (1, false)
        );
    }

    #[test]
    fn slot_offsets_turn_with_the_heading() {
        let f = Formation::new(&FormationShape::Wedge, 3, 2.0).unwrap();
        let t = SlotOffsets::new(&f, 0, 2.0);
        // Heading east: member 1 is back-right = west-south.
        assert_eq!(t.dir(0), &[(-1, 1), (-1, -1)]);
        // Heading north: back is south (+row), right is east.
        assert_eq!(t.dir(6), &[(1, 1), (-1, 1)]);
        // Heading south-east: back-right is (−1, 1)·√2 rotated → straight west.
        assert_eq!(t.dir(1), &[(-1, 0), (0, -1)]);
    }
}
