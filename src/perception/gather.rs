//! The per-tick copy of what perceivers read of each other (stage 2): every agent's record read
//! once, in agent order, into a small [`Gathered`] record, then copied into the agent grid's
//! order (headings and speeds, species and sex, sizes), so that a neighbor costs one small
//! sequential read. Also sizes each agent's share of the output rows. Reads the world and the
//! agent grid; writes only the stage's own buffers.

use super::eye::{cos_min, full_circle};
use super::kin;
use super::rows::RowMask;
use super::walk::kernel_species;
use super::{Perception, Reads, Relations, SenseParams};
use crate::index::Grid;
use crate::world::{Agent, World};
use glam::Vec3;
use rayon::prelude::*;

/// What others read of an agent at the start of the tick (24 bytes: its position a tick
/// before is held apart, only where some species reads it).
#[derive(Debug, Clone, Copy)]
pub(super) struct Gathered {
    pub(super) body: Body,
    pub(super) tag: Tag,
    pub(super) diagonal: f32,
}

/// What a perceiver reads of itself.
#[derive(Debug, Clone, Copy)]
pub(super) struct Me {
    pub(super) pos: Vec3,
    pub(super) yaw: f32,
    /// Forward unit vector.
    pub(super) heading: Vec3,
    pub(super) tag: Tag,
}

/// The part of an agent its neighbors read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Body {
    /// Forward unit vector.
    pub(super) heading: Vec3,
    /// Speed (`heading * speed` is `Agent::velocity`, bit for bit).
    pub(super) speed: f32,
}

impl Body {
    #[inline(always)]
    pub(super) fn velocity(&self) -> Vec3 {
        self.heading * self.speed
    }
}

/// Who an agent is, as its neighbors' relations see it (kept apart from [`Body`]: every
/// candidate's is read, only those perceived have their body read).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Tag {
    pub(super) species: u16,
    pub(super) sex: crate::world::Sex,
}

impl Default for Body {
    fn default() -> Self {
        Body {
            heading: Vec3::ZERO,
            speed: 0.0,
        }
    }
}

/// What stands in for an agent the grid lacks.
const UNKNOWN: Gathered = Gathered {
    body: Body {
        heading: Vec3::ZERO,
        speed: 0.0,
    },
    tag: Tag {
        species: u16::MAX,
        sex: crate::world::Sex::Female,
    },
    diagonal: 0.0,
};

