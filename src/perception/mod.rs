//! Stage 2 of the tick: perception (seed 000 §1, seed 001 vision, occlusion and perceived
//! strength, seed 002 non-spherical volume).
//!
//! For every agent, the spatial index yields candidates within its largest sensing range; each is
//! classified by the species' relations (food, predator, kin, mate, other), tested against vision
//! (sphere `v_r` limited to a cone, or a custom body-frame [`Volume`], not fully occluded by
//! obstacles: see [`occlusion`]) and smell (sphere `O_r`), given its bearing, elevation and sector,
//! and folded into a per-category [`Summary`]. Results go into fixed-size per-agent slots, so the
//! stage allocates nothing once warmed up and runs in parallel with identical results.
//!
//! Cost: neighbors are read from a compact per-tick body record, obstacles from an
//! [`ObstacleGrid`], and the two inverse trigonometric calls of a bearing are spent only on the
//! percepts kept (and, in the pipeline, only on those a behavior can read).

pub mod group;
pub mod kin;
pub mod occlusion;
pub mod strength;
mod types;
pub mod volume;

pub use group::{GroupQueries, GroupQuery, GroupSum};
pub use occlusion::Occluders;
pub use strength::Strength;
pub use types::{Category, Level, Percept, Sector, Sense, Source, Summary};
pub use volume::{Extent, Volume};

use crate::frame;
use crate::index::{Grid, ObstacleGrid};
use crate::steering::goal::Sectors;
use crate::world::{Shape, World};
use glam::{Vec3, Vec3A};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Most percepts a species may keep per agent ([`SenseParams::max_percepts`]).
pub const MAX_PERCEPTS: usize = 32;
/// Percepts kept per agent unless the species says otherwise.
pub const DEFAULT_PERCEPTS: usize = 16;
// Kept percepts are flagged in a `u32` bit mask.
const _: () = assert!(MAX_PERCEPTS <= 32);

/// Most obstacles considered as occluders for one agent.
const MAX_OCCLUDERS: usize = 16;

/// A species' senses (defaults from seed 000: vision ±150°, smell farther than vision).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SenseParams {
    /// Vision radius v_r.
    pub vision_radius: f32,
    /// Half-angle of the vision cone (rad); 150° by default.
    pub vision_half_angle: f32,
    /// Smell radius O_r (≥ v_r to matter).
    pub smell_radius: f32,
    /// A custom body-frame volume replacing the vision sphere and cone.
    pub volume: Option<Volume>,
    /// Whether obstacles hide what lies fully behind them ([`occlusion`]).
    pub occlusion: bool,
    /// What obstacles occlude with: their own shape (default) or their bounding sphere
    /// (seed 001's form).
    pub occluders: Occluders,
    /// What must lie in the vision field for a thing to be seen: its centre (default) or any
    /// part of its bounding sphere (seed 001's form, [`Extent::AnyPart`]).
    pub extent: Extent,
    /// Percepts kept per agent (the nearest ones, and always the nearest of each category), at
    /// least one per [`Category`] and at most [`MAX_PERCEPTS`]. Summaries and group sums still cover everything perceived.
    pub max_percepts: usize,
    /// How perceived strength falls with distance (seed 001): read by `Strength(category)` and
    /// scripts, never by perception itself.
    pub strength: Strength,
    /// Direction sector bounds (seed 000 §4.3–4.4: π/6, 5π/6) of the conditions `InSector` and
    /// `AtLevel` and of scripts' `nearest_sector` / `nearest_level`. `Chase` and `Escape` have
    /// their own (`front`, `rear`), with the same defaults.
    pub sectors: Sectors,
}

impl Default for SenseParams {
    fn default() -> Self {
        SenseParams {
            vision_radius: 10.0,
            vision_half_angle: 150f32.to_radians(),
            smell_radius: 20.0,
            volume: None,
            occlusion: true,
            occluders: Occluders::Shape,
            extent: Extent::Centre,
            max_percepts: DEFAULT_PERCEPTS,
            strength: Strength::default(),
            sectors: Sectors::default(),
        }
    }
}

impl SenseParams {
    /// Percepts kept per agent, within `Category::COUNT..=MAX_PERCEPTS`: fewer slots could not
    /// hold the nearest of each category.
    pub fn slots(&self) -> usize {
        self.max_percepts.clamp(Category::COUNT, MAX_PERCEPTS)
    }
    /// The radius a spatial query must cover.
    pub fn query_radius(&self) -> f32 {
        let v = self.volume.map_or(self.vision_radius, |v| v.max_reach());
        v.max(self.smell_radius).max(0.0)
    }
}

/// What each species is to each other one, resolved at load time.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Relations {
    n: usize,
    cats: Vec<Option<Category>>,
    eats_items: Vec<bool>,
    mates: Vec<bool>,
}

impl Relations {
    /// A table for `n` species where everything is ignored.
    pub fn new(n: usize) -> Self {
        Relations {
            n,
            cats: vec![None; n * n],
            eats_items: vec![false; n],
            mates: vec![false; n],
        }
    }
    /// Sets what `other` is to `perceiver`.
    pub fn set(&mut self, perceiver: usize, other: usize, cat: Option<Category>) {
        self.cats[perceiver * self.n + other] = cat;
    }
    /// What `other` is to `perceiver`.
    #[inline]
    pub fn get(&self, perceiver: usize, other: usize) -> Option<Category> {
        self.cats.get(perceiver * self.n + other).copied().flatten()
    }
    /// What every species is to `perceiver`, by species index.
    #[inline]
    fn row(&self, perceiver: usize) -> &[Option<Category>] {
        self.cats
            .get(perceiver * self.n..(perceiver + 1) * self.n)
            .unwrap_or(&[])
    }
    /// Declares that `perceiver` eats food items.
    pub fn set_eats_items(&mut self, perceiver: usize, yes: bool) {
        self.eats_items[perceiver] = yes;
    }
    /// Whether `perceiver` eats food items.
    pub fn eats_items(&self, perceiver: usize) -> bool {
        self.eats_items.get(perceiver).copied().unwrap_or(false)
    }
    /// Declares that kin of the other sex are mates for `perceiver`.
    pub fn set_mates(&mut self, perceiver: usize, yes: bool) {
        self.mates[perceiver] = yes;
    }
    /// Number of species.
    pub fn len(&self) -> usize {
        self.n
    }
    /// Whether the table has no species.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }
}

/// What a species' behaviors read of its perception, worked out at load time (see
/// `tick::reads`), so that the stage does only that work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reads {
    /// Whether any behavior, condition, script or drive reads individual percepts. Without, the
    /// agent keeps none (its summaries and group sums are still complete).
    pub percepts: bool,
    /// Whether it reads agent and food percepts individually too (without, only obstacles are
    /// kept, and agents are folded into summaries and group sums alone).
    pub agent_percepts: bool,
    /// Distance within which agent percepts get their bearing and elevation (obstacles and the
    /// nearest of each category always do); `None`: every percept kept.
    pub bearing_range: Option<f32>,
    /// Neighborhood sums its group rules read.
    pub groups: GroupQueries,
    /// Whether the mean heading of its kin is read (scripts only); without, the kin kernel
    /// leaves it zero.
    pub headings: bool,
}

impl Default for Reads {
    /// Everything: every percept kept with its bearing, no group sums.
    fn default() -> Self {
        Reads {
            percepts: true,
            agent_percepts: true,
            bearing_range: None,
            groups: GroupQueries::new(),
            headings: true,
        }
    }
}

/// Per-agent perception results of one tick.
#[derive(Debug, Clone, Default)]
pub struct Perception {
    /// Percept slots of every agent by row (see `by_grid`), `slot_starts[r]..slot_starts[r + 1]`
    /// for row `r`.
    percepts: Vec<Percept>,
    slot_starts: Vec<u32>,
    counts: Vec<u16>,
    summaries: Vec<SummaryRow>,
    /// Group sums of every agent by row, `sum_starts[r]..sum_starts[r + 1]` for row `r`.
    sums: Vec<GroupSum>,
    sum_starts: Vec<u32>,
    /// Whether the outputs' rows are in the agent grid's order (an agent's row is then its slot,
    /// `slot_of`), not in agent order. Perceivers on the general path are walked in the grid's
    /// order when the grid indexes exactly the world's agents: perceivers next to each other in
    /// the walk are then next to each other in space, and their neighborhoods are read from
    /// cache.
    by_grid: bool,
    /// Yaw and pitch of the agent of each row, when the rows are in the grid's order (the rest
    /// of what a perceiver reads of itself is in `near`, `tags` and the grid's positions).
    angles: Vec<[f32; 2]>,
    /// What a perceiver reads of each agent, gathered once per tick in the agent grid's order,
    /// so that a neighbor costs one small sequential read instead of a walk into the full agent
    /// and two `sin_cos`.
    near: Vec<Body>,
    /// Species and sex of the same agents, in the same order.
    tags: Vec<Tag>,
    /// Bounding-box diagonals of the same agents, in the same order (read for kept percepts).
    diagonals: Vec<f32>,
    /// Slot of each agent in `near`, by agent index (`u32::MAX` when the grid lacks it).
    slot_of: Vec<u32>,
    /// What others read of each agent this tick, by agent index: the grid-order records are
    /// copied from it (reading every agent's record once, in order, on the thread that last
    /// wrote it, is cheaper than reading the records in the grid's order), and agents' passes
    /// read each other here.
    gathered: Vec<Gathered>,
    /// `near` again, one array per component, for the kin kernel (filled only when a species
    /// perceives by it).
    lanes: kin::KinLanes,
    /// Cosine bound of each species' vision cone, this tick.
    cos_mins: Vec<f32>,
    /// Which species may perceive by the kin kernel, this tick.
    kernel: Vec<bool>,
    /// Obstacles by cell, so a perceiver looks only at those that may be in range.
    obstacle_grid: ObstacleGrid,
}

/// What others read of an agent at the start of the tick.
#[derive(Debug, Clone, Copy)]
struct Gathered {
    body: Body,
    tag: Tag,
    diagonal: f32,
    /// Its position a tick before (pursuers read their target's).
    prev_pos: Vec3,
    /// Its heading's angles (copied to the perceivers' rows in the grid's order).
    yaw: f32,
    pitch: f32,
}

/// What a perceiver reads of itself.
#[derive(Debug, Clone, Copy)]
struct Me {
    pos: Vec3,
    yaw: f32,
    pitch: f32,
    /// Forward unit vector.
    heading: Vec3,
    tag: Tag,
}

/// The part of an agent its neighbors read.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Body {
    /// Forward unit vector.
    heading: Vec3,
    /// Speed (`heading * speed` is `Agent::velocity`, bit for bit).
    speed: f32,
}

