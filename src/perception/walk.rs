//! The walks of stage 2 (seed 000 §1, seed 001, seed 002): for one perceiver, the obstacles
//! near it (percepts and occluders), then the agents within its largest range by one of three
//! walks — the kin kernel ([`kin`]) for a plain flocker, a plain walk straight into the kin
//! sums, or the general walk that classifies, senses and offers every candidate — then the
//! food, and finally the bearings of the percepts kept. Reads the tick's [`View`]; writes only
//! the perceiver's own share of the outputs.

use super::eye::{sense_of, sense_point, Eye, MAX_OCCLUDERS, NO_OCCLUDER};
use super::fold::{kin_only, Acc, Fold, ACC};
use super::gather::Me;
use super::occlusion::Occluders;
use super::rows::RowMask;
use super::view::View;
use super::{kin, nearest, volume, Summary};
use super::{
    Category, Extent, GroupAcc, GroupQueries, Percept, Reads, Relations, SenseParams, SumsOut,
};
use super::{Sense, Source};
use crate::world::Shape;
use glam::{Vec3, Vec3A};

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
    (probe, occluders): (kin::Probe, &[Shape]),
    radius: f32,
    groups: &GroupQueries,
    sums: &mut SumsOut,
    buf: &mut kin::KinBuf,
) -> Acc {
    let mut k = kin::KinFold::new(lanes, probe, groups.iter(), buf);
    k.occlude(occluders, view.diagonals);
    view.agents
        .for_each_row_within(probe.here, radius, |s, e| k.row(s, e));
    let sums_k = k.finish_with(|s| sums.push(s));
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

/// Whether agents of species `s` may perceive by the kin kernel (an agent with an obstacle near
/// it too: the kernel leaves out the neighbors it hides).
pub(super) fn kernel_species(
    s: usize,
    sense: &SenseParams,
    reads: &Reads,
    relations: &Relations,
) -> bool {
    let keeps_agents = reads.percepts && reads.agent_percepts && sense.slots() > 0;
    !keeps_agents
        && sense.neighbors.is_none()
        && sense.volume.is_none()
        && sense.extent == Extent::Centre
        && !relations.mates(s)
        && relations.row(s).iter().all(|c| *c == Some(Category::Kin))
        && kin::supports(&reads.groups)
}

/// The obstacles that may hide a candidate from a perceiver, and how near a candidate must be
/// for none of them to hide it: every point of the segment from the eye to a candidate at
/// distance `d` is within `d` of the eye, so an occluder whose solid lies farther than that
/// cannot block it. `clear2` is the square of the nearest occluder's distance less a
/// thousandth (far beyond the rounding of the segment tests), so skipping the test changes no
/// result; in a school beside a rock, most neighbours are nearer than the rock.
#[derive(Clone, Copy)]
struct Occ<'o> {
    shapes: &'o [Shape],
    clear2: f32,
}

impl<'o> Occ<'o> {
    /// `shapes`, the nearest of whose solids lies `clear` from the eye.
    #[inline(always)]
    fn new(shapes: &'o [Shape], clear: f32) -> Self {
        let clear = clear * 0.999;
        Occ {
            shapes,
            clear2: clear * clear,
        }
    }

    /// The occluders to test for a candidate at squared distance `d2`.
    #[inline(always)]
    fn for_d2(self, d2: f32) -> &'o [Shape] {
        if d2 < self.clear2 {
            &[]
        } else {
            self.shapes
        }
    }
}

/// How far from the eye at `eye` lies the solid that `shape` occludes with under `form`: its
/// own surface, `surface` away, or its bounding sphere (never less than 0).
fn solid_distance(shape: &Shape, form: Occluders, eye: Vec3, surface: f32) -> f32 {
    let d = match form {
        Occluders::Shape => surface,
        Occluders::BoundingSphere => shape.center().distance(eye) - shape.bounding_radius(),
    };
    d.max(0.0)
}

/// What [`Perceiver::general_walk`] classifies and senses each candidate with.
struct Walk<'w> {
    /// Obstacles that may hide a candidate.
    occ: Occ<'w>,
    /// What each species is to the perceiver.
    row: &'w [Option<Category>],
    /// Whether kin of the other sex are mates.
    mates: bool,
    /// Whether agents are kept as percepts (else only summed).
    agent_percepts: bool,
    /// The perceiver's own grid slot.
    me_slot: usize,
    /// The perceiver's position, as the candidates' are (read from here for each of them:
    /// rebuilt from its `Vec3` each time, it went through the stack as an 8- and a 4-byte
    /// store read back by one load across both, a stalled store forward on every candidate;
    /// the default scenario ran 5 % slower for it).
    here: Vec3A,
}

