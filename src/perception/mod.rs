//! Stage 2 of the tick: perception (seed 000 §1, seed 001 vision and occlusion, seed 002
//! non-spherical volume).
//!
//! For every agent, the spatial index yields candidates within its largest sensing range; each is
//! classified by the species' relations (food, predator, kin, mate, other), tested against vision
//! (sphere `v_r` limited to a cone, or a custom body-frame [`Volume`], not occluded by nearer
//! obstacles' bounding spheres) and smell (sphere `O_r`), given its bearing, elevation and sector,
//! and folded into a per-category [`Summary`]. Results go into fixed-size per-agent slots, so the
//! stage allocates nothing once warmed up and runs in parallel with identical results.

mod types;
pub mod volume;

pub use types::{Category, Level, Percept, Sector, Sense, Source, Summary};
pub use volume::Volume;

use crate::frame;
use crate::index::Grid;
use crate::world::World;
use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Percepts kept per agent (the nearest ones; summaries still count all of them).
pub const MAX_PERCEPTS: usize = 24;

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
    /// Whether obstacles' bounding spheres hide what lies behind them.
    pub occlusion: bool,
}

impl Default for SenseParams {
    fn default() -> Self {
        SenseParams {
            vision_radius: 10.0,
            vision_half_angle: 150f32.to_radians(),
            smell_radius: 20.0,
            volume: None,
            occlusion: true,
        }
    }
}

impl SenseParams {
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

/// Per-agent perception results of one tick.
#[derive(Debug, Clone, Default)]
pub struct Perception {
    percepts: Vec<Percept>,
    counts: Vec<u16>,
    summaries: Vec<[Summary; Category::COUNT]>,
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

impl Perception {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Percepts of agent `i` (nearest [`MAX_PERCEPTS`]).
    #[inline]
    pub fn percepts(&self, i: usize) -> &[Percept] {
        &self.percepts[i * MAX_PERCEPTS..i * MAX_PERCEPTS + self.counts[i] as usize]
    }

    /// Summaries of agent `i`, indexed by [`Category`].
    #[inline]
    pub fn summaries(&self, i: usize) -> &[Summary; Category::COUNT] {
        &self.summaries[i]
    }

    /// Number of agents perceived for.
    pub fn len(&self) -> usize {
        self.counts.len()
    }

    /// Whether there are no results.
    pub fn is_empty(&self) -> bool {
        self.counts.is_empty()
    }