impl Body {
    #[inline(always)]
    fn velocity(&self) -> Vec3 {
        self.heading * self.speed
    }
}

/// Who an agent is, as its neighbors' relations see it (kept apart from [`Body`]: every
/// candidate's is read, only those perceived have their body read).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Tag {
    species: u16,
    sex: crate::world::Sex,
}

impl Default for Body {
    fn default() -> Self {
        Body {
            heading: Vec3::ZERO,
            speed: 0.0,
        }
    }
}

const EMPTY: Percept = Percept {
    source: Source::Food(0),
    category: Category::Other,
    sense: Sense::Smell,
    offset: Vec3::ZERO,
    dist: 0.0,
    bearing: 0.0,
    elevation: 0.0,
    size: 0.0,
};

/// One agent's share of the stage's output buffers.
struct AgentOut<'a> {
    slots: &'a mut [Percept],
    count: &'a mut u16,
    summary: &'a mut SummaryRow,
    sums: &'a mut [GroupSum],
}

/// The output buffers of agents `lo..lo + counts.len()`.
struct Outs<'a> {
    lo: usize,
    percepts: &'a mut [Percept],
    counts: &'a mut [u16],
    summaries: &'a mut [SummaryRow],
    sums: &'a mut [GroupSum],
}

/// One agent's summaries, by [`Category`], and whether every one but the kin summary is known
/// to be empty (then the kin kernel rewrites that one alone: a boid's tick does not touch the
/// five cache lines of the others).
#[derive(Debug, Clone, Copy, Default)]
struct SummaryRow {
    by: [Summary; Category::COUNT],
    only_kin: bool,
}

/// Agents per task of the parallel walk.
const AGENTS_PER_TASK: usize = 64;

impl<'a> Outs<'a> {
    /// Calls `f(i, out)` for every agent, splitting the range in halves on rayon's pool (each
    /// agent writes only its own slots: the result does not depend on the split).
    fn for_each(
        self,
        slot_starts: &[u32],
        sum_starts: &[u32],
        f: &(impl Fn(usize, AgentOut) + Sync),
    ) {
        let n = self.counts.len();
        if n <= AGENTS_PER_TASK {
            let lo = self.lo;
            let mut percepts = self.percepts;
            let mut sums = self.sums;
            for (k, (count, summary)) in self.counts.iter_mut().zip(self.summaries).enumerate() {
                let i = lo + k;
                let ns = (slot_starts[i + 1] - slot_starts[i]) as usize;
                let ng = (sum_starts[i + 1] - sum_starts[i]) as usize;
                let (slots, rest) = std::mem::take(&mut percepts).split_at_mut(ns);
                percepts = rest;
                let (own_sums, rest) = std::mem::take(&mut sums).split_at_mut(ng);
                sums = rest;
                f(
                    i,
                    AgentOut {
                        slots,
                        count,
                        summary,
                        sums: own_sums,
                    },
                );
            }
            return;
        }
        let mid = n / 2;
        let at = |starts: &[u32]| (starts[self.lo + mid] - starts[self.lo]) as usize;
        let (slot_mid, sum_mid) = (at(slot_starts), at(sum_starts));
        let (p0, p1) = self.percepts.split_at_mut(slot_mid);
        let (c0, c1) = self.counts.split_at_mut(mid);
        let (s0, s1) = self.summaries.split_at_mut(mid);
        let (g0, g1) = self.sums.split_at_mut(sum_mid);
        let left = Outs {
            lo: self.lo,
            percepts: p0,
            counts: c0,
            summaries: s0,
            sums: g0,
        };
        let right = Outs {
            lo: self.lo + mid,
            percepts: p1,
            counts: c1,
            summaries: s1,
            sums: g1,
        };
        rayon::join(
            || left.for_each(slot_starts, sum_starts, f),
            || right.for_each(slot_starts, sum_starts, f),
        );
    }
}

impl Perception {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
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
    /// category; none when its species reads no individual percept.
    #[inline]
    pub fn percepts(&self, i: usize) -> &[Percept] {
        let r = self.row(i);
        let s = self.slot_starts[r] as usize;
        &self.percepts[s..s + self.counts[r] as usize]
    }

    /// Obstacles (indices into `World::obstacles`, active or not) that may be near `p`: every
    /// obstacle within the perception reach of the tick of any point of `p`'s grid cell.
    #[inline]
    pub fn obstacles_near(&self, p: Vec3) -> &[u32] {
        self.obstacle_grid.near(p)
    }

    /// Summaries of agent `i`, indexed by [`Category`].
    #[inline]
    pub fn summaries(&self, i: usize) -> &[Summary; Category::COUNT] {
        &self.summaries[self.row(i)].by
    }

    /// Group sums of agent `i`, one per query of its species' [`Reads::groups`], in order.
    #[inline]
    pub fn group_sums(&self, i: usize) -> &[GroupSum] {
        let r = self.row(i);
        &self.sums[self.sum_starts[r] as usize..self.sum_starts[r + 1] as usize]
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
    /// ([`crate::world::Agent::prev_pos`]).
    #[inline]
    pub fn prev_pos(&self, i: usize) -> Option<Vec3> {
        self.gathered.get(i).map(|g| g.prev_pos)
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
        let n = world.agents.len();
        let default = SenseParams::default();
        let everything = Reads::default();
        // Each agent's share of the output buffers (by its species).
        let share = |s: usize| {
            let r = reads.get(s).unwrap_or(&everything);
            let slots = if r.percepts {
                senses.get(s).unwrap_or(&default).slots() as u32
            } else {
                0
            };
            (slots, r.groups.len() as u32)
        };
        let unsensed = std::sync::atomic::AtomicBool::new(false);
        let unknown = Gathered {
            body: Body::default(),
            tag: Tag {
                species: u16::MAX,
                sex: crate::world::Sex::Female,
            },
            diagonal: 0.0,
            prev_pos: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.0,
        };
        let entries = agents.entries();
        // Species that may perceive by the kin kernel.
        self.kernel.clear();
        self.kernel
            .extend((0..senses.len().max(reads.len())).map(|s| {
                let r = reads.get(s).unwrap_or(&everything);
                kernel_species(s, senses.get(s).unwrap_or(&default), r, relations)
            }));
        let kernel = self.kernel.iter().any(|&k| k);
        // The walk's order: the grid's when it indexes exactly these agents (its inverse is
        // then the row of each) and perceivers take the general path, else agent order.
        // The general path reads each neighbor's scattered records, which perceivers next to
        // each other in space share; the kin kernel reads compact lanes that stay in cache, and
        // the agent pass then reads the outputs faster in agent order.
        let by_grid = !kernel && agents.slots().len() == n && entries.len() == n;
        // The walk in the grid's order reads each perceiver's position from the grid: it must
        // be the grid of these agents' positions (as `Pipeline::perceive` builds it).
        debug_assert!(
            !by_grid
                || n == 0
                || agents.positions()[agents.slots()[0] as usize] == world.agents[0].pos.into(),
            "the agent grid indexes other positions than the world's agents"
        );
        // Every agent's record read once, in order, on the thread that last wrote it; in agent
        // order, its share of the buffers with it.
        self.gathered.resize(n, unknown);
        self.slot_starts.resize(n + 1, 0);
        self.sum_starts.resize(n + 1, 0);
        world
            .agents
            .par_iter()
            .zip(self.gathered[..n].par_iter_mut())
            .zip(self.slot_starts[..n].par_iter_mut())
            .zip(self.sum_starts[..n].par_iter_mut())
            .with_min_len(256)
            .for_each(|(((a, g), slots), sums)| {
                if a.species.0 as usize >= senses.len() {
                    unsensed.store(true, std::sync::atomic::Ordering::Relaxed);
                }
                if !by_grid {
                    (*slots, *sums) = share(a.species.0 as usize);
                }
                *g = Gathered {
                    body: Body {
                        heading: a.forward(),
                        speed: a.speed,
                    },
                    tag: Tag {
                        species: a.species.0,
                        sex: a.attrs.sex,
                    },
                    diagonal: a.diagonal(),
                    prev_pos: a.prev_pos,
                    yaw: a.yaw,
                    pitch: a.pitch,
                };
            });
        let unsensed = unsensed.into_inner();
        self.by_grid = by_grid;
        self.angles.clear();
        let gathered = &self.gathered[..];
        if by_grid {
            // In the grid's order, each row's heading angles, and its share of the buffers.
            self.angles.resize(n, [0.0; 2]);
            self.angles
                .par_iter_mut()
                .zip(self.slot_starts[..n].par_iter_mut())
                .zip(self.sum_starts[..n].par_iter_mut())
                .zip(entries.par_iter())
                .with_min_len(256)
                .for_each(|(((angles, slots), sums), &i)| {
                    let g = &gathered[i as usize];
                    *angles = [g.yaw, g.pitch];
                    (*slots, *sums) = share(g.tag.species as usize);
                });
        }
        let running = |starts: &mut [u32]| {
            let mut total = 0;
            for v in &mut starts[..n] {
                (*v, total) = (total, total + *v);
            }
            starts[n] = total;
            total
        };
        let slots = running(&mut self.slot_starts);
        let sums = running(&mut self.sum_starts);
        self.percepts.resize(slots as usize, EMPTY);
        self.sums.resize(sums as usize, GroupSum::default());
        self.counts.resize(n, 0);
        self.summaries.resize(n, SummaryRow::default());
        let of_slot =
            |k: usize| -> &Gathered { gathered.get(entries[k] as usize).unwrap_or(&unknown) };
        self.near.resize(entries.len(), Body::default());
        // The kin kernel's lanes, when a species may perceive by it, filled in the same pass.
        if kernel {
            self.lanes.fill(agents.positions(), &mut self.near, |k, b| {
                *b = of_slot(k).body;
                (b.heading, b.velocity())
            });
        } else {
            self.lanes
                .fill(&[], &mut [], |_, _: &mut Body| (Vec3::ZERO, Vec3::ZERO));
            self.near
                .par_iter_mut()
                .enumerate()
                .with_min_len(256)
                .for_each(|(k, b)| *b = of_slot(k).body);
        }
        self.tags.resize(entries.len(), unknown.tag);
        self.diagonals.resize(entries.len(), unknown.diagonal);
        self.tags
            .par_iter_mut()
            .zip(self.diagonals.par_iter_mut())
            .enumerate()
            .with_min_len(256)
            .for_each(|(k, (t, d))| {
                let g = of_slot(k);
                (*t, *d) = (g.tag, g.diagonal);
            });
        self.slot_of.clear();
        if agents.slots().len() == n {
            // The grid indexes exactly these agents: its inverse is the slot of each.
            self.slot_of.extend_from_slice(agents.slots());
        } else {
            self.slot_of.resize(n, u32::MAX);
            for (k, &j) in entries.iter().enumerate() {
                if let Some(s) = self.slot_of.get_mut(j as usize) {
                    *s = k as u32;
                }
            }
        }
        self.cos_mins.clear();
        self.cos_mins
            .extend(senses.iter().map(|s| s.vision_half_angle.cos() - 1e-6));
        let default_cos_min = default.vision_half_angle.cos() - 1e-6;
        let cos_mins = &self.cos_mins[..];
        let kernel_ok = &self.kernel[..];
        let near = &self.near[..];
        let tags = &self.tags[..];
        let diagonals = &self.diagonals[..];
        // How far beyond its range a perceiver must look for a body whose edge may be in range
        // (seed 001's "any part", `Extent::AnyPart`).
        let body_reach = diagonals.iter().fold(0.0f32, |m, &d| m.max(d)) * 0.5;
        let slot_of = &self.slot_of[..];
        let angles = &self.angles[..];
        let positions = agents.positions();
        let lanes = (kernel && self.lanes.len() == near.len()).then_some(&self.lanes);
        let reach = senses
            .iter()
            .chain(unsensed.then_some(&default))
            .map(|s| s.query_radius())
            .fold(0.0, f32::max);
        self.obstacle_grid
            .update(world.bounds, reach, &world.obstacles);
        let obstacle_grid = &self.obstacle_grid;
        let outs = Outs {
            lo: 0,
            percepts: &mut self.percepts,
            counts: &mut self.counts,
            summaries: &mut self.summaries,
            sums: &mut self.sums,
        };
        outs.for_each(&self.slot_starts, &self.sum_starts, &|r, out| {
            // The perceiver of row `r`, and what it reads of itself: in the grid's order from
            // the slot-ordered copies, in agent order from its record.
            let (i, me) = if by_grid {
                let [yaw, pitch] = angles[r];
                let me = Me {
                    pos: positions[r].into(),
                    yaw,
                    pitch,
                    heading: near[r].heading,
                    tag: tags[r],
                };
                (entries[r] as usize, me)
            } else {
                let a = &world.agents[r];
                let me = Me {
                    pos: a.pos,
                    yaw: a.yaw,
                    pitch: a.pitch,
                    heading: gathered[r].body.heading,
                    tag: gathered[r].tag,
                };
                (r, me)
            };
            let me = &me;
            let s = me.tag.species as usize;
            let sense = senses.get(s).unwrap_or(&default);
            let rd = reads.get(s).unwrap_or(&everything);
            // Cosine bound of the vision cone (as `volume::in_cone` computes it).
            let cos_min = cos_mins.get(s).copied().unwrap_or(default_cos_min);
            let view = View {
                world,
                near,
                tags,
                diagonals,
                body_reach,
                lanes,
                kernel: kernel_ok,
                slot_of,
                agents,
                food,
                obstacle_grid,
                relations,
            };
            *out.count = if out.slots.is_empty() {
                perceive_one::<false>(
                    i,
                    me,
                    &view,
                    sense,
                    cos_min,
                    rd,
                    out.slots,
                    out.summary,
                    out.sums,
                )
            } else {
                perceive_one::<true>(
                    i,
                    me,
                    &view,
                    sense,
                    cos_min,
                    rd,
                    out.slots,
                    out.summary,
                    out.sums,
                )
            };
        });
    }
}

impl Perception {
    /// Replaces what agent `i` (at `pos`) perceived this tick by `percepts` (the nearest
    /// [`MAX_PERCEPTS`] kept) and rebuilds its summaries from them, as the stage would have.
    /// Agent percepts carry no heading or velocity, so their means are zero.
    pub fn inject(&mut self, i: usize, pos: Vec3, percepts: &[Percept]) {
        if i >= self.counts.len() {
            return;
        }
        let i = self.row(i);
        let range = self.slot_starts[i] as usize..self.slot_starts[i + 1] as usize;
        let slots = &mut self.percepts[range];
        // Fed percepts stand for no object of the world: no neighbor for the group rules.
        let sums = self.sum_starts[i] as usize..self.sum_starts[i + 1] as usize;
        self.sums[sums].fill(GroupSum::default());
        // Folded as perception folds what it perceives (no heading or velocity: their means
        // are zero), the nearest of each category kept.
        let mut fold = Fold::<true>::new(slots);
        for p in percepts {
            let at = Vec3A::from(pos + p.offset);
            let d = p.dist;
            fold.take(
                p.category,
                p.sense,
                d,
                || d,
                at,
                Vec3A::ZERO,
                Vec3A::ZERO,
                |_| *p,
            );
        }
        let row = &mut self.summaries[i];
        row.only_kin = false;
        let len = fold.finish(&mut row.by).0.len();
        self.counts[i] = len as u16;
    }
}

/// The nearest percepts of one agent, as many as it has slots: appends while there is room,
/// else replaces the farthest when nearer. The farthest slot (the first one of the largest
/// distance) is remembered between offers and looked for again only after a replacement.
struct Kept<'a> {
    slots: &'a mut [Percept],
    /// Distances of `slots`, contiguous for the search of the farthest; −∞ past the slots.
    dists: [f32; MAX_PERCEPTS],
    len: usize,
    /// The first slot of the largest distance, when `far_valid`.
    far: usize,
    far_valid: bool,
    /// The largest distance (when `far_valid`) or an upper bound of it.
    bound: f32,
}