/// One perceiver and what it perceives with, for its walks.
struct Perceiver<'p, 'a> {
    view: &'p View<'a>,
    /// Its agent index.
    i: usize,
    me: &'p Me,
    /// Its species.
    s: usize,
    sense: &'p SenseParams,
    reads: &'p Reads,
    eye: Eye,
    /// The reach of its senses.
    radius: f32,
    /// The obstacles that may be within it (looked up once: both walks ask).
    obstacles_near: &'p [u32],
}

/// Perceives for agent `i`: fills its slots, summaries and group sums; returns the number of
/// percepts kept.
#[allow(clippy::too_many_arguments)]
// Inlined into the row loop, as the compiler chose before the agent pass grew: left to it, it
// may not, at a cost of about 50 instructions a reef fish.
#[inline(always)]
pub(super) fn perceive_one<const KEEP: bool>(
    i: usize,
    me: &Me,
    view: &View,
    sense: &SenseParams,
    cos_min: f32,
    reads: &Reads,
    slots: &mut [Percept],
    summary: &mut [Summary; Category::COUNT],
    mask: RowMask,
    reach: &mut f32,
    sums: &mut SumsOut,
    buf: &mut kin::KinBuf,
) -> u16 {
    let p = Perceiver {
        view,
        i,
        me,
        s: me.tag.species as usize,
        sense,
        reads,
        eye: Eye::new(me.heading, me.yaw, cos_min, sense),
        radius: sense.query_radius(),
        obstacles_near: view.obstacle_grid.near(me.pos),
    };
    if p.kernel_alone(summary, mask, sums, buf) {
        return 0;
    }
    let mut fold = Fold::<KEEP>::new(slots);
    // Every group sum is written by `agents` (kernel or walk), none kept from before.
    debug_assert_eq!(sums.len(), reads.groups.len());
    // Nearby obstacles first: they are percepts and occluders.
    let mut occluders = [NO_OCCLUDER; MAX_OCCLUDERS];
    let (n_occ, clear) = p.obstacles(&mut fold, &mut occluders);
    let occ = Occ::new(&occluders[..n_occ], clear);
    // Agents and food are kept as percepts only where the species reads them.
    let agent_percepts = KEEP && reads.agent_percepts;
    *reach = p.agents(occ, agent_percepts, &mut fold, sums, buf);
    if view.relations.eats_items(p.s) {
        p.food(occ, agent_percepts, &mut fold);
    }
    // Bearings are worked out where the percepts are read (`Perception::percepts_in`).
    let len = fold.finish(summary).len() as u16;
    // The walks fold only what the row's categories hold.
    debug_assert!(mask.holds_all_perceived(summary), "{mask:?}: {summary:?}");
    len
}

impl Perceiver<'_, '_> {
    /// A plain flocker with nothing but kin around (no obstacle in range, no food): the kin kernel
    /// alone, its sums written straight into the summaries. Returns whether it took it.
    #[inline(always)]
    fn kernel_alone(
        &self,
        summary: &mut [Summary; Category::COUNT],
        mask: RowMask,
        sums: &mut SumsOut,
        buf: &mut kin::KinBuf,
    ) -> bool {
        let (view, me, s) = (self.view, self.me, self.s);
        if let (Some(lanes), Some(&me_slot), true) = (
            view.lanes,
            view.slot_of.get(self.i),
            view.kernel.get(s).copied().unwrap_or(false),
        ) {
            if !view.relations.eats_items(s) && self.no_obstacle_in_range() {
                let probe = probe(me.pos, me_slot, self.sense, &self.eye, self.reads);
                let acc = kernel(
                    view,
                    lanes,
                    (probe, &[]),
                    self.radius,
                    &self.reads.groups,
                    sums,
                    buf,
                );
                kin_only(summary, mask, &acc);
                return true;
            }
        }
        false
    }

    /// Whether no obstacle the grid lists is within range: the test [`Self::obstacles`] makes,
    /// so that it would fold none and hide nothing. The grid lists a rock for every agent in
    /// a cell its grown bounding sphere touches, most of them out of its range: those take
    /// the kernel alone too, with the same bits (the kernel inside the general fold, with no
    /// obstacle, sums what the kernel alone does).
    #[inline(always)]
    fn no_obstacle_in_range(&self) -> bool {
        let (world, here) = (self.view.world, self.me.pos);
        self.obstacles_near.iter().all(|&k| {
            let o = &world.obstacles[k as usize];
            !o.active || (o.shape.closest_point(here) - here).length() > self.radius
        })
    }

