//! Where an agent is, for the monitor's figures and examples: signed distances to obstacles,
//! obstacles' labels, and what a frozen agent is next to.

use super::SpeciesInfo;
use crate::health::{NextTo, NEAR_OBSTACLE};
use crate::world::{Obstacle, Shape, World};
use glam::Vec3;

/// Signed distance from `p` to the surface of `shape` (negative inside).
pub(super) fn signed_distance(shape: &Shape, p: Vec3) -> f32 {
    match shape {
        Shape::Sphere { center, radius } => (p - *center).length() - radius,
        Shape::Box(b) => {
            let q = (p - b.center()).abs() - b.size() * 0.5;
            q.max(Vec3::ZERO).length() + q.max_element().min(0.0)
        }
        Shape::Cylinder {
            base,
            radius,
            height,
        } => {
            // Outside the side and outside the height, as a box's two axes.
            let ring = crate::math::hypot(p.x - base.x, p.z - base.z) - radius;
            let y = (p.y - (base.y + height * 0.5)).abs() - height * 0.5;
            let q = glam::Vec2::new(ring, y);
            q.max(glam::Vec2::ZERO).length() + q.max_element().min(0.0)
        }
    }
}

/// "sphere 2", "box 4".
pub(super) fn obstacle_label(o: &Obstacle) -> String {
    match o.shape {
        Shape::Sphere { .. } => format!("sphere {}", o.id),
        Shape::Box(_) => format!("box {}", o.id),
        Shape::Cylinder { .. } => format!("cylinder {}", o.id),
    }
}

/// Label of a frozen agent's place for counting: the obstacle, or open water.
pub(super) fn place_of(near: &NextTo) -> String {
    match near {
        NextTo::Obstacle { label, .. } => label.clone(),
        _ => "open water".to_string(),
    }
}

/// What agent `i` is next to: the nearest active obstacle within [`NEAR_OBSTACLE`] of its
/// centre, else the nearest other agent.
pub(super) fn near(world: &World, i: usize, species: &[SpeciesInfo]) -> NextTo {
    let p = world.agents[i].pos;
    let obstacle = world
        .obstacles
        .iter()
        .filter(|o| o.active)
        .map(|o| (signed_distance(&o.shape, p).max(0.0), o))
        .filter(|(d, _)| *d <= NEAR_OBSTACLE)
        .min_by(|x, y| x.0.total_cmp(&y.0));
    if let Some((distance, o)) = obstacle {
        return NextTo::Obstacle {
            id: o.id,
            label: obstacle_label(o),
            distance,
        };
    }
    world
        .agents
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != i)
        .map(|(_, b)| ((b.pos - p).length(), b))
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map_or(NextTo::Nothing, |(distance, b)| NextTo::Agent {
            id: b.id.0,
            species: species
                .get(b.species.0 as usize)
                .map_or_else(|| "?".to_string(), |s| s.name.clone()),
            distance,
        })
}