impl Kept<'_> {
    /// The first slot of the largest distance, once every slot is used (distances are finite:
    /// positions are kept inside the world bounds).
    #[inline]
    fn find_far(&mut self) {
        // Four independent running maxima and a mask of the slots equal to the largest: no
        // serial chain of compares and branches. Entries past the slots are −∞.
        // Only the chunks that hold slots (entries past them are −∞).
        let used = self.slots.len().div_ceil(4) * 4;
        let d = &self.dists[..used.min(MAX_PERCEPTS)];
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
        self.far = (mask.trailing_zeros() as usize).min(self.len.saturating_sub(1));
    }

    /// Offers the percept `make()` builds, at distance `dist`; `make` runs only when it is kept.
    /// After a replacement the farthest slot is looked for again only when an offer could beat
    /// the distance just replaced (an upper bound of the new largest one).
    #[inline(always)]
    fn offer(&mut self, dist: f32, make: impl FnOnce() -> Percept) {
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
fn restore_nearest(
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
        offer(p.category as usize);
        if p.category == Category::Mate {
            offer(Category::Kin as usize);
        }
    }
    best
}

/// Running sums of one category, kept in 16-byte lanes while the neighbors are walked,
/// written out as a [`Summary`] at the end.
#[derive(Debug, Clone, Copy)]
struct Acc {
    pos: Vec3A,
    heading: Vec3A,
    vel: Vec3A,
    count: u32,
    seen: u32,
    /// Ordering key of the nearest so far (squared distance) and its distance.
    key: f32,
    nearest: f32,
    /// `Σ 1/d` (predators only).
    inv_dist: f32,
}

const ACC: Acc = Acc {
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
    #[inline(always)]
    fn note(
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
}

/// What one agent has perceived so far: per-category sums, kept percepts and, per category,
/// the nearest percept (kept even when nearer ones of other categories fill the slots).
/// `KEEP`: whether the agent keeps percepts at all (without, the per-percept bookkeeping
/// compiles away).
struct Fold<'a, const KEEP: bool> {
    acc: [Acc; Category::COUNT],
    kept: Kept<'a>,
    nearest: [Percept; Category::COUNT],
    /// Categories with a percept in `nearest` (bit per category).
    offered: u8,
}

impl<'a, const KEEP: bool> Fold<'a, KEEP> {
    /// Nothing perceived yet; `slots` receive the kept percepts.
    fn new(slots: &'a mut [Percept]) -> Self {
        Fold {
            acc: [ACC; Category::COUNT],
            kept: Kept {
                slots,
                dists: [f32::NEG_INFINITY; MAX_PERCEPTS],
                len: 0,
                far: 0,
                far_valid: false,
                bound: f32::INFINITY,
            },
            nearest: [EMPTY; Category::COUNT],
            offered: 0,
        }
    }

    /// Writes the summaries (means, and the nearest among the kept percepts: the first of the
    /// smallest distance, mates also counting as kin), with the nearest of each category put
    /// back among the kept; returns the kept percepts and a bit mask of the slots that are some
    /// category's nearest.
    fn finish(&mut self, summary: &mut [Summary; Category::COUNT]) -> (&'a mut [Percept], u32) {
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
        let mut nearest = 0u32;
        for (sm, b) in summary.iter_mut().zip(best) {
            if sm.count > 0 {
                let n = sm.count as f32;
                sm.centroid /= n;
                sm.mean_heading /= n;
                sm.mean_velocity /= n;
            }
            sm.nearest = b.map(|b| b.0);
            if let Some((k, _)) = b {
                nearest |= 1 << k;
            }
        }
        (&mut slots[..len], nearest)
    }

    /// Notes one percept of category `cat` at squared distance `key` (distance `dist()`),
    /// which `make(dist)` builds if it is kept.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn take(
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
        self.acc[cat as usize].note(seen, key, &dist, pos, heading, vel);
        if cat == Category::Mate {
            self.acc[Category::Kin as usize].note(seen, key, &dist, pos, heading, vel);
        }
        if cat == Category::Predator {
            self.acc[cat as usize].inv_dist += 1.0 / dist().max(1e-6);
        }
    }

    /// Notes one percept of category `cat` in the sums only (never kept).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn sum(
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

    /// Writes the sums out as summaries (means not yet divided).
    fn sums_into(&self, summary: &mut [Summary; Category::COUNT]) {
        for (sm, a) in summary.iter_mut().zip(&self.acc) {
            *sm = Summary {
                count: a.count,
                seen: a.seen,
                nearest: None,
                nearest_dist: a.nearest,
                centroid: a.pos.into(),
                mean_heading: a.heading.into(),
                mean_velocity: a.vel.into(),
                inv_dist_sum: a.inv_dist,
            };
        }
    }
}

/// An unused occluder slot.
const NO_OCCLUDER: Shape = Shape::Sphere {
    center: Vec3::ZERO,
    radius: 0.0,
};

/// A perceiver's body frame and vision cone, computed once per agent.
struct Eye {
    fwd: Vec3,
    left: Vec3,
    up: Vec3,
    /// Cosine bound of the vision cone (as [`volume::in_cone`] computes it).
    cos_min: f32,
    /// Whether the cone is the whole sphere.
    full_circle: bool,
}

