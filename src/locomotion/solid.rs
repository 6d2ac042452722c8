//! Stage 6 of the tick, after the body moved: solid bodies. Whatever the steering asked, a body
//! ends the tick inside the world, out of every obstacle and not overlapping the kin it
//! perceives. Reads perception's results of the tick (the kin offsets, the obstacle grid) and
//! the world's obstacles; writes only the agent's own new position.

use crate::perception::{Category, Percept, Perception, Source};
use crate::world::{Agent, World};
use glam::Vec3;

/// Keeps a body solid after locomotion moved it to `pos`: it never ends a tick inside an
/// obstacle or closer to one than half its width, and it does not overlap kin it perceives (each
/// of two overlapping agents moves half the overlap away from where the other is heading this
/// tick (its start position plus its velocity), so the pair separates whichever is processed
/// first; of two agents at the very same point the lower-numbered steps to its left, the other
/// to its right). Steering avoids obstacles and
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
    let dt = world.dt;
    // Both bodies drift with the world current (locomotion adds it to this one's move).
    let current = if world.current.is_finite() {
        world.current
    } else {
        Vec3::ZERO
    };
    // Inside the world before parting from the others: parting then moves along a wall of the
    // world, where straight out of the wall would be undone by the clamp below.
    *pos = world.bounds.closest_point(*pos);
    for p in percepts {
        let Source::Agent(j) = p.source() else {
            continue;
        };
        // Same-species bodies keep a body width apart; any two keep apart by the smaller body
        // of the two (a predator still reaches its prey: catches reach further than that).
        let apart = match p.category() {
            Category::Kin | Category::Mate => width,
            _ => width.min(p.size),
        };
        // Where the other is heading this tick, not where it was: two fish swimming at each
        // other close more than a body width in one tick and would pass through each other.
        // (The other agents are out of the world during the pass: perception's copy of them.)
        let v = perception.velocity(j as usize).unwrap_or(Vec3::ZERO);
        let there = world
            .bounds
            .closest_point(me.pos + p.offset + (v + current) * dt);
        // Apart by the whole distance; only the way they part keeps to the walls (a body on
        // the floor with kin straight above is not overlapping it, however close they are
        // along the floor).
        let dist = (*pos - there).length();
        if dist >= apart || dist.is_nan() {
            continue;
        }
        let sep = along_walls(&world.bounds, *pos, *pos - there);
        let away = match sep.try_normalize() {
            Some(d) if sep.length() > 1e-4 => d,
            _ => {
                let left = along_walls(&world.bounds, *pos, crate::frame::left(me.yaw))
                    .try_normalize()
                    .unwrap_or(Vec3::Y);
                if i < j as usize {
                    left
                } else {
                    -left
                }
            }
        };
        *pos += away * (0.5 * (apart - dist));
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

/// `v` without the parts that point out of the world through a wall `pos` lies on.
fn along_walls(bounds: &crate::world::Aabb, pos: Vec3, v: Vec3) -> Vec3 {
    let mut v = v;
    for k in 0..3 {
        if (pos[k] <= bounds.min[k] && v[k] < 0.0) || (pos[k] >= bounds.max[k] && v[k] > 0.0) {
            v[k] = 0.0;
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::index::Grid;
    use crate::perception::{Relations, SenseParams};
    use crate::world::SpeciesId;
    use crate::world::{Aabb, AgentId, Anim, Attributes, Drives, ForwardCache, Mind, Rng};

    fn fish(id: u32, pos: Vec3) -> Agent {
        Agent {
            id: AgentId(id),
            species: SpeciesId(0),
            pos,
            prev_pos: pos,
            yaw: 0.0,
            pitch: 0.0,
            speed: 0.0,
            yaw_rate: 0.0,
            pitch_rate: 0.0,
            size: Vec3::new(0.4, 0.4, 1.0),
            drives: Drives::default(),
            attrs: Attributes::default(),
            mind: Mind::new(0, 0),
            anim: Anim::default(),
            rng: Rng::new(0, id as u64),
            memory: Default::default(),
            inbox: crate::world::Inbox::Empty,
            forward_cache: ForwardCache::NONE,
        }
    }

    /// Where agent 0 of a world with agents at `at` ends the tick, not having moved.
    fn settled(at: &[Vec3]) -> Vec3 {
        let mut w = World::new(Aabb::new(Vec3::ZERO, Vec3::splat(20.0)), 0.1, 1);
        w.agents = at
            .iter()
            .enumerate()
            .map(|(k, &p)| fish(k as u32, p))
            .collect();
        let mut rel = Relations::new(1);
        rel.set(0, 0, Some(Category::Kin));
        let sense = SenseParams {
            vision_radius: 8.0,
            vision_half_angle: std::f32::consts::PI,
            smell_radius: 0.0,
            occlusion: false,
            ..SenseParams::default()
        };
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 8.0, w.agents.iter().map(|a| a.pos));
        let mut p = Perception::new();
        p.run(&w, &ag, &Grid::new(), &[sense], &rel);
        assert_eq!(p.percepts(0).len(), at.len() - 1);
        let mut pos = w.agents[0].pos;
        keep_solid(&mut pos, 0, &w.agents[0], &p.percepts(0), &w, &p);
        pos
    }

    #[test]
    fn a_body_on_the_floor_parts_only_from_kin_it_overlaps() {
        let floor = Vec3::new(10.0, 0.0, 10.0);
        // Kin straight above, well clear of it: nothing to part from (a body on the floor
        // used to measure the gap along the floor only, and stepped aside).
        assert_eq!(settled(&[floor, floor + Vec3::new(0.0, 3.0, 0.0)]), floor);
        assert_eq!(settled(&[floor, floor + Vec3::new(0.1, 2.0, 0.0)]), floor);
        // Kin overlapping it above: it cannot go down, so it steps aside along the floor.
        let moved = settled(&[floor, floor + Vec3::new(0.0, 0.1, 0.0)]);
        assert_eq!(moved.y, 0.0);
        assert!((moved - floor).length() > 0.1, "{moved}");
        // Overlapping kin beside it on the floor: straight apart, along the floor.
        let moved = settled(&[floor, floor + Vec3::new(0.2, 0.0, 0.0)]);
        assert!(
            moved.x < floor.x && moved.y == 0.0 && moved.z == floor.z,
            "{moved}"
        );
        // In open water, kin clear of it leave it where it is.
        let mid = Vec3::splat(10.0);
        assert_eq!(settled(&[mid, mid + Vec3::new(0.0, 3.0, 0.0)]), mid);
    }
}
