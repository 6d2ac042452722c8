//! The world state: agents, static obstacles, food, bounds and the clock.
//!
//! Not a stage itself: every stage of the tick (see [`crate::tick`]) reads the world as it was at
//! the start of the tick and the pipeline applies the results in agent order at the end.

mod agent;
pub mod board;
mod rng;
mod signal;

pub use agent::{
    Agent, AgentId, Anim, Attributes, Cooldowns, Drives, ForwardCache, MemValue, MessageKind, Mind,
    MindParts, RareMind, ScopeTicks, Sex, SpeciesId, Spot, MEMORY_CAPACITY, STACK_CAPACITY,
};
pub use rng::Rng;
pub use signal::{
    field_fits, field_zero, EventSpec, FieldType, HeardEvent, Inbox, Payload, Signal,
};

use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// An axis-aligned box: world bounds, obstacle boxes, spawn regions. A key other than `min`
/// and `max` (`size:`) is an error, not ignored.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// A box from two corners in any order.
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Aabb {
            min: a.min(b),
            max: a.max(b),
        }
    }
    /// Centre point.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
    /// Full size along each axis.
    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }
    /// Whether `p` lies inside or on the box.
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
    /// Whether `other` lies entirely inside this box.
    pub fn contains_box(&self, other: &Aabb) -> bool {
        self.contains(other.min) && self.contains(other.max)
    }
    /// The point of the box nearest to `p`.
    pub fn closest_point(&self, p: Vec3) -> Vec3 {
        p.clamp(self.min, self.max)
    }
}

/// The shape of a static obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// An axis-aligned box.
    Box(Aabb),
    /// An upright cylinder (axis along world up): from `base` up to `base.y + height`
    /// (seed 001: complex obstacles bounded by boxes, cylinders or spheres).
    Cylinder {
        /// Centre of the bottom disc.
        base: Vec3,
        /// Radius.
        radius: f32,
        /// Height (≥ 0).
        height: f32,
    },
}