impl Eye {
    /// `offset` in the body frame (x left, y up, z forward).
    #[inline(always)]
    fn local(&self, offset: Vec3) -> Vec3 {
        Vec3::new(
            offset.dot(self.left),
            offset.dot(self.up),
            offset.dot(self.fwd),
        )
    }
}

/// What every perceiver reads: the world at the start of the tick and this tick's indexes.
struct View<'a> {
    world: &'a World,
    /// Agents' records in the agent grid's order.
    near: &'a [Body],
    /// Their species and sex, in the same order.
    tags: &'a [Tag],
    /// Their bounding-box diagonals, in the same order.
    diagonals: &'a [f32],
    /// Half the largest of them: the largest bounding radius.
    body_reach: f32,
    /// The same for the kin kernel, when a species may perceive by it.
    lanes: Option<&'a kin::KinLanes>,
    /// Which species may perceive by the kin kernel.
    kernel: &'a [bool],
    /// Slot of each agent in `near`.
    slot_of: &'a [u32],
    agents: &'a Grid,
    food: &'a Grid,
    obstacle_grid: &'a ObstacleGrid,
    relations: &'a Relations,
}

/// What the kin kernel needs of a perceiver at `here`, in grid slot `me_slot`.
fn probe(here: Vec3, me_slot: u32, sense: &SenseParams, eye: &Eye, reads: &Reads) -> kin::Probe {
    kin::Probe {
        here,
        me: me_slot as usize,
        vision2: sense.vision_radius * sense.vision_radius,
        smell2: sense.smell_radius * sense.smell_radius,
        cone: (!eye.full_circle).then_some((eye.fwd, eye.cos_min)),
        headings: reads.headings,
    }
}

/// The kin kernel over the grid rows within `radius` of the probe: the kin sums, and the group
/// sums into `sums`.
fn kernel(
    view: &View,
    lanes: &kin::KinLanes,
    probe: kin::Probe,
    radius: f32,
    groups: &GroupQueries,
    sums: &mut [GroupSum],
) -> Acc {
    let mut k = kin::KinFold::new(lanes, probe, groups.iter());
    view.agents
        .for_each_row_within(probe.here, radius, |s, e| k.row(s, e));
    let sums_k = k.finish(sums);
    Acc {
        pos: sums_k.pos,
        heading: sums_k.heading,
        vel: sums_k.vel,
        count: sums_k.count,
        seen: sums_k.seen,
        key: sums_k.nearest2,
        nearest: sums_k.nearest2.sqrt(),
        inv_dist: 0.0,
    }
}

/// Whether agents of species `s` may perceive by the kin kernel (an agent with an occluder near
/// it still takes the general path).
fn kernel_species(s: usize, sense: &SenseParams, reads: &Reads, relations: &Relations) -> bool {
    let keeps_agents = reads.percepts && reads.agent_percepts && sense.slots() > 0;
    !keeps_agents
        && sense.volume.is_none()
        && sense.extent == Extent::Centre
        && !relations.mates.get(s).copied().unwrap_or(false)
        && relations.row(s).iter().all(|c| *c == Some(Category::Kin))
        && kin::supports(&reads.groups)
}

/// Perceives for agent `i`: fills its slots, summaries and group sums; returns the number of
/// percepts kept.
#[allow(clippy::too_many_arguments)]
fn perceive_one<const KEEP: bool>(
    i: usize,
    me: &Me,
    view: &View,
    sense: &SenseParams,
    cos_min: f32,
    reads: &Reads,
    slots: &mut [Percept],
    summary: &mut SummaryRow,
    sums: &mut [GroupSum],
) -> u16 {
    let world = view.world;
    let s = me.tag.species as usize;
    let (yaw, pitch) = (me.yaw, me.pitch);
    // The body frame, only where a cone or a sense volume reads it. `frame::dorsal` is
    // `forward × left`: reuse both (the forward vector is in the body cache).
    let full_circle = cos_min < -1.000_000_5;
    let eye = if full_circle && sense.volume.is_none() {
        Eye {
            fwd: Vec3::ZERO,
            left: Vec3::ZERO,
            up: Vec3::ZERO,
            cos_min,
            full_circle,
        }
    } else {
        let fwd = me.heading;
        let left = frame::left(yaw);
        Eye {
            fwd,
            left,
            up: fwd.cross(left),
            cos_min,
            full_circle,
        }
    };
    let radius = sense.query_radius();
    let groups = &reads.groups;
    // A plain flocker with nothing but kin around (no obstacle, no food): the kin kernel
    // alone, its sums written straight into the summaries.
    if let (Some(lanes), Some(&me_slot), true) = (
        view.lanes,
        view.slot_of.get(i),
        view.kernel.get(s).copied().unwrap_or(false),
    ) {
        if !view.relations.eats_items(s) && view.obstacle_grid.near(me.pos).is_empty() {
            let probe = probe(me.pos, me_slot, sense, &eye, reads);
            let acc = kernel(view, lanes, probe, radius, groups, sums);
            if !summary.only_kin {
                summary.by.fill(Summary::default());
                summary.only_kin = true;
            }
            let sm = &mut summary.by[Category::Kin as usize];
            *sm = Summary {
                count: acc.count,
                seen: acc.seen,
                nearest: None,
                nearest_dist: acc.nearest,
                centroid: acc.pos.into(),
                mean_heading: acc.heading.into(),
                mean_velocity: acc.vel.into(),
                inv_dist_sum: 0.0,
            };
            // As `Fold::finish` divides.
            if sm.count > 0 {
                let n = sm.count as f32;
                sm.centroid /= n;
                sm.mean_heading /= n;
                sm.mean_velocity /= n;
            }
            return 0;
        }
    }
    let mut fold = Fold::<KEEP>::new(slots);
    sums.fill(GroupSum::default());

    // Nearby obstacles first: they are percepts and occluders.
    let mut occluders = [NO_OCCLUDER; MAX_OCCLUDERS];
    let mut n_occ = 0;
    // The grid lists, in index order, every active obstacle that may be within `radius`.
    for &k in view.obstacle_grid.near(me.pos) {
        let o = &world.obstacles[k as usize];
        if !o.active {
            continue;
        }
        let surface = o.shape.closest_point(me.pos);
        let offset = surface - me.pos;
        let dist = offset.length();
        if dist > radius {
            continue;
        }
        if sense.occlusion && n_occ < MAX_OCCLUDERS {
            occluders[n_occ] = occlusion::occluder(&o.shape, sense.occluders);
            n_occ += 1;
        }
        let to_center = o.shape.center() - me.pos;
        let dir = if dist > 1e-6 { offset } else { to_center };
        let mut seen = sense_of(me.pos, dir, dir.length(), dist, &eye, sense);
        if sense.extent == Extent::AnyPart && seen != Some(Sense::Vision) {
            // Seed 001: its bounding sphere partly in the field is enough.
            let r = o.shape.bounding_radius();
            let any = match &sense.volume {
                Some(v) => v.contains_sphere(eye.local(to_center), r),
                None => {
                    dist <= sense.vision_radius
                        && (eye.full_circle
                            || volume::sphere_in_cone(
                                eye.fwd,
                                to_center,
                                r,
                                sense.vision_half_angle,
                            ))
                }
            };
            if any {
                seen = Some(Sense::Vision);
            }
        }
        if let Some(seen) = seen {
            let cat = Category::Obstacle;
            fold.take(
                cat,
                seen,
                dist * dist,
                || dist,
                (me.pos + offset).into(),
                Vec3A::ZERO,
                Vec3A::ZERO,
                |dist| {
                    percept(
                        Source::Obstacle(k),
                        cat,
                        seen,
                        dir,
                        dist,
                        o.shape.diagonal(),
                    )
                },
            );
        }
    }
    let occ = &occluders[..n_occ];

    let relations = view.relations;
    let mates = relations.mates.get(s).copied().unwrap_or(false);
    let (here, my_sex) = (me.pos, me.tag.sex);
    let here_a = Vec3A::from(here);
    let row = relations.row(s);
    let entries = view.agents.entries();
    // Own slot in the grid's order: a candidate there is oneself.
    let me_slot = view.slot_of.get(i).map_or(usize::MAX, |&k| k as usize);
    // With `AnyPart`, a body whose centre lies beyond the ranges may reach into them.
    let agent_radius = match sense.extent {
        Extent::Centre => radius,
        Extent::AnyPart => radius + view.body_reach,
    };
    // A species that keeps no percepts and sees only kin, plainly (no occluder, no custom
    // volume, no mates): the neighbors go straight into the kin sums, held in registers.
    // Agents and food are kept as percepts only where the species reads them.
    let agent_percepts = KEEP && reads.agent_percepts;
    let plain = !agent_percepts
        && sense.volume.is_none()
        && !mates
        && row.iter().all(|c| matches!(c, None | Some(Category::Kin)));
    let lanes = view.lanes.filter(|_| {
        plain
            && occ.is_empty()
            && row.iter().all(|c| *c == Some(Category::Kin))
            && kin::supports(groups)
    });
    if let (Some(lanes), Some(&me_slot)) = (lanes, view.slot_of.get(i)) {
        let probe = probe(here, me_slot, sense, &eye, reads);
        fold.acc[Category::Kin as usize] = kernel(view, lanes, probe, radius, groups, sums);
    } else if plain {
        let mut kin = ACC;
        view.agents
            .for_each_slot_within(here, agent_radius, |k, pos, d2| {
                if k == me_slot
                    || row.get(view.tags[k].species as usize) != Some(&Some(Category::Kin))
                {
                    return;
                }
                let offset = pos - here_a;
                let radius = || view.diagonals[k] * 0.5;
                let Some(seen) = sense_point(here, offset.into(), d2, &eye, sense, occ, radius)
                else {
                    return;
                };
                let other = &view.near[k];
                let vel = Vec3A::from(other.velocity());
                groups.add(sums, offset, d2, vel);
                kin.note(seen, d2, || d2.sqrt(), pos, other.heading.into(), vel);
            });
        fold.acc[Category::Kin as usize] = kin;
    } else {
        view.agents
            .for_each_slot_within(here, agent_radius, |k, pos, d2| {
                if k == me_slot {
                    return;
                }
                let tag = view.tags[k];
                let Some(mut cat) = row.get(tag.species as usize).copied().flatten() else {
                    return;
                };
                if cat == Category::Kin && mates && tag.sex != my_sex {
                    cat = Category::Mate;
                }
                let offset_a = pos - here_a;
                let offset = Vec3::from(offset_a);
                let radius = || view.diagonals[k] * 0.5;
                let Some(seen) = sense_point(here, offset, d2, &eye, sense, occ, radius) else {
                    return;
                };
                let other = &view.near[k];
                let vel = Vec3A::from(other.velocity());
                if matches!(cat, Category::Kin | Category::Mate) {
                    groups.add(sums, offset_a, d2, vel);
                }
                // `offset.length()`, bit for bit: the grid measured `offset.length_squared()`.
                let dist = || d2.sqrt();
                if !agent_percepts {
                    fold.sum(cat, seen, d2, dist, pos, other.heading.into(), vel);
                    return;
                }
                fold.take(
                    cat,
                    seen,
                    d2,
                    dist,
                    pos,
                    other.heading.into(),
                    vel,
                    |dist| {
                        percept(
                            Source::Agent(entries[k]),
                            cat,
                            seen,
                            offset,
                            dist,
                            view.diagonals[k],
                        )
                    },
                );
            });
    }

    if relations.eats_items(s) {
        view.food.for_each_within(here, radius, |j, pos, d2| {
            let offset = pos - here;
            if let Some(seen) = sense_point(here, offset, d2, &eye, sense, occ, || 0.0) {
                let cat = Category::Food;
                let at = Vec3A::from(pos);
                let dist = || d2.sqrt();
                if !agent_percepts {
                    fold.sum(cat, seen, d2, dist, at, Vec3A::ZERO, Vec3A::ZERO);
                    return;
                }
                fold.take(cat, seen, d2, dist, at, Vec3A::ZERO, Vec3A::ZERO, |dist| {
                    percept(Source::Food(j), cat, seen, offset, dist, 0.0)
                });
            }
        });
    }

    summary.only_kin = false;
    let (slots, nearest) = fold.finish(&mut summary.by);
    let len = slots.len();

    // Bearing and elevation (a pure function of the offset) for the percepts kept, or only for
    // those the species reads.
    for (k, p) in slots.iter_mut().enumerate() {
        let wanted = match reads.bearing_range {
            None => true,
            Some(r) => nearest & (1 << k) != 0 || p.category == Category::Obstacle || p.dist <= r,
        };
        if wanted {
            (p.bearing, p.elevation) = frame::bearing_elevation(yaw, pitch, p.offset);
        }
    }
    len as u16
}

