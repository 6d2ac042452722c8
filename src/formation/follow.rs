//! Follower paths from the key-point and transition tables, seed 004 ("generate the paths of the
//! non-leader members").
//!
//! Not a tick stage: path planning, last step. Each member gets one waypoint per key point, so
//! leg `j` of every member runs while the leader covers its leg `j`. At a key point the member's
//! waypoint is the formation function of the formation held there, applied to the leader's
//! position and heading (the heading of the leg leaving the key point; the last key point keeps
//! the heading of the leg into it). Where the formation changes, the leg into the transition
//! starts at the member's slot in the old formation and ends at its slot in the new one: moving
//! straight along it is the linear interpolation between the two, evaluated at the leader's
//! position. Each leg carries a speed factor, the member's distance over the leader's, so that
//! members moving at `factor × leader speed` arrive together and wait little.

use super::shape::Formation;
use super::smooth::KeyPoint;
use glam::Vec2;
use serde::{Deserialize, Serialize};

/// The heading a team faces when its plan has a single key point (start = goal): north (−Z).
pub const DEFAULT_HEADING: Vec2 = Vec2::new(0.0, -1.0);

/// One member's planned path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MemberPath {
    /// The member's index in the team.
    pub member: usize,
    /// World `(x, z)`, one per key point.
    pub waypoints: Vec<Vec2>,
    /// Per leg (`waypoints.len() - 1` of them): the member's leg length over the leader's.
    pub speed_factors: Vec<f32>,
}

impl MemberPath {
    /// Where the member is a fraction `t ∈ [0, 1]` along leg `leg` (the leader being the same
    /// fraction along its own leg).
    pub fn position_at(&self, leg: usize, t: f32) -> Vec2 {
        self.waypoints[leg].lerp(self.waypoints[leg + 1], t.clamp(0.0, 1.0))
    }
}

/// The heading the team faces at each key point.
pub fn key_headings(keys: &[KeyPoint]) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = keys
        .windows(2)
        .map(|w| (w[1].pos - w[0].pos).normalize_or(DEFAULT_HEADING))
        .collect();
    out.push(out.last().copied().unwrap_or(DEFAULT_HEADING));
    out
}

/// Every member's path (the leader's is the key points themselves), indexed by member.
pub fn member_paths(keys: &[KeyPoint], formations: &[Formation], leader: usize) -> Vec<MemberPath> {
    let headings = key_headings(keys);
    let members = formations.first().map_or(0, Formation::len);
    (0..members)
        .map(|m| {
            let waypoints: Vec<Vec2> = keys
                .iter()
                .zip(&headings)
                .map(|(k, &h)| formations[k.formation].world_slot(m, leader, k.pos, h))
                .collect();
            let speed_factors = keys
                .windows(2)
                .zip(waypoints.windows(2))
                .map(|(l, w)| {
                    let lead = l[0].pos.distance(l[1].pos);
                    if lead > 0.0 {
                        w[0].distance(w[1]) / lead
                    } else {
                        1.0
                    }
                })
                .collect();
            MemberPath {
                member: m,
                waypoints,
                speed_factors,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formation::shape::Shape;
    use crate::terrain::Cell;

    fn kp(x: f32, z: f32, formation: usize, i: usize) -> KeyPoint {
        KeyPoint {
            cell: Cell::new(x as usize, z as usize),
            pos: Vec2::new(x, z),
            formation,
            path_index: i,
        }
    }

    #[test]
    fn members_hold_slots_at_key_points_and_interpolate_at_transitions() {
        let f = [
            Formation::new(&Shape::Wedge, 3, 2.0).unwrap(),
            Formation::new(&Shape::Column, 3, 2.0).unwrap(),
        ];
        // East 10, then south 10 switching to a column, then east 10 back to the wedge.
        let keys = [
            kp(0.5, 0.5, 0, 0),
            kp(10.5, 0.5, 1, 10),
            kp(10.5, 10.5, 0, 20),
            kp(20.5, 10.5, 0, 30),
        ];
        let paths = member_paths(&keys, &f, 0);
        let h = key_headings(&keys);
        assert_eq!(h[0], Vec2::new(1.0, 0.0));
        assert_eq!(h[1], Vec2::new(0.0, 1.0));
        assert_eq!(h[3], Vec2::new(1.0, 0.0));
        for p in &paths {
            for (j, k) in keys.iter().enumerate() {
                assert_eq!(
                    p.waypoints[j],
                    f[k.formation].world_slot(p.member, 0, k.pos, h[j])
                );
            }
        }
        assert_eq!(
            paths[0].waypoints,
            keys.iter().map(|k| k.pos).collect::<Vec<_>>()
        );
        assert!(paths[0].speed_factors.iter().all(|&s| s == 1.0));
        // Leg 0 ends at a transition wedge → column: at t the member is the lerp between its wedge
        // slot and its column slot for the leader's position at t.
        for p in &paths[1..] {
            let m = p.member;
            for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
                let leader = keys[0].pos.lerp(keys[1].pos, t);
                let old = f[0].world_slot(m, 0, leader, h[0]);
                let new = f[1].world_slot(m, 0, leader, h[1]);
                let expected = old.lerp(new, t);
                assert!(
                    (p.position_at(0, t) - expected).length() < 1e-4,
                    "member {m} t {t}"
                );
            }
        }
        // Speed factors make every member finish each leg with the leader.
        for p in &paths {
            for (j, s) in p.speed_factors.iter().enumerate() {
                let lead = keys[j].pos.distance(keys[j + 1].pos);
                let own = p.waypoints[j].distance(p.waypoints[j + 1]);
                assert!((s * lead - own).abs() < 1e-4);
            }
        }
    }

    #[test]
    fn single_key_point_faces_north() {
        let f = [Formation::new(&Shape::Line, 3, 1.0).unwrap()];
        let paths = member_paths(&[kp(5.0, 5.0, 0, 0)], &f, 0);
        assert_eq!(paths[1].waypoints, vec![Vec2::new(6.0, 5.0)]);
        assert!(paths[1].speed_factors.is_empty());
    }
}