impl Shape {
    /// Centre of the shape.
    pub fn center(&self) -> Vec3 {
        match self {
            Shape::Sphere { center, .. } => *center,
            Shape::Box(b) => b.center(),
            Shape::Cylinder { base, height, .. } => *base + Vec3::Y * (height * 0.5),
        }
    }
    /// Radius of the bounding sphere (used for occlusion and the path test, seed 001).
    pub fn bounding_radius(&self) -> f32 {
        match self {
            Shape::Sphere { radius, .. } => *radius,
            Shape::Box(b) => b.size().length() * 0.5,
            Shape::Cylinder { radius, height, .. } => crate::math::hypot(*radius, height * 0.5),
        }
    }
    /// Size `S` of seed 000 §4.1: the bounding box diagonal.
    pub fn diagonal(&self) -> f32 {
        match self {
            Shape::Sphere { radius, .. } => 2.0 * radius * 3f32.sqrt(),
            Shape::Box(b) => b.size().length(),
            // The box around it: 2r × h × 2r.
            Shape::Cylinder { radius, height, .. } => {
                (8.0 * radius * radius + height * height).sqrt()
            }
        }
    }
    /// Where a body centred at `p` must move to keep `clearance` from the shape: `None` when it
    /// already does; else the nearest point at that clearance (for a box, on the nearest face
    /// of the box grown by `clearance`, which is at least `clearance` from the box).
    pub fn push_out(&self, p: Vec3, clearance: f32) -> Option<Vec3> {
        let clearance = clearance.max(0.0);
        match self {
            Shape::Sphere { center, radius } => {
                let keep = radius + clearance;
                let d = p - *center;
                let len2 = d.length_squared();
                if len2 >= keep * keep || len2.is_nan() {
                    return None;
                }
                // A body exactly at the centre leaves upward.
                let dir = d.try_normalize().unwrap_or(Vec3::Y);
                Some(*center + dir * keep)
            }
            Shape::Box(b) => {
                let (lo, hi) = (
                    b.min - Vec3::splat(clearance),
                    b.max + Vec3::splat(clearance),
                );
                if !(p.cmpgt(lo).all() && p.cmplt(hi).all()) {
                    return None;
                }
                // The face the body is nearest to, in axis order among equals.
                let mut best = (f32::INFINITY, p);
                for axis in 0..3 {
                    for (face, gap) in [
                        (lo[axis], p[axis] - lo[axis]),
                        (hi[axis], hi[axis] - p[axis]),
                    ] {
                        if gap < best.0 {
                            let mut q = p;
                            q[axis] = face;
                            best = (gap, q);
                        }
                    }
                }
                Some(best.1)
            }
            Shape::Cylinder {
                base,
                radius,
                height,
            } => {
                let keep = radius + clearance;
                let (lo, hi) = (base.y - clearance, base.y + height + clearance);
                let h = Vec3::new(p.x - base.x, 0.0, p.z - base.z);
                let ring = h.length();
                if !(p.y > lo && p.y < hi && ring < keep) {
                    return None;
                }
                // The nearest of the side (grown by `clearance`), the top and the bottom, in
                // that order among equals.
                let side = keep - ring;
                let (top, bottom) = (hi - p.y, p.y - lo);
                if side <= top && side <= bottom {
                    let dir = h.try_normalize().unwrap_or(Vec3::X);
                    Some(Vec3::new(base.x + dir.x * keep, p.y, base.z + dir.z * keep))
                } else if top <= bottom {
                    Some(Vec3::new(p.x, hi, p.z))
                } else {
                    Some(Vec3::new(p.x, lo, p.z))
                }
            }
        }
    }
    /// [`Shape::push_out`] along the horizontal only: for a body that stands on the floor of
    /// the world where a rock meets it (pushed straight out, it would go through the floor and
    /// be put back inside the rock).
    pub fn push_out_level(&self, p: Vec3, clearance: f32) -> Option<Vec3> {
        let clearance = clearance.max(0.0);
        match self {
            Shape::Sphere { center, radius } => {
                let keep = radius + clearance;
                let dy = p.y - center.y;
                let ring2 = keep * keep - dy * dy;
                let h = Vec3::new(p.x - center.x, 0.0, p.z - center.z);
                if ring2 <= 0.0 || ring2.is_nan() || h.length_squared() >= ring2 {
                    return None;
                }
                let dir = h.try_normalize().unwrap_or(Vec3::X);
                let ring = ring2.sqrt();
                Some(Vec3::new(
                    center.x + dir.x * ring,
                    p.y,
                    center.z + dir.z * ring,
                ))
            }
            Shape::Box(b) => {
                let flat = Aabb::new(
                    Vec3::new(b.min.x, f32::NEG_INFINITY, b.min.z),
                    Vec3::new(b.max.x, f32::INFINITY, b.max.z),
                );
                let inside_height = p.y > b.min.y - clearance && p.y < b.max.y + clearance;
                if !inside_height {
                    return None;
                }
                Shape::Box(flat).push_out(p, clearance)
            }
            Shape::Cylinder {
                base,
                radius,
                height,
            } => {
                let keep = radius + clearance;
                let inside_height = p.y > base.y - clearance && p.y < base.y + height + clearance;
                let h = Vec3::new(p.x - base.x, 0.0, p.z - base.z);
                if !inside_height || h.length_squared() >= keep * keep {
                    return None;
                }
                let dir = h.try_normalize().unwrap_or(Vec3::X);
                Some(Vec3::new(base.x + dir.x * keep, p.y, base.z + dir.z * keep))
            }
        }
    }
    /// The surface point nearest to `p` (for a point inside, `p` itself).
    pub fn closest_point(&self, p: Vec3) -> Vec3 {
        match self {
            Shape::Sphere { center, radius } => {
                let d = p - *center;
                let len = d.length();
                if len <= *radius {
                    p
                } else {
                    *center + d * (*radius / len)
                }
            }
            Shape::Box(b) => b.closest_point(p),
            Shape::Cylinder {
                base,
                radius,
                height,
            } => {
                let y = p.y.clamp(base.y, base.y + height);
                let h = Vec3::new(p.x - base.x, 0.0, p.z - base.z);
                let ring = h.length();
                if ring <= *radius {
                    Vec3::new(p.x, y, p.z)
                } else {
                    let k = radius / ring;
                    Vec3::new(base.x + h.x * k, y, base.z + h.z * k)
                }
            }
        }
    }
}