/// A percept without bearing and elevation (filled in for the percepts kept).
#[inline(always)]
fn percept(
    source: Source,
    category: Category,
    sense: Sense,
    offset: Vec3,
    dist: f32,
    size: f32,
) -> Percept {
    Percept {
        source,
        category,
        sense,
        offset,
        dist,
        bearing: 0.0,
        elevation: 0.0,
        size,
    }
}

/// Decides whether a target at `offset`, of squared length `d2` and bounding radius
/// `radius()` (asked only when occluders hide its centre), is seen, smelt or missed: ranges
/// are compared squared, and the square root is taken only for a vision cone.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sense_point(
    from: Vec3,
    offset: Vec3,
    d2: f32,
    eye: &Eye,
    sense: &SenseParams,
    occluders: &[Shape],
    radius: impl FnOnce() -> f32,
) -> Option<Sense> {
    let smell = d2 <= sense.smell_radius * sense.smell_radius;
    if sense.extent == Extent::AnyPart {
        return sense_any_part(from, offset, d2, radius(), smell, eye, sense, occluders);
    }
    let vision = d2 <= sense.vision_radius * sense.vision_radius;
    sense_with(
        from,
        offset,
        || d2.sqrt(),
        vision,
        smell,
        eye,
        sense,
        (occluders, radius),
    )
}

/// [`sense_point`] for [`Extent::AnyPart`] (seed 001): a body of bounding radius `r` is seen
/// when any part of its bounding sphere is in the field: `d − r ≤ v_r` and
/// [`volume::sphere_in_cone`], or within the volume along the ray to its centre. Smell still
/// goes by the centre.
#[allow(clippy::too_many_arguments)]
fn sense_any_part(
    from: Vec3,
    offset: Vec3,
    d2: f32,
    r: f32,
    within_smell: bool,
    eye: &Eye,
    sense: &SenseParams,
    occluders: &[Shape],
) -> Option<Sense> {
    let in_vision = match &sense.volume {
        Some(v) => v.contains_sphere(eye.local(offset), r),
        None => {
            d2.sqrt() - r <= sense.vision_radius
                && (eye.full_circle
                    || volume::sphere_in_cone(eye.fwd, offset, r, sense.vision_half_angle))
        }
    };
    if in_vision && (occluders.is_empty() || !occlusion::hidden(from, offset, || r, occluders)) {
        Some(Sense::Vision)
    } else if within_smell {
        Some(Sense::Smell)
    } else {
        None
    }
}

/// Decides whether an obstacle at `offset` (of length `offset_len`; `dist` is the distance the
/// ranges apply to, to its surface) is seen, smelt or missed: obstacles are not occluded.
#[inline(always)]
fn sense_of(
    from: Vec3,
    offset: Vec3,
    offset_len: f32,
    dist: f32,
    eye: &Eye,
    sense: &SenseParams,
) -> Option<Sense> {
    let vision = dist <= sense.vision_radius;
    let smell = dist <= sense.smell_radius;
    sense_with(
        from,
        offset,
        || offset_len,
        vision,
        smell,
        eye,
        sense,
        (&[], || 0.0),
    )
}