    /// Folds the active obstacles within range into `fold` and, where the species' vision is
    /// occluded, puts them among the `occluders`; returns how many occluders it put and the
    /// distance from the eye to the nearest of their solids (infinite without one).
    #[inline(always)]
    fn obstacles<const KEEP: bool>(
        &self,
        fold: &mut Fold<'_, KEEP>,
        occluders: &mut [Shape; MAX_OCCLUDERS],
    ) -> (usize, f32) {
        let (world, me, sense, eye, radius) =
            (self.view.world, self.me, self.sense, &self.eye, self.radius);
        let mut n_occ = 0;
        let mut clear = f32::INFINITY;
        // The grid lists, in index order, every active obstacle that may be within `radius`.
        for &k in self.obstacles_near {
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
                occluders[n_occ] = super::occlusion::occluder(&o.shape, sense.occluders);
                n_occ += 1;
                clear = clear.min(solid_distance(&o.shape, sense.occluders, me.pos, dist));
            }
            let to_center = o.shape.center() - me.pos;
            let dir = if dist > 1e-6 { offset } else { to_center };
            let mut seen = sense_of(me.pos, dir, dir.length(), dist, eye, sense);
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
                        Percept::new(
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
        (n_occ, clear)
    }

    /// Folds the agents within range into `fold` and the group sums, by the kin kernel, the
    /// plain walk or the general one. `agent_percepts`: whether agents are kept as percepts.
    /// Returns how far a bounded kin neighborhood reached (0 without a bound).
    #[inline(always)]
    fn agents<const KEEP: bool>(
        &self,
        occ: Occ<'_>,
        agent_percepts: bool,
        fold: &mut Fold<'_, KEEP>,
        sums: &mut SumsOut,
        buf: &mut kin::KinBuf,
    ) -> f32 {
        let (view, sense, radius) = (self.view, self.sense, self.radius);
        let groups = &self.reads.groups;
        let mates = view.relations.mates(self.s);
        let row = view.relations.row(self.s);
        // With `AnyPart`, a body whose centre lies beyond the ranges may reach into them.
        let agent_radius = match sense.extent {
            Extent::Centre => radius,
            Extent::AnyPart => radius + view.body_reach,
        };
        // A species that keeps no percepts and sees only kin, plainly (no custom volume, no
        // mates): the neighbors go straight into the kin sums, held in registers.
        let plain = !agent_percepts
            && sense.neighbors.is_none()
            && sense.volume.is_none()
            && !mates
            && row.iter().all(|c| matches!(c, None | Some(Category::Kin)));
        // The kin kernel, for a species it serves (which tests the centre, as `Extent::Centre`
        // does); it tests occlusion too, with the same function as the walks.
        let lanes = view
            .lanes
            .filter(|_| plain && view.kernel.get(self.s).copied().unwrap_or(false));
        if let (Some(lanes), Some(&me_slot)) = (lanes, view.slot_of.get(self.i)) {
            let probe = probe(self.me.pos, me_slot, sense, &self.eye, self.reads);
            fold.set_kin(kernel(
                view,
                lanes,
                (probe, occ.shapes),
                radius,
                groups,
                sums,
                buf,
            ));
            0.0
        } else {
            // Summed in 16-byte vectors in the worker's buffer, stored once at the end.
            let acc = &mut buf.acc[..groups.len()];
            acc.fill(GroupAcc::default());
            let reach = if plain {
                fold.set_kin(self.plain_walk(occ, row, agent_radius, acc));
                0.0
            } else {
                self.general_walk(occ, row, mates, agent_radius, agent_percepts, fold, acc)
            };
            for a in acc.iter() {
                sums.push((*a).into());
            }
            reach
        }
    }

    /// Own slot in the grid's order: a candidate there is oneself.
    #[inline(always)]
    fn me_slot(&self) -> usize {
        self.view
            .slot_of
            .get(self.i)
            .map_or(usize::MAX, |&k| k as usize)
    }

    /// The kin within `agent_radius` (`row`: what each species is to the perceiver), summed
    /// straight into the kin sums and the group sums.
    #[inline(always)]
    fn plain_walk(
        &self,
        occ: Occ<'_>,
        row: &[Option<Category>],
        agent_radius: f32,
        sums: &mut [GroupAcc],
    ) -> Acc {
        let (view, eye, sense) = (self.view, &self.eye, self.sense);
        let groups = &self.reads.groups;
        let here = self.me.pos;
        let here_a = Vec3A::from(here);
        let me_slot = self.me_slot();
        let mut kin = ACC;
        view.agents
            .for_each_slot_within(here, agent_radius, |k, pos, d2| {
                if k == me_slot || !view.is_kin(row, k) {
                    return;
                }
                let offset = pos - here_a;
                let radius = || view.diagonals[k] * 0.5;
                let Some(seen) =
                    sense_point(here, offset.into(), d2, eye, sense, occ.for_d2(d2), radius)
                else {
                    return;
                };
                let other = &view.near[k];
                let vel = Vec3A::from(other.velocity());
                groups.add(sums, offset, d2, vel);
                kin.note(seen, d2, || d2.sqrt(), pos, other.heading.into(), vel);
            });
        kin
    }

    /// Every agent within `agent_radius` classified by `row` (kin of the other sex are mates
    /// when `mates`), sensed, and folded: offered as a percept when `agent_percepts`, else
    /// summed; kin and mates also go into the group sums. Returns how far a bounded kin
    /// neighborhood reached (0 without a bound).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn general_walk<const KEEP: bool>(
        &self,
        occ: Occ<'_>,
        row: &[Option<Category>],
        mates: bool,
        agent_radius: f32,
        agent_percepts: bool,
        fold: &mut Fold<'_, KEEP>,
        sums: &mut [GroupAcc],
    ) -> f32 {
        let (view, sense) = (self.view, self.sense);
        let here = self.me.pos;
        let me_slot = self.me_slot();
        let walk = Walk {
            occ,
            row,
            mates,
            agent_percepts,
            me_slot,
            here: here.into(),
        };
        // Each walk below takes a closure of its own around the same inlined body: one body
        // shared by the three would be a call per candidate (a reef fish's walk takes some 16).
        match (sense.neighbors, view.others.of(self.s)) {
            (Some(n), Some(others)) => {
                // A bounded kin neighborhood: the others within range, then the nearest `n` kin.
                others.for_each_within(here, agent_radius, |k, pos, d2| {
                    self.visit(&walk, None, fold, sums, k, pos, d2)
                });
                let is_kin = |k: usize| view.is_kin(row, k);
                let q = nearest::KinQuery {
                    here,
                    radius: agent_radius,
                    me: me_slot,
                    n: n as usize,
                };
                let hint = view.others.hint(self.i);
                // Each of them is kin: `is_kin` said so.
                nearest::nearest_kin(view.agents, q, hint, is_kin, |k, pos, d2| {
                    self.visit(&walk, Some(Category::Kin), fold, sums, k, pos, d2)
                })
            }
            _ => {
                view.agents
                    .for_each_slot_within(here, agent_radius, |k, pos, d2| {
                        self.visit(&walk, None, fold, sums, k, pos, d2)
                    });
                0.0
            }
        }
    }