/// A static obstacle with a stable id.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Obstacle {
    /// Stable id (its index in the scenario).
    pub id: u32,
    /// Geometry.
    pub shape: Shape,
    /// False once removed by a timed event; removed obstacles are neither seen nor avoided.
    pub active: bool,
}

/// A food item.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Food {
    /// Stable id.
    pub id: u32,
    /// Position.
    pub pos: Vec3,
}

/// The whole simulated state.
#[derive(Debug, Clone)]
pub struct World {
    /// Agents in ascending id order; dead agents are removed at the end of the tick they die in.
    pub agents: Vec<Agent>,
    /// Static obstacles.
    pub obstacles: Vec<Obstacle>,
    /// Food items in ascending id order.
    pub food: Vec<Food>,
    /// World bounds; agents are kept inside.
    pub bounds: Aabb,
    /// A uniform current (world units / s) added to every agent's motion.
    pub current: Vec3,
    /// Fixed time step (s).
    pub dt: f32,
    /// Ticks done.
    pub tick: u64,
    /// The run's seed.
    pub seed: u64,
    /// Next agent id to hand out.
    pub next_agent_id: u32,
    /// Next food id to hand out.
    pub next_food_id: u32,
    /// The ground, when the scenario has terrain: walking species stand on it and scripts test
    /// line of sight over it.
    pub terrain: Option<Arc<crate::terrain::Terrain>>,
    /// The squads' plans as scripts see them, published by the scenario layer before each tick.
    pub squads: Option<Arc<board::Board>>,
    /// Payloads of the named events agents heard this tick ([`HeardEvent::payload`] indexes
    /// it); replaced with the inboxes at the end of every tick that delivered a message.
    pub event_payloads: Vec<Payload>,
}

impl World {
    /// An empty world.
    pub fn new(bounds: Aabb, dt: f32, seed: u64) -> Self {
        World {
            agents: Vec::new(),
            obstacles: Vec::new(),
            food: Vec::new(),
            bounds,
            current: Vec3::ZERO,
            dt,
            tick: 0,
            seed,
            next_agent_id: 0,
            next_food_id: 0,
            terrain: None,
            squads: None,
            event_payloads: Vec::new(),
        }
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.tick as f64 * self.dt as f64
    }

    /// Adds food at `pos` and returns its id.
    pub fn add_food(&mut self, pos: Vec3) -> u32 {
        let id = self.next_food_id;
        self.next_food_id += 1;
        self.food.push(Food { id, pos });
        id
    }

    /// Adds an obstacle and returns its id.
    pub fn add_obstacle(&mut self, shape: Shape) -> u32 {
        let id = self.obstacles.len() as u32;
        self.obstacles.push(Obstacle {
            id,
            shape,
            active: true,
        });
        id
    }

    /// Adds to `counts[s]` the number of agents of species `s` (species past the end of
    /// `counts` are not counted).
    pub fn count_species(&self, counts: &mut [u32]) {
        for a in &self.agents {
            if let Some(c) = counts.get_mut(a.species.0 as usize) {
                *c += 1;
            }
        }
    }

    /// Index of the agent with this id (agents are sorted by id).
    pub fn agent_index(&self, id: AgentId) -> Option<usize> {
        self.agents.binary_search_by_key(&id, |a| a.id).ok()
    }

