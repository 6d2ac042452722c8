//! Walking on the terrain (2.5D): after locomotion, a ground agent is put back on the surface,
//! its pitch follows the slope along its heading, and it never stands on a cell its species may
//! not enter (seed 004's terrain, seed 002's self-balancing frame: no roll, |pitch| < 90°).
//!
//! Not a tick stage: applied by the scenario layer right after the tick's world events, in agent
//! order, so the next tick starts from positions on the ground.

use crate::terrain::{CostGrid, Terrain};
use crate::world::Agent;
use glam::{Vec2, Vec3};

/// Pitch (rad, up positive) of a body facing `yaw` standing on the terrain at `(x, z)`: the
/// slope of the surface along the heading, within `limit` (itself kept inside ±90°).
pub fn slope_pitch(terrain: &Terrain, x: f32, z: f32, yaw: f32, limit: f32) -> f32 {
    let g = terrain.gradient_at(x, z);
    let f = crate::frame::forward(yaw, 0.0);
    let rise = g.x * f.x + g.y * f.z;
    let limit = limit.abs().min(crate::frame::PITCH_LIMIT);
    crate::math::atan(rise).clamp(-limit, limit)
}

/// What [`settle`] did to one agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Settled {
    /// The agent's cell is free; only height and pitch were set.
    Free,
    /// The step ended on a blocked cell and was cut back: the agent slid along the blocked
    /// cell's side or stayed where it was. This is a collision with the terrain.
    Blocked,
}

/// Puts `agent` on the ground: if `grid` is given and the step from `agent.prev_pos` ended on a
/// blocked cell (or off the grid), the step is cut back (keeping the X or the Z part when that
/// one is free, else staying put); then its height is the terrain's and its pitch the slope's.
pub fn settle(
    agent: &mut Agent,
    terrain: &Terrain,
    grid: Option<&CostGrid>,
    pitch_limit: f32,
) -> Settled {
    let mut result = Settled::Free;
    if let Some(g) = grid {
        let free = |p: Vec2| super::route::free_at(g, p);
        let (now, before) = (
            Vec2::new(agent.pos.x, agent.pos.z),
            Vec2::new(agent.prev_pos.x, agent.prev_pos.z),
        );
        if !free(now) {
            result = Settled::Blocked;
            let slide_x = Vec2::new(now.x, before.y);
            let slide_z = Vec2::new(before.x, now.y);
            let to = [slide_x, slide_z]
                .into_iter()
                .find(|&p| free(p))
                .unwrap_or(before);
            agent.pos.x = to.x;
            agent.pos.z = to.y;
        }
    }
    agent.pos = Vec3::new(
        agent.pos.x,
        terrain.height_at(agent.pos.x, agent.pos.z),
        agent.pos.z,
    );
    agent.pitch = slope_pitch(terrain, agent.pos.x, agent.pos.z, agent.yaw, pitch_limit);
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{AgentId, Anim, Attributes, Drives, Mind, Rng, SpeciesId};

    fn agent(prev: Vec3, pos: Vec3, yaw: f32) -> Agent {
        Agent {
            id: AgentId(0),
            species: SpeciesId(0),
            pos,
            prev_pos: prev,
            yaw,
            pitch: 0.7,
            speed: 1.0,
            yaw_rate: 0.0,
            pitch_rate: 0.0,
            size: Vec3::ONE,
            drives: Drives::default(),
            attrs: Attributes::default(),
            mind: Mind::new(0, 0),
            anim: Anim::default(),
            rng: Rng::new(1, 1),
            memory: Default::default(),
            inbox: crate::world::Inbox::Empty,
            forward_cache: crate::world::ForwardCache::NONE,
        }
    }

    /// 4×4 cells of 1 m, rising 0.5 m per cell eastwards.
    fn ramp() -> Terrain {
        let h = (0..16).map(|i| 0.5 * (i % 4) as f32).collect();
        Terrain::from_heights(4, 4, 1.0, Vec2::ZERO, h)
    }

    #[test]
    fn agents_stand_on_the_surface_pitched_along_the_slope() {
        let t = ramp();
        // Facing east (yaw −90°: positive yaw turns toward −X) the body climbs 0.5 per metre.
        let mut a = agent(
            Vec3::new(1.5, 9.0, 1.5),
            Vec3::new(2.0, 9.0, 1.5),
            -90f32.to_radians(),
        );
        assert_eq!(settle(&mut a, &t, None, 1.2), Settled::Free);
        assert!((a.pos.y - 0.75).abs() < 1e-6, "{}", a.pos.y);
        assert!(
            (a.pitch - crate::math::atan(0.5)).abs() < 1e-5,
            "{}",
            a.pitch
        );
        // Facing south (+Z) the ground is level along the heading.
        let mut a = agent(Vec3::new(1.5, 0.0, 1.5), Vec3::new(2.0, 0.0, 1.5), 0.0);
        settle(&mut a, &t, None, 1.2);
        assert!(a.pitch.abs() < 1e-6);
        // The limit holds.
        let mut a = agent(
            Vec3::new(1.5, 0.0, 1.5),
            Vec3::new(2.0, 0.0, 1.5),
            -90f32.to_radians(),
        );
        settle(&mut a, &t, None, 0.1);
        assert_eq!(a.pitch, 0.1);
    }

    #[test]
    fn steps_onto_blocked_cells_are_cut_back() {
        let t = ramp();
        let mut g = CostGrid::open(4, 4, 1.0, Vec2::ZERO);
        g.blocked[2 * 4 + 2] = true; // cell (2, 2)
                                     // From (1.5, 1.5) to (2.5, 2.5): the diagonal step lands on (2, 2); sliding along X
                                     // keeps (2.5, 1.5), which is free.
        let mut a = agent(Vec3::new(1.5, 0.0, 1.5), Vec3::new(2.5, 0.0, 2.5), 0.0);
        assert_eq!(settle(&mut a, &t, Some(&g), 1.2), Settled::Blocked);
        assert_eq!((a.pos.x, a.pos.z), (2.5, 1.5));
        assert!((a.pos.y - t.height_at(2.5, 1.5)).abs() < 1e-6);
        // Off the grid counts as blocked; with both slides blocked the agent stays.
        g.blocked[4 + 2] = true; // (2, 1)
        g.blocked[2 * 4 + 1] = true; // (1, 2)
        let mut a = agent(Vec3::new(1.5, 0.0, 1.5), Vec3::new(2.5, 0.0, 2.5), 0.0);
        assert_eq!(settle(&mut a, &t, Some(&g), 1.2), Settled::Blocked);
        assert_eq!((a.pos.x, a.pos.z), (1.5, 1.5));
        let mut a = agent(Vec3::new(0.5, 0.0, 0.5), Vec3::new(-0.5, 0.0, 0.5), 0.0);
        assert_eq!(settle(&mut a, &t, Some(&g), 1.2), Settled::Blocked);
        assert_eq!((a.pos.x, a.pos.z), (0.5, 0.5));
        let mut a = agent(Vec3::new(0.5, 0.0, 0.5), Vec3::new(0.7, 0.0, 0.9), 0.0);
        assert_eq!(settle(&mut a, &t, Some(&g), 1.2), Settled::Free);
    }
}