    /// One candidate of [`Self::general_walk`]: the agent in grid slot `k` at `pos`, at squared
    /// distance `d2`; `known`: what the row makes it, when the walk already looked.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn visit<const KEEP: bool>(
        &self,
        walk: &Walk,
        known: Option<Category>,
        fold: &mut Fold<'_, KEEP>,
        sums: &mut [GroupAcc],
        k: usize,
        pos: Vec3A,
        d2: f32,
    ) {
        let (view, eye, sense) = (self.view, &self.eye, self.sense);
        if k == walk.me_slot {
            return;
        }
        let tag = view.tags[k];
        let Some(mut cat) = known.or_else(|| walk.row.get(tag.species as usize).copied().flatten())
        else {
            return;
        };
        if cat == Category::Kin && walk.mates && tag.sex != self.me.tag.sex {
            cat = Category::Mate;
        }
        let here = self.me.pos;
        let offset_a = pos - walk.here;
        let offset = Vec3::from(offset_a);
        let radius = || view.diagonals[k] * 0.5;
        let Some(seen) = sense_point(here, offset, d2, eye, sense, walk.occ.for_d2(d2), radius)
        else {
            return;
        };
        let other = &view.near[k];
        let vel = Vec3A::from(other.velocity());
        if matches!(cat, Category::Kin | Category::Mate) {
            self.reads.groups.add(sums, offset_a, d2, vel);
        }
        // `offset.length()`, bit for bit: the grid measured `offset.length_squared()`.
        let dist = || d2.sqrt();
        if !walk.agent_percepts {
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
                Percept::new(
                    Source::Agent(view.agents.entries()[k]),
                    cat,
                    seen,
                    offset,
                    dist,
                    view.diagonals[k],
                )
            },
        );
    }

    /// Folds the food items within range into `fold`: offered as percepts when `keep`, else
    /// summed.
    #[inline(always)]
    fn food<const KEEP: bool>(&self, occ: Occ<'_>, keep: bool, fold: &mut Fold<'_, KEEP>) {
        let (eye, sense) = (&self.eye, self.sense);
        let here = self.me.pos;
        self.view
            .food
            .for_each_within(here, self.radius, |j, pos, d2| {
                let offset = pos - here;
                if let Some(seen) =
                    sense_point(here, offset, d2, eye, sense, occ.for_d2(d2), || 0.0)
                {
                    let cat = Category::Food;
                    let at = Vec3A::from(pos);
                    let dist = || d2.sqrt();
                    if !keep {
                        fold.sum(cat, seen, d2, dist, at, Vec3A::ZERO, Vec3A::ZERO);
                        return;
                    }
                    fold.take(cat, seen, d2, dist, at, Vec3A::ZERO, Vec3A::ZERO, |dist| {
                        Percept::new(Source::Food(j), cat, seen, offset, dist, 0.0)
                    });
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::super::occlusion::{blocks, hidden, occluder};
    use super::*;
    use crate::world::{Aabb, Rng};

    /// The claim [`Occ`] rests on: no occluder hides a target nearer than the distance to its
    /// solid, less a thousandth (the targets [`Occ::for_d2`] tests against none). Random
    /// spheres, boxes (flat ones among them) and cylinders, both occluder forms, eyes near
    /// them and targets in every direction, half of them aimed at the solid.
    #[test]
    fn no_occluder_hides_a_target_nearer_than_its_solid() {
        let mut rng = Rng::new(11, 0);
        let (mut near, mut far_blocked) = (0, 0);
        for k in 0..4000 {
            let c = Vec3::new(
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
            );
            let size = Vec3::new(
                rng.range(0.2, 12.0),
                rng.range(0.1, 3.0),
                rng.range(0.2, 8.0),
            );
            let shape = match k % 3 {
                0 => Shape::Sphere {
                    center: c,
                    radius: rng.range(0.2, 5.0),
                },
                1 => Shape::Box(Aabb::new(c - size * 0.5, c + size * 0.5)),
                _ => Shape::Cylinder {
                    base: c,
                    radius: rng.range(0.2, 4.0),
                    height: rng.range(0.2, 6.0),
                },
            };
            let form = if k % 2 == 0 {
                Occluders::Shape
            } else {
                Occluders::BoundingSphere
            };
            let eye = Vec3::new(
                rng.range(-9.0, 9.0),
                rng.range(-9.0, 9.0),
                rng.range(-9.0, 9.0),
            );
            let surface = (shape.closest_point(eye) - eye).length();
            let clear = solid_distance(&shape, form, eye, surface);
            let solid = occluder(&shape, form);
            let occ = Occ::new(std::slice::from_ref(&solid), clear);
            let aim = (solid.closest_point(eye) - eye).normalize_or_zero();
            for j in 0..50 {
                let jitter = Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                // Half of them aimed at the solid's nearest point, where one hides soonest.
                let dir = if j % 2 == 0 {
                    (aim * 4.0 + jitter).normalize_or_zero()
                } else {
                    jitter.normalize_or_zero()
                };
                let d = rng.range(0.0, 1.5) * clear;
                let offset = dir * d;
                if occ.for_d2(offset.length_squared()).is_empty() {
                    near += 1;
                    assert!(
                        !blocks(&solid, eye, offset) && !hidden(eye, offset, || 0.5, &[solid]),
                        "{shape:?} ({form:?}) hides {offset} from {eye}, nearer than {clear}"
                    );
                }
                // Beyond it, some are hidden: the targets do go round the solids.
                let beyond = dir * (clear + rng.range(0.0, 12.0));
                far_blocked += blocks(&solid, eye, beyond) as u32;
            }
        }
        assert!(
            near > 100_000 && far_blocked > 5_000,
            "{near} {far_blocked}"
        );
    }
}