    /// The agent with this id.
    pub fn agent(&self, id: AgentId) -> Option<&Agent> {
        self.agent_index(id).map(|i| &self.agents[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_out_keeps_the_clearance_from_spheres_and_boxes() {
        let s = Shape::Sphere {
            center: Vec3::ZERO,
            radius: 2.0,
        };
        // Inside, 1 from the centre along +X: out to 2 + 0.5.
        assert_eq!(
            s.push_out(Vec3::new(1.0, 0.0, 0.0), 0.5),
            Some(Vec3::new(2.5, 0.0, 0.0))
        );
        // Just outside the clearance: left alone; at the centre: straight up.
        assert_eq!(s.push_out(Vec3::new(2.6, 0.0, 0.0), 0.5), None);
        assert_eq!(s.push_out(Vec3::ZERO, 0.5), Some(Vec3::new(0.0, 2.5, 0.0)));
        let b = Shape::Box(Aabb::new(Vec3::ZERO, Vec3::new(4.0, 2.0, 10.0)));
        // Inside, nearest the top face (0.3 below it): onto the top grown by 0.2.
        assert_eq!(
            b.push_out(Vec3::new(2.0, 1.7, 5.0), 0.2),
            Some(Vec3::new(2.0, 2.2, 5.0))
        );
        // Outside the box but within the clearance of its +X face.
        assert_eq!(
            b.push_out(Vec3::new(4.1, 1.0, 5.0), 0.2),
            Some(Vec3::new(4.2, 1.0, 5.0))
        );
        assert_eq!(b.push_out(Vec3::new(4.3, 1.0, 5.0), 0.2), None);
    }

    #[test]
    fn push_out_level_moves_along_the_floor() {
        // A sphere of radius 5 centred 4 above the floor: at the floor (3 below the centre) the
        // ring of radius √(5.5² − 3²) = √21.25 is what a body with clearance 0.5 must clear.
        let s = Shape::Sphere {
            center: Vec3::new(0.0, 4.0, 0.0),
            radius: 5.0,
        };
        let q = s.push_out_level(Vec3::new(2.0, 1.0, 0.0), 0.5).unwrap();
        assert!(
            (q - Vec3::new(21.25f32.sqrt(), 1.0, 0.0)).length() < 1e-5,
            "{q}"
        );
        assert_eq!(s.push_out_level(Vec3::new(5.0, 1.0, 0.0), 0.5), None);
        // Above the top of a box: nothing to do horizontally.
        let b = Shape::Box(Aabb::new(Vec3::ZERO, Vec3::splat(2.0)));
        assert_eq!(b.push_out_level(Vec3::new(1.0, 3.0, 1.0), 0.2), None);
        assert_eq!(
            b.push_out_level(Vec3::new(1.9, 0.0, 1.0), 0.2),
            Some(Vec3::new(2.2, 0.0, 1.0))
        );
    }

    #[test]
    fn a_cylinder_has_its_bounds_nearest_point_and_push_out() {
        // Radius 2, from y = 1 up to y = 7, axis at x = 10, z = 0.
        let c = Shape::Cylinder {
            base: Vec3::new(10.0, 1.0, 0.0),
            radius: 2.0,
            height: 6.0,
        };
        // Centre at mid-height (1 + 3); bounding sphere √(2² + 3²) = √13; box 4 × 6 × 4:
        // diagonal √(16 + 36 + 16) = √68.
        assert_eq!(c.center(), Vec3::new(10.0, 4.0, 0.0));
        assert!((c.bounding_radius() - 13f32.sqrt()).abs() < 1e-6);
        assert!((c.diagonal() - 68f32.sqrt()).abs() < 1e-5);
        // Beside it at 5 from the axis, 2 above the base: onto the side at radius 2.
        assert_eq!(
            c.closest_point(Vec3::new(15.0, 3.0, 0.0)),
            Vec3::new(12.0, 3.0, 0.0)
        );
        // Above the top, off the axis by (3, 4) (5 away): the rim of the top disc, at 2/5 of it.
        let q = c.closest_point(Vec3::new(13.0, 9.0, 4.0));
        assert!((q - Vec3::new(11.2, 7.0, 1.6)).length() < 1e-5, "{q}");
        // Above the top, within the radius: straight down onto the top.
        assert_eq!(
            c.closest_point(Vec3::new(11.0, 9.0, 0.0)),
            Vec3::new(11.0, 7.0, 0.0)
        );
        // Inside: itself.
        let inside = Vec3::new(10.5, 2.0, 0.5);
        assert_eq!(c.closest_point(inside), inside);
        // Inside, 0.5 from the side (ring 1.5), 1 above the base, 5 below the top: out of the
        // side grown by 0.25, at 2.25 from the axis.
        assert_eq!(
            c.push_out(Vec3::new(11.5, 2.0, 0.0), 0.25),
            Some(Vec3::new(12.25, 2.0, 0.0))
        );
        // Inside, 0.2 below the top (ring 1, 1 from the side): onto the top grown by 0.25.
        assert_eq!(
            c.push_out(Vec3::new(11.0, 6.8, 0.0), 0.25),
            Some(Vec3::new(11.0, 7.25, 0.0))
        );
        // Inside, 0.1 above the base: down under the base grown by 0.25.
        assert_eq!(
            c.push_out(Vec3::new(11.0, 1.1, 0.0), 0.25),
            Some(Vec3::new(11.0, 0.75, 0.0))
        );
        // Outside the clearance, beside and above: left alone.
        assert_eq!(c.push_out(Vec3::new(12.3, 2.0, 0.0), 0.25), None);
        assert_eq!(c.push_out(Vec3::new(10.0, 7.3, 0.0), 0.25), None);
        // Along the floor: sideways only, even when the top is nearer.
        assert_eq!(
            c.push_out_level(Vec3::new(11.0, 6.8, 0.0), 0.25),
            Some(Vec3::new(12.25, 6.8, 0.0))
        );
        assert_eq!(c.push_out_level(Vec3::new(11.0, 7.3, 0.0), 0.25), None);
        assert_eq!(c.push_out_level(Vec3::new(12.3, 3.0, 0.0), 0.25), None);
    }

    #[test]
    fn a_cylinder_off_the_axes_and_at_its_bounds() {
        // Radius 2 around (10, ·, −3), y from 1 to 7; with clearance 0.25: keep 2.25 from the
        // axis, y within (0.75, 7.25).
        let c = Shape::Cylinder {
            base: Vec3::new(10.0, 1.0, -3.0),
            radius: 2.0,
            height: 6.0,
        };
        let near = |a: Option<Vec3>, b: Vec3| a.is_some_and(|a| (a - b).length() < 1e-5);
        // 1 from the axis along (0.6, 0, 0.8): side 1.25, top 4.25, bottom 2.25: out of the
        // side at (10 + 0.6·2.25, 3, −3 + 0.8·2.25).
        let p = Vec3::new(10.6, 3.0, -2.2);
        let out = Vec3::new(11.35, 3.0, -1.2);
        assert!(near(c.push_out(p, 0.25), out));
        assert!(near(c.push_out_level(p, 0.25), out));
        // 1.55 from the axis, 0.45 below the grown top: the top (0.45) is nearer than the side
        // (0.7).
        assert!(near(
            c.push_out(Vec3::new(11.55, 6.8, -3.0), 0.25),
            Vec3::new(11.55, 7.25, -3.0)
        ));
        // 2.2 from the axis (2.2² = 4.84 < 2.25² = 5.0625), 1.0 high (above 0.75): along the
        // floor out to 2.25.
        assert!(near(
            c.push_out_level(Vec3::new(12.2, 1.0, -3.0), 0.25),
            Vec3::new(12.25, 1.0, -3.0)
        ));
        // Exactly at the grown bounds: outside.
        for q in [
            Vec3::new(10.5, 0.75, -3.0),
            Vec3::new(10.5, 7.25, -3.0),
            Vec3::new(12.25, 3.0, -3.0),
        ] {
            assert_eq!(c.push_out(q, 0.25), None, "{q}");
            assert_eq!(c.push_out_level(q, 0.25), None, "{q}");
        }
        // Above the top, off the axis by (3, 4): the rim of the top at 2/5 of the way.
        assert!(near(
            Some(c.closest_point(Vec3::new(13.0, 9.0, 1.0))),
            Vec3::new(11.2, 7.0, -1.4)
        ));
    }
}