    /// Runs perception for every agent of `world`. `senses[s]` are species `s`'s senses.
    pub fn run(
        &mut self,
        world: &World,
        agents: &Grid,
        food: &Grid,
        senses: &[SenseParams],
        relations: &Relations,
    ) {
        let n = world.agents.len();
        self.percepts.clear();
        self.percepts.resize(n * MAX_PERCEPTS, EMPTY);
        self.counts.clear();
        self.counts.resize(n, 0);
        self.summaries.clear();
        self.summaries
            .resize(n, [Summary::default(); Category::COUNT]);
        self.percepts
            .par_chunks_mut(MAX_PERCEPTS)
            .zip(self.counts.par_iter_mut())
            .zip(self.summaries.par_iter_mut())
            .enumerate()
            .with_min_len(64)
            .for_each(|(i, ((slots, count), summary))| {
                let s = world.agents[i].species.0 as usize;
                let default = SenseParams::default();
                let sense = senses.get(s).unwrap_or(&default);
                *count = perceive_one(i, world, agents, food, sense, relations, slots, summary);
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
        let slots = &mut self.percepts[i * MAX_PERCEPTS..(i + 1) * MAX_PERCEPTS];
        let summary = &mut self.summaries[i];
        *summary = [Summary::default(); Category::COUNT];
        let mut len = 0;
        for p in percepts {
            note(summary, p, pos + p.offset, Vec3::ZERO, Vec3::ZERO);
            if p.category == Category::Mate {
                let kin = Percept {
                    category: Category::Kin,
                    ..*p
                };
                note(summary, &kin, pos + p.offset, Vec3::ZERO, Vec3::ZERO);
            }
            keep(slots, &mut len, *p);
        }
        for (c, sm) in summary.iter_mut().enumerate() {
            if sm.count > 0 {
                sm.centroid /= sm.count as f32;
            }
            let mut best: Option<(u16, f32)> = None;
            for (k, p) in slots[..len].iter().enumerate() {
                let matches = p.category as usize == c
                    || (c == Category::Kin as usize && p.category == Category::Mate);
                if matches && best.is_none_or(|(_, d)| p.dist < d) {
                    best = Some((k as u16, p.dist));
                }
            }
            sm.nearest = best.map(|b| b.0);
        }
        self.counts[i] = len as u16;
    }
}

/// Keeps the nearest `MAX_PERCEPTS` percepts: appends while there is room, else replaces the
/// farthest when nearer.
#[inline]
fn keep(slots: &mut [Percept], len: &mut usize, p: Percept) {
    if *len < slots.len() {
        slots[*len] = p;
        *len += 1;
        return;
    }
    let mut far = 0;
    for k in 1..*len {
        if slots[k].dist > slots[far].dist {
            far = k;
        }
    }
    if p.dist < slots[far].dist {
        slots[far] = p;
    }
}

/// Whether the segment from `from` to `to` passes through a sphere nearer than `to`.
#[inline]
fn occluded(from: Vec3, to: Vec3, occluders: &[(Vec3, f32)]) -> bool {
    let seg = to - from;
    let len2 = seg.length_squared();
    if len2 <= 0.0 {
        return false;
    }
    for &(c, r) in occluders {
        let t = ((c - from).dot(seg) / len2).clamp(0.0, 1.0);
        let closest = from + seg * t;
        // The target itself may touch the sphere (food on a rock): only block strictly between.
        if t > 0.0
            && t < 1.0
            && (c - closest).length_squared() < r * r
            && (c - to).length_squared() > r * r
        {
            return true;
        }
    }
    false
}

#[allow(clippy::too_many_arguments)]
fn perceive_one(
    i: usize,
    world: &World,
    agents: &Grid,
    food: &Grid,
    sense: &SenseParams,
    relations: &Relations,
    slots: &mut [Percept],
    summary: &mut [Summary; Category::COUNT],
) -> u16 {
    let me = &world.agents[i];
    let s = me.species.0 as usize;
    let (yaw, pitch) = (me.yaw, me.pitch);
    let fwd = me.forward();
    let left = frame::left(yaw);
    let up = frame::dorsal(yaw, pitch);
    let radius = sense.query_radius();
    let mut len = 0usize;

    // Nearby obstacles first: they are percepts and occluders.
    let mut occluders = [(Vec3::ZERO, 0.0f32); MAX_OCCLUDERS];
    let mut n_occ = 0;
    for (k, o) in world.obstacles.iter().enumerate() {
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
            occluders[n_occ] = (o.shape.center(), o.shape.bounding_radius());
            n_occ += 1;
        }
        let to_center = o.shape.center() - me.pos;
        let dir = if dist > 1e-6 { offset } else { to_center };
        if let Some(p) = classify(
            me.pos,
            dir,
            dist,
            fwd,
            left,
            up,
            yaw,
            pitch,
            sense,
            Category::Obstacle,
            &[],
        ) {
            let p = Percept {
                source: Source::Obstacle(k as u32),
                size: o.shape.diagonal(),
                ..p
            };
            note(summary, &p, me.pos + offset, Vec3::ZERO, Vec3::ZERO);
            keep(slots, &mut len, p);
        }
    }
    let occ = &occluders[..n_occ];

    agents.for_each_within(me.pos, radius, |j, pos, _| {
        let j = j as usize;
        if j == i {
            return;
        }
        let other = &world.agents[j];
        let Some(mut cat) = relations.get(s, other.species.0 as usize) else {
            return;
        };
        if cat == Category::Kin
            && relations.mates.get(s).copied().unwrap_or(false)
            && other.attrs.sex != me.attrs.sex
        {
            cat = Category::Mate;
        }
        let offset = pos - me.pos;
        let dist = offset.length();
        if let Some(p) = classify(
            me.pos, offset, dist, fwd, left, up, yaw, pitch, sense, cat, occ,
        ) {
            let p = Percept {
                source: Source::Agent(j as u32),
                size: other.diagonal(),
                ..p
            };
            let heading = other.forward();
            let vel = heading * other.speed;
            note(summary, &p, pos, heading, vel);
            if cat == Category::Mate {
                note(
                    summary,
                    &Percept {
                        category: Category::Kin,
                        ..p
                    },
                    pos,
                    heading,
                    vel,
                );
            }
            keep(slots, &mut len, p);
        }
    });

    if relations.eats_items(s) {
        food.for_each_within(me.pos, radius, |j, pos, _| {
            let offset = pos - me.pos;
            let dist = offset.length();
            if let Some(p) = classify(
                me.pos,
                offset,
                dist,
                fwd,
                left,
                up,
                yaw,
                pitch,
                sense,
                Category::Food,
                occ,
            ) {
                let p = Percept {
                    source: Source::Food(j),
                    size: 0.0,
                    ..p
                };
                note(summary, &p, pos, Vec3::ZERO, Vec3::ZERO);
                keep(slots, &mut len, p);
            }
        });
    }

    // Finish summaries: means, and the nearest among the kept percepts.
    for (c, sm) in summary.iter_mut().enumerate() {
        if sm.count > 0 {
            let n = sm.count as f32;
            sm.centroid /= n;
            sm.mean_heading /= n;
            sm.mean_velocity /= n;
        }
        let mut best: Option<(u16, f32)> = None;
        for (k, p) in slots[..len].iter().enumerate() {
            let matches = p.category as usize == c
                || (c == Category::Kin as usize && p.category == Category::Mate);
            if matches && best.is_none_or(|(_, d)| p.dist < d) {
                best = Some((k as u16, p.dist));
            }
        }
        sm.nearest = best.map(|b| b.0);
    }
    len as u16
}

/// Adds a percept to its category's running sums.
#[inline]
fn note(
    summary: &mut [Summary; Category::COUNT],
    p: &Percept,
    pos: Vec3,
    heading: Vec3,
    vel: Vec3,
) {
    let sm = &mut summary[p.category as usize];
    sm.count += 1;
    if p.sense == Sense::Vision {
        sm.seen += 1;
    }
    if p.dist < sm.nearest_dist {
        sm.nearest_dist = p.dist;
    }
    sm.centroid += pos;
    sm.mean_heading += heading;
    sm.mean_velocity += vel;
}

/// Decides whether a target at `offset` is seen, smelt or missed, and builds its percept.
#[allow(clippy::too_many_arguments)]
#[inline]
fn classify(
    from: Vec3,
    offset: Vec3,
    dist: f32,
    fwd: Vec3,
    left: Vec3,
    up: Vec3,
    yaw: f32,
    pitch: f32,
    sense: &SenseParams,
    category: Category,
    occluders: &[(Vec3, f32)],
) -> Option<Percept> {
    let in_vision = match &sense.volume {
        Some(v) => v.contains(Vec3::new(offset.dot(left), offset.dot(up), offset.dot(fwd))),
        None => {
            dist <= sense.vision_radius && volume::in_cone(fwd, offset, sense.vision_half_angle)
        }
    };
    let seen = in_vision && !occluded(from, from + offset, occluders);
    let sense_used = if seen {
        Sense::Vision
    } else if dist <= sense.smell_radius {
        Sense::Smell
    } else {
        return None;
    };
    let (bearing, elevation) = frame::bearing_elevation(yaw, pitch, offset);
    Some(Percept {
        source: Source::Food(0),
        category,
        sense: sense_used,
        offset,
        dist,
        bearing,
        elevation,
        size: 0.0,
    })
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
        assert_eq!(p.percepts(0).len(), MAX_PERCEPTS);
        assert_eq!(p.summaries(0)[Category::Kin as usize].count, 40);
        let maxd = p.percepts(0).iter().map(|q| q.dist).fold(0.0, f32::max);
        assert!((maxd - 0.2 * MAX_PERCEPTS as f32).abs() < 1e-4);
    }
}
