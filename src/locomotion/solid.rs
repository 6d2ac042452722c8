//! Stage 6 of the tick, after the body moved: solid bodies. Whatever the steering asked, a body
//! ends the tick inside the world, out of every obstacle and not overlapping the kin it
//! perceives. Reads perception's results of the tick (the kin offsets, the obstacle grid) and
//! the world's obstacles; writes only the agent's own new position.

use crate::perception::{Category, Percept, Perception, Source};
use crate::world::{Agent, World};
use glam::Vec3;

/// Keeps a body solid after locomotion moved it to `pos`: it never ends a tick inside an
/// obstacle or closer to one than half its width, and it does not overlap kin it perceives (each
/// of two overlapping agents moves half the overlap away from the other, from the start of the
/// tick's positions, so the pair separates whichever is processed first; of two agents at the
/// very same point the lower-numbered steps to its left, the other to its right). Steering avoids obstacles and
/// kin; this is what holds when it does not, whatever a species' recipe says.
pub fn keep_solid(
    pos: &mut Vec3,
    i: usize,
    me: &Agent,
    percepts: &[Percept],
    world: &World,
    perception: &Perception,
) {
    let width = me.size.x.max(0.0);
    for p in percepts {
        let (Source::Agent(j), Category::Kin | Category::Mate) = (p.source, p.category) else {
            continue;
        };
        if p.dist >= width {
            continue;
        }
        let away = match (-p.offset).try_normalize() {
            Some(d) if p.dist > 1e-4 => d,
            _ => {
                let left = crate::frame::left(me.yaw);
                if i < j as usize {
                    left
                } else {
                    -left
                }
            }
        };
        *pos += away * (0.5 * (width - p.dist));
    }
    // A hair more than half the width, so that rounding never leaves the body inside it.
    let clearance = 0.5 * width * 1.001 + 1e-4;
    // Inside the world first: a body below the floor may be clear of a rock that the floor
    // puts it back against.
    *pos = world.bounds.closest_point(*pos);
    for &k in perception.obstacles_near(*pos) {
        let Some(o) = world.obstacles.get(k as usize) else {
            continue;
        };
        if o.active {
            if let Some(q) = o.shape.push_out(*pos, clearance) {
                // Where a rock meets the floor or a wall of the world, straight out may be out
                // of the world: then along the horizontal.
                *pos = if world.bounds.contains(q) {
                    q
                } else {
                    let p = world.bounds.closest_point(*pos);
                    o.shape.push_out_level(p, clearance).unwrap_or(q)
                };
            }
        }
    }
}