/// The sense test itself, given whether the target is within the vision and smell ranges and
/// the length of `offset` (asked only for a vision cone).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sense_with(
    from: Vec3,
    offset: Vec3,
    offset_len: impl FnOnce() -> f32,
    within_vision: bool,
    within_smell: bool,
    eye: &Eye,
    sense: &SenseParams,
    (occluders, radius): (&[Shape], impl FnOnce() -> f32),
) -> Option<Sense> {
    let in_vision = match &sense.volume {
        Some(v) => v.contains(eye.local(offset)),
        // `volume::in_cone` with the cosine computed once per perceiver; a full circle (±180°,
        // bound below −1 by more than any rounding of a unit vector's dot product) needs no test.
        None => {
            within_vision
                && (eye.full_circle || {
                    let len = offset_len();
                    len == 0.0 || eye.fwd.dot(offset) / len >= eye.cos_min
                })
        }
    };
    if in_vision && (occluders.is_empty() || !occlusion::hidden(from, offset, radius, occluders)) {
        Some(Sense::Vision)
    } else if within_smell {
        Some(Sense::Smell)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{
        Aabb, Agent, AgentId, Anim, Attributes, Drives, Mind, Rng, Shape, SpeciesId,
    };

    pub(crate) fn agent(id: u32, species: u16, pos: Vec3, yaw: f32) -> Agent {
        Agent {
            id: AgentId(id),
            species: SpeciesId(species),
            pos,
            prev_pos: pos,
            yaw,
            pitch: 0.0,
            speed: 1.0,
            yaw_rate: 0.0,
            pitch_rate: 0.0,
            size: Vec3::new(0.2, 0.3, 1.0),
            drives: Drives::default(),
            attrs: Attributes::default(),
            mind: Mind::new(0, 1, 0),
            anim: Anim::default(),
            rng: Rng::new(0, id as u64),
            memory: Vec::new(),
            inbox: None,
            forward_cache: crate::world::ForwardCache::NONE,
        }
    }

    fn run(world: &World, rel: &Relations, sense: SenseParams) -> Perception {
        let mut ag = Grid::new();
        ag.rebuild(
            world.bounds,
            sense.query_radius(),
            world.agents.iter().map(|a| a.pos),
        );
        let mut fg = Grid::new();
        fg.rebuild(
            world.bounds,
            sense.query_radius(),
            world.food.iter().map(|f| f.pos),
        );
        let mut p = Perception::new();
        p.run(world, &ag, &fg, &[sense, sense], rel);
        p
    }

    /// A point drawn uniformly in the cube `[-half, half]³`.
    fn random_point(rng: &mut Rng, half: f32) -> Vec3 {
        Vec3::new(
            rng.range(-half, half),
            rng.range(-half, half),
            rng.range(-half, half),
        )
    }

    fn rel() -> Relations {
        let mut r = Relations::new(2);
        r.set(0, 0, Some(Category::Kin));
        r.set(0, 1, Some(Category::Predator));
        r.set(1, 0, Some(Category::Food));
        r.set_eats_items(0, true);
        r
    }

    #[test]
    fn vision_smell_and_blind_spot() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        // Predator ahead-right within vision: bearing +π/4 (right is −X).
        w.agents.push(agent(1, 1, Vec3::new(-5.0, 0.0, 5.0), 0.0));
        // Kin straight behind within vision radius: blind spot → only smelt.
        w.agents.push(agent(2, 0, Vec3::new(0.0, 0.0, -5.0), 0.0));
        // Food at 15: smell only. Food at 25: nothing.
        w.add_food(Vec3::new(0.0, 0.0, 15.0));
        w.add_food(Vec3::new(0.0, 0.0, 25.0));
        let p = run(&w, &rel(), SenseParams::default());
        let sm = p.summaries(0);
        assert_eq!(sm[Category::Predator as usize].count, 1);
        assert_eq!(sm[Category::Predator as usize].seen, 1);
        let pred = p.percepts(0)[sm[Category::Predator as usize].nearest.unwrap() as usize];
        assert!((pred.bearing - std::f32::consts::FRAC_PI_4).abs() < 1e-5);
        assert_eq!(pred.sector(), Sector::RightFront);
        assert!((pred.dist - 50f32.sqrt()).abs() < 1e-5);
        assert_eq!(sm[Category::Kin as usize].count, 1);
        assert_eq!(
            sm[Category::Kin as usize].seen,
            0,
            "behind is the blind spot"
        );
        assert_eq!(sm[Category::Food as usize].count, 1);
        assert_eq!(sm[Category::Food as usize].seen, 0);
        assert_eq!(sm[Category::Food as usize].nearest_dist, 15.0);
        // The predator perceives both fish as food (one seen, one smelt at 11.2).
        assert_eq!(
            p.summaries(1)[Category::Food as usize].count,
            2,
            "both fish"
        );
    }

    /// Seed 001's "visible if any part is in the field" (`Extent::AnyPart`) against the centre
    /// test: a cone of ±60°, vision 10, no smell.
    #[test]
    fn any_part_in_the_field_is_enough_with_any_part() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        // A predator 6 away, 70° to the right of the heading (right is −X), of size 4 × 4 × 4:
        // r = 2√3 = 3.464, asin(3.464/6) = 35.3°, 70 − 35.3 = 34.7 ≤ 60.
        let a = 70f32.to_radians();
        let mut big = agent(1, 1, Vec3::new(-a.sin(), 0.0, a.cos()) * 6.0, 0.0);
        big.size = Vec3::splat(4.0);
        w.agents.push(big);
        // A second one 13 straight ahead: 13 − 3.464 = 9.54 ≤ 10.
        let mut far = agent(2, 1, Vec3::new(0.0, 0.0, 13.0), 0.0);
        far.size = Vec3::splat(4.0);
        w.agents.push(far);
        // A rock of radius 3 centred 7 away, 80° to the left: its nearest point is 80° off too,
        // but asin(3/7) = 25.4°, 80 − 25.4 = 54.6 ≤ 60.
        let b = 80f32.to_radians();
        w.add_obstacle(Shape::Sphere {
            center: Vec3::new(b.sin(), 0.0, b.cos()) * 7.0,
            radius: 3.0,
        });
        // Food (no body) 11 ahead: out of range either way.
        w.add_food(Vec3::new(0.0, 0.0, 11.0));
        let sense = SenseParams {
            vision_radius: 10.0,
            vision_half_angle: 60f32.to_radians(),
            smell_radius: 0.0,
            occlusion: false,
            ..SenseParams::default()
        };
        let centre = run(&w, &rel(), sense);
        let sm = centre.summaries(0);
        assert_eq!(sm[Category::Predator as usize].count, 0);
        assert_eq!(sm[Category::Obstacle as usize].count, 0);
        let any = run(
            &w,
            &rel(),
            SenseParams {
                extent: Extent::AnyPart,
                ..sense
            },
        );
        let sm = any.summaries(0);
        assert_eq!(sm[Category::Predator as usize].count, 2);
        assert_eq!(sm[Category::Predator as usize].seen, 2);
        assert_eq!(sm[Category::Obstacle as usize].seen, 1);
        assert_eq!(sm[Category::Food as usize].count, 0);
        // Smaller bodies (size 1 × 1 × 1, r = 0.866) stay unseen: 70 − 8.3 > 60, 13 − 0.87 > 10.
        w.agents[1].size = Vec3::ONE;
        w.agents[2].size = Vec3::ONE;
        let any = run(
            &w,
            &rel(),
            SenseParams {
                extent: Extent::AnyPart,
                ..sense
            },
        );
        assert_eq!(any.summaries(0)[Category::Predator as usize].count, 0);
    }

    #[test]
    fn obstacles_occlude_what_is_behind_them() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        w.add_food(Vec3::new(0.0, 0.0, 8.0));
        w.add_obstacle(Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 4.0),
            radius: 1.0,
        });
        let p = run(&w, &rel(), SenseParams::default());
        let sm = p.summaries(0);
        assert_eq!(sm[Category::Food as usize].count, 1);
        assert_eq!(
            sm[Category::Food as usize].seen,
            0,
            "hidden by the rock, still smelt"
        );
        assert_eq!(sm[Category::Obstacle as usize].count, 1);
        assert!((sm[Category::Obstacle as usize].nearest_dist - 3.0).abs() < 1e-6);
    }

    /// A reef fish at (0, 0, −3) heading +z, 3 in front of a 12 × 2 × 6 box (x −6..6, y −1..1,
    /// z 2..8; centre (0, 0, 5), bounding radius √184/2 = 6.78: the fish is 8 from its centre,
    /// outside it), with vision 20 and smell 30.
    fn beside_a_box() -> (World, SenseParams) {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::new(0.0, 0.0, -3.0), 0.0));
        w.add_obstacle(Shape::Box(Aabb::new(
            Vec3::new(-6.0, -1.0, 2.0),
            Vec3::new(6.0, 1.0, 8.0),
        )));
        let sense = SenseParams {
            vision_radius: 20.0,
            smell_radius: 30.0,
            ..SenseParams::default()
        };
        (w, sense)
    }

    #[test]
    fn a_shark_above_a_box_is_seen_past_its_real_shape() {
        let (mut w, sense) = beside_a_box();
        // The shark at (0, 4, 12): the line of sight rises 4 over 15, at the box's front face
        // (z = 2, 5 along) it is 4·5/15 = 1.33 high, above the top (1); it passes the box's
        // centre at 8·4/√241 = 2.06 (< 6.78) and the shark is √(16 + 49) = 8.06 from that
        // centre (> 6.78): the bounding sphere would hide it.
        w.agents.push(agent(1, 1, Vec3::new(0.0, 4.0, 12.0), 0.0));
        let p = run(&w, &rel(), sense);
        let pred = p.summaries(0)[Category::Predator as usize];
        assert_eq!((pred.count, pred.seen), (1, 1), "seen above the box");
        // The box itself: 5 ahead (front face at z = 2).
        let obs = p.summaries(0)[Category::Obstacle as usize];
        assert!((obs.nearest_dist - 5.0).abs() < 1e-6);
        // The paper's form: the bounding sphere hides it (still smelt at 15.5 < 30).
        let paper = SenseParams {
            occluders: Occluders::BoundingSphere,
            ..sense
        };
        let p = run(&w, &rel(), paper);
        let pred = p.summaries(0)[Category::Predator as usize];
        assert_eq!(
            (pred.count, pred.seen),
            (1, 0),
            "the bounding sphere hides it"
        );
        // Occlusion off: seen either way.
        let off = SenseParams {
            occlusion: false,
            ..paper
        };
        let pred = run(&w, &rel(), off).summaries(0)[Category::Predator as usize];
        assert_eq!((pred.count, pred.seen), (1, 1));
    }

    #[test]
    fn a_fish_behind_the_box_is_hidden_by_its_real_shape() {
        let (mut w, sense) = beside_a_box();
        // Kin at (0, 0, 12): the line of sight runs through the box along its axis; the outline
        // points (0.53 across: size 0.2 × 0.3 × 1, diagonal 1.06) do too.
        w.agents.push(agent(1, 0, Vec3::new(0.0, 0.0, 12.0), 0.0));
        let kin = run(&w, &rel(), sense).summaries(0)[Category::Kin as usize];
        assert_eq!((kin.count, kin.seen), (1, 0), "behind the box: smelt only");
    }

    #[test]
    fn a_target_behind_a_rock_is_hidden_unless_it_sticks_out() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        // A rock of radius 1 at z = 4; a predator at z = 8, radius 0.53: its outline points'
        // lines of sight pass the rock's centre at 4·0.53/8 ≈ 0.27 (< 1): hidden.
        w.add_obstacle(Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 4.0),
            radius: 1.0,
        });
        w.agents.push(agent(1, 1, Vec3::new(0.0, 0.0, 8.0), 0.0));
        let pred =
            run(&w, &rel(), SenseParams::default()).summaries(0)[Category::Predator as usize];
        assert_eq!((pred.count, pred.seen), (1, 0), "hidden by the rock");
        // A big one there (size 4 × 4 × 4: radius 2√3 = 3.46) sticks out: its outline points'
        // lines of sight pass the rock's centre at about 4·3.46/√(64 + 12) = 1.59 (> 1).
        w.agents[1].size = Vec3::splat(4.0);
        let pred =
            run(&w, &rel(), SenseParams::default()).summaries(0)[Category::Predator as usize];
        assert_eq!((pred.count, pred.seen), (1, 1), "partly in view");
    }

    #[test]
    fn a_cylinder_is_perceived_at_its_surface_and_occludes() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        // A pillar of radius 1 around (0, ·, 4), from y = −5 to 5: its surface 3 ahead.
        w.add_obstacle(Shape::Cylinder {
            base: Vec3::new(0.0, -5.0, 4.0),
            radius: 1.0,
            height: 10.0,
        });
        w.add_food(Vec3::new(0.0, 0.0, 8.0));
        // Higher, at y = 6: the line of sight crosses the axis 3 high, below the top (5): hidden.
        w.add_food(Vec3::new(0.0, 6.0, 8.0));
        // Beside it (x = 3 at z = 8: 1.5 off the axis at z = 4): seen.
        w.add_food(Vec3::new(3.0, 0.0, 8.0));
        let p = run(&w, &rel(), SenseParams::default());
        let sm = p.summaries(0);
        let obs = sm[Category::Obstacle as usize];
        assert!((obs.nearest_dist - 3.0).abs() < 1e-6);
        let food = sm[Category::Food as usize];
        assert_eq!((food.count, food.seen), (3, 1));
    }

    #[test]
    fn custom_volume_replaces_the_vision_sphere() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        w.agents.push(agent(1, 0, Vec3::new(0.0, 0.0, 14.0), 0.0)); // ahead, inside the egg
        w.agents.push(agent(2, 0, Vec3::new(0.0, 0.0, -4.0), 0.0)); // behind, outside
        let sense = SenseParams {
            volume: Some(Volume::Egg {
                ahead: 15.0,
                behind: 3.0,
                side: 5.0,
                up: 5.0,
            }),
            smell_radius: 0.0,
            ..Default::default()
        };
        let p = run(&w, &rel(), sense);
        let sm = p.summaries(0)[Category::Kin as usize];
        assert_eq!((sm.count, sm.seen), (1, 1));
    }

    #[test]
    fn injected_percepts_replace_an_agents_and_rebuild_its_summaries() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        w.add_food(Vec3::new(0.0, 0.0, 3.0));
        let mut p = run(&w, &rel(), SenseParams::default());
        assert_eq!(p.summaries(0)[Category::Food as usize].count, 1);
        let fed = |category, sense, offset: Vec3| Percept {
            source: Source::Injected,
            category,
            sense,
            offset,
            dist: offset.length(),
            bearing: 0.0,
            elevation: 0.0,
            size: 1.0,
        };
        p.inject(
            0,
            Vec3::new(1.0, 0.0, 0.0),
            &[
                fed(Category::Predator, Sense::Smell, Vec3::new(0.0, 0.0, 12.0)),
                fed(Category::Mate, Sense::Vision, Vec3::new(0.0, 0.0, 2.0)),
                fed(Category::Kin, Sense::Vision, Vec3::new(0.0, 0.0, 4.0)),
            ],
        );
        let sm = p.summaries(0);
        assert_eq!(p.percepts(0).len(), 3);
        assert_eq!(
            sm[Category::Food as usize].count,
            0,
            "the real food is gone"
        );
        let pred = sm[Category::Predator as usize];
        assert_eq!((pred.count, pred.seen, pred.nearest_dist), (1, 0, 12.0));
        // A mate also counts as kin, as perception does it.
        let kin = sm[Category::Kin as usize];
        assert_eq!((kin.count, kin.seen, kin.nearest_dist), (2, 2, 2.0));
        assert_eq!(kin.nearest, Some(1));
        assert_eq!(kin.centroid, Vec3::new(1.0, 0.0, 3.0));
    }

    #[test]
    fn keeps_the_nearest_when_crowded_but_counts_all() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        for k in 0..40 {
            w.agents.push(agent(
                k + 1,
                0,
                Vec3::new(0.0, 0.0, 0.2 + k as f32 * 0.2),
                0.0,
            ));
        }
        let p = run(&w, &rel(), SenseParams::default());
        assert_eq!(p.percepts(0).len(), DEFAULT_PERCEPTS);
        assert_eq!(p.summaries(0)[Category::Kin as usize].count, 40);
        let maxd = p.percepts(0).iter().map(|q| q.dist).fold(0.0, f32::max);
        assert!((maxd - 0.2 * DEFAULT_PERCEPTS as f32).abs() < 1e-4);
        // A species may keep more.
        let more = SenseParams {
            max_percepts: 20,
            ..SenseParams::default()
        };
        assert_eq!(run(&w, &rel(), more).percepts(0).len(), 20);
    }

    #[test]
    fn the_nearest_of_each_category_survives_a_crowd() {
        // 30 kin within 6 m, then food at 7 m and a predator at 8 m: the 16 slots would hold
        // only kin by distance, but the nearest food and predator replace the farthest kin.
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 2);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        for k in 0..30 {
            w.agents.push(agent(
                k + 1,
                0,
                Vec3::new(0.0, 0.0, 0.2 * (k + 1) as f32),
                0.0,
            ));
        }
        w.agents.push(agent(31, 1, Vec3::new(0.0, 0.0, 8.0), 0.0));
        w.add_food(Vec3::new(0.0, 0.0, 7.0));
        let p = run(&w, &rel(), SenseParams::default());
        let kept = p.percepts(0);
        assert_eq!(kept.len(), DEFAULT_PERCEPTS);
        let sm = p.summaries(0);
        for (c, d) in [
            (Category::Food, 7.0),
            (Category::Predator, 8.0),
            (Category::Kin, 0.2),
        ] {
            let near = &kept[sm[c as usize].nearest.expect("kept") as usize];
            assert_eq!(near.category, c);
            assert!((near.dist - d).abs() < 1e-5, "{c:?} {}", near.dist);
        }
        // They took the places of the two farthest kin: the nearest 14 kin stay (0.2 … 2.8 m).
        let far_kin = kept
            .iter()
            .filter(|q| q.category == Category::Kin)
            .map(|q| q.dist)
            .fold(0.0, f32::max);
        assert!((far_kin - 2.8).abs() < 1e-5, "{far_kin}");
        assert_eq!(
            kept.iter().filter(|q| q.category == Category::Kin).count(),
            14
        );
    }

    #[test]
    fn group_sums_cover_every_kin_perceived_and_need_no_slots() {
        // 40 kin around the perceiver, a predator among them; a species reading only group
        // rules keeps no percept, and its sums are those of the whole neighbor list.
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 3);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        let mut rng = Rng::new(4, 0);
        for k in 0..40 {
            let pos = random_point(&mut rng, 6.0);
            let mut a = agent(k + 1, 0, pos, rng.range(-3.0, 3.0));
            a.speed = rng.range(0.0, 2.0);
            w.agents.push(a);
        }
        w.agents.push(agent(41, 1, Vec3::new(1.0, 0.0, 0.0), 0.0));
        let sense = SenseParams {
            vision_half_angle: std::f32::consts::PI,
            ..SenseParams::default()
        };
        let mut groups = GroupQueries::new();
        let queries = [
            GroupQuery::Separation { radius: 3.0 },
            GroupQuery::Mean { radius: 5.0 },
            GroupQuery::Zones {
                repulsion: 1.0,
                matching: 3.0,
                attraction: 6.0,
                soft: 0.5,
            },
            GroupQuery::Headings { radius: 4.0 },
        ];
        for q in queries {
            groups.insert(q);
        }
        let reads = Reads {
            percepts: false,
            agent_percepts: false,
            bearing_range: Some(0.0),
            groups,
            headings: true,
        };
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 3.0, w.agents.iter().map(|a| a.pos));
        let mut p = Perception::new();
        p.run_selective(
            &w,
            &ag,
            &Grid::new(),
            &[sense, sense],
            &rel(),
            &[reads, reads],
        );
        assert!(p.percepts(0).is_empty());
        assert_eq!(p.summaries(0)[Category::Kin as usize].count, 40);
        // The same sums from the full neighbor list, in the index's order.
        let mut neighbors = Vec::new();
        ag.for_each_within(Vec3::ZERO, sense.query_radius(), |j, pos, d2| {
            if j != 0 && j != 41 {
                let a = &w.agents[j as usize];
                neighbors.push(crate::steering::group::Neighbor {
                    offset: pos,
                    dist: d2.sqrt(),
                    velocity: a.velocity(),
                });
            }
        });
        assert_eq!(neighbors.len(), 40);
        for (k, q) in queries.iter().enumerate() {
            let want = crate::steering::group::fold(&neighbors, q);
            assert_eq!(p.group_sums(0)[k], want, "{q:?}");
            assert!(want.n + want.m > 0, "{q:?} sums something");
        }
    }
    #[test]
    fn injected_percepts_keep_the_nearest_of_each_category() {
        // Ten kin fed within 3 m and a predator at 9 m to an agent keeping 8 percepts: like
        // perception, the predator (the only one of its category) must stay among the kept.
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        let sense = SenseParams {
            max_percepts: 8,
            ..SenseParams::default()
        };
        let mut p = run(&w, &rel(), sense);
        let fed = |category, offset: Vec3| Percept {
            source: Source::Injected,
            category,
            sense: Sense::Vision,
            offset,
            dist: offset.length(),
            bearing: 0.0,
            elevation: 0.0,
            size: 1.0,
        };
        let mut feed: Vec<Percept> = (0..10)
            .map(|k| fed(Category::Kin, Vec3::new(0.0, 0.0, 0.3 * (k + 1) as f32)))
            .collect();
        feed.push(fed(Category::Predator, Vec3::new(0.0, 0.0, 9.0)));
        p.inject(0, Vec3::ZERO, &feed);
        let sm = p.summaries(0);
        assert_eq!(sm[Category::Predator as usize].count, 1);
        assert_eq!(p.percepts(0).len(), 8);
        let k = sm[Category::Predator as usize]
            .nearest
            .expect("the predator is kept") as usize;
        assert_eq!(p.percepts(0)[k].category, Category::Predator);
        let kin = sm[Category::Kin as usize].nearest.expect("kin kept") as usize;
        assert!((p.percepts(0)[kin].dist - 0.3).abs() < 1e-6);
    }

    #[test]
    fn injecting_into_an_agent_without_slots_does_not_panic() {
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 5.0, w.agents.iter().map(|a| a.pos));
        let reads = Reads {
            percepts: false,
            ..Reads::default()
        };
        let mut p = Perception::new();
        let sense = SenseParams::default();
        p.run_selective(
            &w,
            &ag,
            &Grid::new(),
            &[sense, sense],
            &rel(),
            &[reads, reads],
        );
        let fed = Percept {
            source: Source::Injected,
            category: Category::Food,
            sense: Sense::Vision,
            offset: Vec3::Z,
            dist: 1.0,
            bearing: 0.0,
            elevation: 0.0,
            size: 0.0,
        };
        p.inject(0, Vec3::ZERO, &[fed]);
        assert!(p.percepts(0).is_empty());
        let food = p.summaries(0)[Category::Food as usize];
        assert_eq!((food.count, food.nearest), (1, None));
    }

    #[test]
    fn a_reused_buffer_holds_no_summary_of_a_rock_that_is_gone() {
        // Agents near a rock take the general path and summarize it; once the rock is removed
        // they take the kin kernel, which rewrites only the kin summary of a row it cleared
        // itself: the rock's summary must be gone, as in a fresh perception, whatever path
        // each row took the tick before.
        let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 1);
        let mut rng = Rng::new(3, 0);
        for k in 0..200 {
            let pos = random_point(&mut rng, 10.0);
            w.agents.push(agent(k, 0, pos, rng.range(-3.0, 3.0)));
        }
        w.add_obstacle(Shape::Sphere {
            center: Vec3::ZERO,
            radius: 2.0,
        });
        let mut groups = GroupQueries::new();
        groups.insert(GroupQuery::Separation { radius: 2.0 });
        let reads = Reads {
            percepts: false,
            agent_percepts: false,
            bearing_range: Some(0.0),
            groups,
            headings: false,
        };
        let sense = SenseParams {
            vision_radius: 5.0,
            vision_half_angle: std::f32::consts::PI,
            smell_radius: 0.0,
            occlusion: false,
            ..SenseParams::default()
        };
        let mut rel = Relations::new(1);
        rel.set(0, 0, Some(Category::Kin));
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 5.0, w.agents.iter().map(|a| a.pos));
        let run = |p: &mut Perception, w: &World| {
            p.run_selective(w, &ag, &Grid::new(), &[sense], &rel, &[reads]);
        };
        // Without the rock (the kernel clears every row and flags it), with it (the general
        // path must unflag the rows it writes), then twice without it again.
        let mut reused = Perception::new();
        for active in [false, true, false, false] {
            w.obstacles[0].active = active;
            run(&mut reused, &w);
            let mut fresh = Perception::new();
            run(&mut fresh, &w);
            for i in 0..w.agents.len() {
                assert_eq!(reused.summaries(i), fresh.summaries(i), "agent {i}");
            }
            let near_rock = (0..w.agents.len())
                .filter(|&i| reused.summaries(i)[Category::Obstacle as usize].count > 0)
                .count();
            if active {
                assert!(near_rock > 10, "{near_rock} agents see the rock");
            } else {
                assert_eq!(near_rock, 0);
            }
        }
    }

    #[test]
    fn the_kin_kernel_perceives_what_the_general_path_does() {
        // A world of one kin-only species without slots is perceived by the kin kernel; naming
        // a second species (with no agent) as `Other` sends it down the general path. Same
        // neighbors, same counts; the sums differ by rounding only.
        let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 2);
        let mut rng = Rng::new(7, 0);
        for k in 0..400 {
            let pos = random_point(&mut rng, 15.0);
            let mut a = agent(k, 0, pos, rng.range(-3.0, 3.0));
            a.pitch = rng.range(-0.5, 0.5);
            a.speed = rng.range(0.0, 2.0);
            w.agents.push(a);
        }
        // Agents near the rock perceive it too (the kernel then runs inside the general
        // fold); the others take the kernel alone.
        w.add_obstacle(Shape::Sphere {
            center: Vec3::new(8.0, 8.0, 8.0),
            radius: 2.0,
        });
        let mut groups = GroupQueries::new();
        groups.insert(GroupQuery::Separation { radius: 2.0 });
        groups.insert(GroupQuery::Mean { radius: 3.0 });
        let reads = Reads {
            percepts: false,
            agent_percepts: false,
            bearing_range: Some(0.0),
            groups,
            headings: true,
        };
        let whole = SenseParams {
            vision_radius: 5.0,
            vision_half_angle: std::f32::consts::PI,
            smell_radius: 0.0,
            occlusion: false,
            ..SenseParams::default()
        };
        let cone_and_smell = SenseParams {
            vision_radius: 5.0,
            vision_half_angle: 2.0,
            smell_radius: 3.5,
            ..whole
        };
        for sense in [whole, cone_and_smell] {
            let mut ag = Grid::new();
            ag.rebuild(w.bounds, 2.5, w.agents.iter().map(|a| a.pos));
            let perceive = |rel: &Relations| {
                let mut p = Perception::new();
                p.run_selective(&w, &ag, &Grid::new(), &[sense; 2], rel, &[reads; 2]);
                p
            };
            let mut kernel = Relations::new(2);
            kernel.set(0, 0, Some(Category::Kin));
            kernel.set(0, 1, Some(Category::Kin));
            let mut general = kernel.clone();
            general.set(0, 1, Some(Category::Other));
            let (a, b) = (perceive(&kernel), perceive(&general));
            let close = |x: Vec3, y: Vec3| (x - y).length() <= 1e-4 * (1.0 + y.length());
            let mut perceived = 0;
            for i in 0..w.agents.len() {
                let (ka, kb) = (
                    &a.summaries(i)[Category::Kin as usize],
                    &b.summaries(i)[Category::Kin as usize],
                );
                assert_eq!((ka.count, ka.seen), (kb.count, kb.seen), "agent {i}");
                perceived += ka.count;
                assert!((ka.nearest_dist - kb.nearest_dist).abs() <= 1e-5 || ka.count == 0);
                assert!(close(ka.centroid, kb.centroid), "agent {i}");
                assert!(close(ka.mean_heading, kb.mean_heading), "agent {i}");
                assert!(close(ka.mean_velocity, kb.mean_velocity), "agent {i}");
                for (ga, gb) in a.group_sums(i).iter().zip(b.group_sums(i)) {
                    assert_eq!(ga.n, gb.n, "agent {i}");
                    assert!(close(ga.a.into(), gb.a.into()), "agent {i}");
                    assert!(close(ga.b.into(), gb.b.into()), "agent {i}");
                }
            }
            assert!(perceived > 400, "{perceived}");
            let near_rock = (0..w.agents.len())
                .filter(|&i| a.summaries(i)[Category::Obstacle as usize].count > 0)
                .count();
            assert!(near_rock > 0 && near_rock < w.agents.len(), "{near_rock}");
        }
    }

    #[test]
    fn the_plain_path_matches_the_general_one() {
        // A kin-only perceiver without slots takes the plain path; naming a third species (with
        // no agent) as `Other` sends it down the general path: the results must be the same.
        let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 3);
        let mut rng = Rng::new(5, 0);
        for k in 0..300 {
            let pos = random_point(&mut rng, 15.0);
            let mut a = agent(k, 0, pos, rng.range(-3.0, 3.0));
            a.pitch = rng.range(-0.5, 0.5);
            a.speed = rng.range(0.0, 2.0);
            w.agents.push(a);
        }
        let sense = SenseParams {
            smell_radius: 6.0,
            vision_radius: 4.0,
            occlusion: false,
            ..SenseParams::default()
        };
        let mut groups = GroupQueries::new();
        groups.insert(GroupQuery::Separation { radius: 2.0 });
        groups.insert(GroupQuery::Mean { radius: 3.0 });
        groups.insert(GroupQuery::Headings { radius: 3.0 });
        let reads = Reads {
            percepts: false,
            agent_percepts: false,
            bearing_range: Some(0.0),
            groups,
            headings: true,
        };
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 3.0, w.agents.iter().map(|a| a.pos));
        let perceive = |rel: &Relations| {
            let mut p = Perception::new();
            p.run_selective(&w, &ag, &Grid::new(), &[sense; 3], rel, &[reads; 3]);
            p
        };
        let mut plain = Relations::new(3);
        plain.set(0, 0, Some(Category::Kin));
        let mut general = plain.clone();
        general.set(0, 2, Some(Category::Other));
        let (a, b) = (perceive(&plain), perceive(&general));
        for i in 0..w.agents.len() {
            assert_eq!(a.summaries(i), b.summaries(i), "agent {i}");
            assert_eq!(a.group_sums(i), b.group_sums(i), "agent {i}");
        }
        assert!(a.summaries(0)[Category::Kin as usize].count > 0);
    }
    #[test]
    fn the_grid_order_walk_perceives_what_the_agent_order_walk_does() {
        // Fish (with mates, food, rocks and a predator) take the general path, which walks the
        // perceivers in the grid's order. A grid with one entry beyond the agents makes the same
        // perception walk in agent order: every agent's results must be the same, bit for bit.
        let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 1);
        let mut rng = Rng::new(9, 0);
        let point = |rng: &mut Rng| random_point(rng, 18.0);
        for k in 0..400 {
            let species = u16::from(k % 40 == 0);
            let mut a = agent(k, species, point(&mut rng), rng.range(-3.0, 3.0));
            a.pitch = rng.range(-0.5, 0.5);
            a.speed = rng.range(0.0, 2.0);
            if k % 2 == 1 {
                a.attrs.sex = crate::world::Sex::Male;
            }
            w.agents.push(a);
        }
        for _ in 0..60 {
            let p = point(&mut rng);
            w.add_food(p);
        }
        for id in 0..6 {
            w.obstacles.push(crate::world::Obstacle {
                id,
                shape: Shape::Sphere {
                    center: point(&mut rng),
                    radius: 1.5,
                },
                active: true,
            });
        }
        let sense = SenseParams {
            smell_radius: 6.0,
            vision_radius: 4.0,
            max_percepts: 8,
            ..SenseParams::default()
        };
        let mut rel = rel();
        rel.set_mates(0, true);
        let mut groups = GroupQueries::new();
        groups.insert(GroupQuery::Separation { radius: 2.0 });
        groups.insert(GroupQuery::Mean { radius: 3.0 });
        let reads = Reads {
            groups,
            ..Reads::default()
        };
        let mut fg = Grid::new();
        fg.rebuild(w.bounds, 6.0, w.food.iter().map(|f| f.pos));
        let perceive = |extra: Option<Vec3>| {
            let mut ag = Grid::new();
            let points: Vec<Vec3> = w.agents.iter().map(|a| a.pos).chain(extra).collect();
            ag.rebuild(w.bounds, 6.0, points.into_iter());
            let mut p = Perception::new();
            p.run_selective(&w, &ag, &fg, &[sense; 2], &rel, &[reads; 2]);
            p
        };
        let (by_grid, by_agent) = (perceive(None), perceive(Some(Vec3::splat(19.0))));
        let n = w.agents.len();
        assert!(by_grid.by_grid, "walked in the grid's order");
        assert_ne!(by_grid.slot_of, (0..n as u32).collect::<Vec<_>>());
        assert!(!by_agent.by_grid, "walked in agent order");
        let mut kept = 0;
        for i in 0..n {
            assert_eq!(by_grid.percepts(i), by_agent.percepts(i), "agent {i}");
            assert_eq!(by_grid.summaries(i), by_agent.summaries(i), "agent {i}");
            assert_eq!(by_grid.group_sums(i), by_agent.group_sums(i), "agent {i}");
            kept += by_grid.percepts(i).len();
        }
        assert!(kept > n, "most fish keep percepts");
        // Fed percepts land on the agent they are for, whatever its row.
        let mut fed = by_grid.clone();
        let p = by_grid.percepts(7)[0];
        fed.inject(3, w.agents[3].pos, &[p]);
        assert_eq!(fed.percepts(3), &[p]);
        for i in (0..n).filter(|&i| i != 3) {
            assert_eq!(fed.percepts(i), by_grid.percepts(i), "agent {i}");
        }
    }

    #[test]
    fn few_slots_still_keep_the_nearest_of_each_category() {
        // A kin at 1 m, the shark at 5 m and food at 6 m: however few percepts a species asks
        // for, the predator and the food must not be hidden by the kin in front of them.
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        w.agents.push(agent(1, 0, Vec3::new(0.0, 0.0, 1.0), 0.0));
        w.agents.push(agent(2, 1, Vec3::new(0.0, 0.0, 5.0), 0.0));
        w.add_food(Vec3::new(0.0, 0.0, 6.0));
        for max_percepts in [1, 2] {
            let sense = SenseParams {
                max_percepts,
                ..SenseParams::default()
            };
            let p = run(&w, &rel(), sense);
            let sm = p.summaries(0);
            for c in [Category::Kin, Category::Predator, Category::Food] {
                assert_eq!(sm[c as usize].count, 1);
                let k = sm[c as usize]
                    .nearest
                    .unwrap_or_else(|| panic!("{c:?} kept with {max_percepts} slots"));
                assert_eq!(p.percepts(0)[k as usize].category, c);
            }
        }
    }

    #[test]
    fn a_species_reading_obstacles_only_keeps_no_agent_percept() {
        // Kin all around and a rock ahead: only the rock is kept; kin are summed, not kept, and
        // no empty record stands in for them.
        let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
        w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
        for k in 0..12 {
            w.agents.push(agent(
                k + 1,
                0,
                Vec3::new(0.5 * k as f32 - 3.0, 0.0, 1.0),
                0.0,
            ));
        }
        w.add_obstacle(Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 6.0),
            radius: 1.0,
        });
        let reads = Reads {
            agent_percepts: false,
            ..Reads::default()
        };
        let sense = SenseParams {
            occlusion: false,
            ..SenseParams::default()
        };
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 5.0, w.agents.iter().map(|a| a.pos));
        let mut p = Perception::new();
        p.run_selective(
            &w,
            &ag,
            &Grid::new(),
            &[sense, sense],
            &rel(),
            &[reads, reads],
        );
        let kept = p.percepts(0);
        assert_eq!(kept.len(), 1, "{kept:?}");
        assert_eq!(kept[0].source, Source::Obstacle(0));
        let sm = p.summaries(0);
        assert_eq!(sm[Category::Kin as usize].count, 12);
        assert_eq!(sm[Category::Kin as usize].nearest, None);
        assert_eq!(sm[Category::Obstacle as usize].nearest, Some(0));
    }
}