impl Perception {
    /// Gathers, for this tick, what perceivers read of each other (see [`Gathered`]) and
    /// sizes every agent's share of the output rows; decides the walk's order (`by_grid`) and
    /// which species may perceive by the kin kernel (`kernel`). Returns whether some agent's
    /// species has no senses (it then perceives with the defaults).
    pub(super) fn gather(
        &mut self,
        world: &World,
        agents: &Grid,
        senses: &[SenseParams],
        relations: &Relations,
        reads: &[Reads],
    ) -> bool {
        let n = world.agents.len();
        let default = SenseParams::default();
        let everything = Reads::default();
        let unsensed = std::sync::atomic::AtomicBool::new(false);
        let entries = agents.entries();
        // Species that may perceive by the kin kernel.
        self.kernel.clear();
        self.kernel
            .extend((0..senses.len().max(reads.len())).map(|s| {
                let r = reads.get(s).unwrap_or(&everything);
                kernel_species(s, senses.get(s).unwrap_or(&default), r, relations)
            }));
        let kernel = self.kernel.iter().any(|&k| k);
        // Each species' group queries: how its rows' sums are laid out and read back.
        self.queries.clear();
        self.queries.extend(reads.iter().map(|r| r.groups));
        // The categories each species' rows hold (a species beyond these, all of them).
        let obstacles = !world.obstacles.is_empty();
        self.species_masks.clear();
        self.species_masks
            .extend(self.kernel.iter().enumerate().map(|(s, &k)| {
                if self.full_rows {
                    RowMask::ALL
                } else {
                    RowMask::of(s, relations, obstacles, k)
                }
            }));
        let masks = &self.species_masks;
        // Each agent's share of the output buffers (by its species).
        let share = |s: usize| {
            let r = reads.get(s).unwrap_or(&everything);
            let slots = if r.percepts {
                senses.get(s).unwrap_or(&default).slots() as u8
            } else {
                0
            };
            (slots, r.groups.iter().map(|q| q.words() as u32).sum())
        };
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
        self.gathered.resize(n, UNKNOWN);
        self.rooms.resize(n, 0);
        self.sum_starts.resize(n + 1, 0);
        self.row_masks.resize(n, RowMask::ALL);
        // Positions a tick before, only where some species keeps agent percepts: a pursuer
        // reads its target's, and nothing else does (12 bytes an agent otherwise).
        let keeps_agents = |r: &Reads| r.percepts && r.agent_percepts;
        let prev = reads.len() < senses.len() || reads.iter().any(keeps_agents);
        let gather = |a: &Agent, g: &mut Gathered, slots: &mut u8, sums: &mut u32| {
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
            };
        };
        let pass = world
            .agents
            .par_iter()
            .zip(self.gathered[..n].par_iter_mut())
            .zip(self.rooms[..n].par_iter_mut())
            .zip(self.sum_starts[..n].par_iter_mut());
        if prev {
            self.prev_pos.resize(n, Vec3::ZERO);
            pass.zip(self.prev_pos[..n].par_iter_mut())
                .with_min_len(crate::par::min_len(256))
                .for_each(|((((a, g), slots), sums), p)| {
                    gather(a, g, slots, sums);
                    *p = a.prev_pos;
                });
        } else {
            pass.with_min_len(crate::par::min_len(256))
                .for_each(|(((a, g), slots), sums)| gather(a, g, slots, sums));
        }
        let unsensed = unsensed.into_inner();
        // A species without reads or senses reads everything (`Reads::default`).
        let reads_all = unsensed || reads.len() < senses.len();
        // Mean headings are kept where some species reads them.
        self.keep_headings = self.full_rows || reads_all || reads.iter().any(|r| r.headings);
        if !prev {
            // An agent of a species without senses perceives with the defaults, which keep
            // agent percepts (rare: a second, sequential pass).
            self.prev_pos = if unsensed {
                world.agents.iter().map(|a| a.prev_pos).collect()
            } else {
                Vec::new()
            };
        }
        self.by_grid = by_grid;
        // What kept percepts are read back with (`Perception::percepts_in`).
        self.fed.clear();
        self.bearing_ranges.clear();
        self.bearing_ranges.extend(
            (0..senses.len().max(reads.len()))
                .map(|s| reads.get(s).unwrap_or(&everything).bearing_range),
        );
        self.obstacle_sizes.clear();
        self.obstacle_sizes
            .extend(world.obstacles.iter().map(|o| o.shape.diagonal()));
        let keeps_percepts = reads_all || (0..senses.len()).any(|s| share(s).0 > 0);
        self.angles.clear();
        if !by_grid && keeps_percepts {
            // In agent order, each row's heading angles, only for the bearings of its percepts.
            self.angles.resize(n, [0.0; 2]);
            self.angles
                .par_iter_mut()
                .zip(world.agents.par_iter())
                .with_min_len(crate::par::min_len(1024))
                .for_each(|(angles, a)| *angles = [a.yaw, a.pitch]);
        }
        if by_grid {
            // In the grid's order, each row's heading angles, and its share of the buffers, read
            // from the agent's record (as fast as from a gathered copy of the angles: reef 100k,
            // 11.4–11.6 ticks/s against 11.0–11.3 with the copy, three rounds).
            self.angles.resize(n, [0.0; 2]);
            self.angles
                .par_iter_mut()
                .zip(self.rooms[..n].par_iter_mut())
                .zip(self.sum_starts[..n].par_iter_mut())
                .zip(entries.par_iter())
                .with_min_len(crate::par::min_len(256))
                .for_each(|(((angles, slots), sums), &i)| {
                    let a = &world.agents[i as usize];
                    *angles = [a.yaw, a.pitch];
                    (*slots, *sums) = share(a.species.0 as usize);
                });
        }
        let gathered = &self.gathered[..];
        // Each row's categories, by its agent's species.
        let species_of = |r: usize| {
            let i = if by_grid { entries[r] as usize } else { r };
            gathered[i].tag.species as usize
        };
        self.row_masks
            .par_iter_mut()
            .enumerate()
            .with_min_len(crate::par::min_len(1024))
            .for_each(|(r, mask)| {
                *mask = masks.get(species_of(r)).copied().unwrap_or(RowMask::ALL);
            });
        // A row's reach only where some species' neighborhood is bounded.
        self.size_rows(n, super::nearest::any_bound(senses));
        // The kernel's heading lanes only where some kernel perceiver's fold sums headings.
        let headings = obstacles
            || self.kernel.iter().enumerate().any(|(s, &k)| {
                let sense = senses.get(s).unwrap_or(&default);
                let r = reads.get(s).unwrap_or(&everything);
                let cone = !full_circle(cos_min(sense.vision_half_angle));
                let smell = sense.smell_radius * sense.smell_radius > 0.0;
                k && kin::needs_headings(false, cone, smell, r.headings)
            });
        // Whether some agent perceives by the walks, which read the grid-order bodies (`near`):
        // one of a species the kernel does not serve, or of one without senses.
        let walks = unsensed || self.kernel.iter().any(|&k| !k);
        self.copy_by_slot(agents, kernel, walks, headings);
        self.cos_mins.clear();
        self.cos_mins
            .extend(senses.iter().map(|s| cos_min(s.vision_half_angle)));
        unsensed
    }

    /// Turns every row's share of the group sums into running starts and sizes the buffers to
    /// hold them all (the summaries and percepts are laid out by the walk); the rows' reaches
    /// only when `bounded`.
    fn size_rows(&mut self, n: usize, bounded: bool) {
        let running = |starts: &mut [u32]| {
            let mut total = 0;
            for v in &mut starts[..n] {
                (*v, total) = (total, total + *v);
            }
            starts[n] = total;
            total
        };
        let sums = running(&mut self.sum_starts);
        self.sums.resize(sums as usize, 0);
        self.counts.resize(n, 0);
        // Only the summaries perceived and the percepts kept are stored.
        let chunks = n.div_ceil(super::SUMMARY_CHUNK);
        self.held.resize(n, RowMask::ALL);
        self.held_at.resize(n, 0);
        self.summary_chunks.resize_with(chunks, Vec::new);
        self.heading_chunks.resize_with(chunks, Vec::new);
        self.percept_at.resize(n, 0);
        self.percept_chunks.resize_with(chunks, Vec::new);
        if bounded {
            self.reaches.resize(n, 0.0);
        } else {
            self.reaches = Vec::new();
        }
    }

    /// Copies the gathered records into the agent grid's order (`near` when `walks`: some agent
    /// perceives by the walks; `tags`, `diagonals`, and the kin kernel's lanes when `kernel`: a
    /// species may perceive by it; their heading columns only with `headings`), and works out
    /// the slot of each agent in that order.
    fn copy_by_slot(&mut self, agents: &Grid, kernel: bool, walks: bool, headings: bool) {
        let n = self.gathered.len();
        let entries = agents.entries();
        let gathered = &self.gathered[..];
        let of_slot =
            |k: usize| -> &Gathered { gathered.get(entries[k] as usize).unwrap_or(&UNKNOWN) };
        if walks {
            self.near.resize(entries.len(), Body::default());
        } else {
            // Only the kernel reads the neighbors (16 bytes an agent otherwise).
            self.near = Vec::new();
        }
        // The kin kernel's lanes, when a species may perceive by it, filled in the same pass.
        if kernel && walks {
            self.lanes
                .fill(agents.positions(), &mut self.near, headings, |k, b| {
                    *b = of_slot(k).body;
                    (b.heading, b.velocity())
                });
        } else if kernel {
            let mut none = vec![(); entries.len()];
            self.lanes
                .fill(agents.positions(), &mut none, headings, |k, _| {
                    let b = of_slot(k).body;
                    (b.heading, b.velocity())
                });
        } else {
            self.lanes.fill(&[], &mut [], false, |_, _: &mut Body| {
                (Vec3::ZERO, Vec3::ZERO)
            });
            self.near
                .par_iter_mut()
                .enumerate()
                .with_min_len(crate::par::min_len(256))
                .for_each(|(k, b)| *b = of_slot(k).body);
        }
        self.tags.resize(entries.len(), UNKNOWN.tag);
        self.diagonals.resize(entries.len(), UNKNOWN.diagonal);
        self.tags
            .par_iter_mut()
            .zip(self.diagonals.par_iter_mut())
            .enumerate()
            .with_min_len(crate::par::min_len(256))
            .for_each(|(k, (t, d))| {
                let g = of_slot(k);
                (*t, *d) = (g.tag, g.diagonal);
            });
        self.slot_of.clear();
        if agents.slots().len() == n {
            // The grid indexes exactly these agents: its inverse is the slot of each. The walk
            // reads the grid's own; a copy is kept only for reading rows in the grid's order
            // after it (4 bytes an agent otherwise).
            if self.by_grid {
                self.slot_of.extend_from_slice(agents.slots());
            } else {
                self.slot_of = Vec::new();
            }
        } else {
            self.slot_of.resize(n, u32::MAX);
            for (k, &j) in entries.iter().enumerate() {
                if let Some(s) = self.slot_of.get_mut(j as usize) {
                    *s = k as u32;
                }
            }
        }
    }
}
