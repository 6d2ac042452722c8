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
//!
//! On a grid ([`member_paths_on`]) one rule keeps the slots out of walls, an engine reading the
//! source leaves open:
//! - **A transition starts where the new formation fits.** The leg into a transition is where
//!   the source interpolates; that is right going into a narrow pass (the narrow formation fits
//!   where the leg starts), but coming out of one the leg into the transition runs inside the pass,
//!   and the wide formation would start spreading between its walls. So when the new formation
//!   does not fit at the key point before the transition (leader there, facing along the leg), the
//!   members hold the old formation up to the transition and interpolate over the leg after it:
//!   the wide formation is restored only after the pass.
//! - **A member's leg must be walkable** ([`leg_passable`], [`blocked_per_leg`]): the planner
//!   ([`crate::formation`]) narrows the formation where a follower's straight way from one
//!   waypoint to the next crosses a blocked cell, and counts such a follower out of its slot.
//! - **Not applied: drawing a slot inside a wall in toward the leader** ([`draw_in`], kept and
//!   tested). Moving the waypoint to the last free point before the wall made members walk into
//!   blocked cells on the way to it (7–9 blocked steps on `tests/squad_runtime.rs`'s wall, none
//!   without it): a waypoint must be reachable along the leg, not just free.
//!
//! [`member_paths`] is the source's form, the formation function alone.

use super::shape::Formation;
use super::smooth::KeyPoint;
use crate::terrain::CostGrid;
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
            let speed_factors = speed_factors(keys, &waypoints);
            MemberPath {
                member: m,
                waypoints,
                speed_factors,
            }
        })
        .collect()
}

/// Every member's path on `grid`: [`member_paths`] with a widening transition interpolated over
/// the leg after it where the new formation does not fit before it ([`held_formations`]).
pub fn member_paths_on(
    grid: &CostGrid,
    keys: &[KeyPoint],
    formations: &[Formation],
    leader: usize,
) -> Vec<MemberPath> {
    let headings = key_headings(keys);
    let held = held_formations(grid, keys, formations, leader, &headings);
    member_paths_held(keys, formations, leader, &headings, &held)
}

/// Every member's path with the formation `held[j]` at key point `j`, facing `headings[j]`.
pub fn member_paths_held(
    keys: &[KeyPoint],
    formations: &[Formation],
    leader: usize,
    headings: &[Vec2],
    held: &[usize],
) -> Vec<MemberPath> {
    let members = formations.first().map_or(0, Formation::len);
    (0..members)
        .map(|m| {
            let waypoints: Vec<Vec2> = keys
                .iter()
                .zip(headings)
                .zip(held)
                .map(|((k, &h), &f)| formations[f].world_slot(m, leader, k.pos, h))
                .collect();
            let speed_factors = speed_factors(keys, &waypoints);
            MemberPath {
                member: m,
                waypoints,
                speed_factors,
            }
        })
        .collect()
}

/// Samples per cell with which [`leg_passable`] walks a leg.
pub const LEG_SAMPLES_PER_CELL: f32 = 4.0;

/// Whether a member walking straight from `a` to `b` stays on free cells of `grid`: both ends
/// inside the grid and free, and the segment sampled [`LEG_SAMPLES_PER_CELL`] times a cell.
pub fn leg_passable(grid: &CostGrid, a: Vec2, b: Vec2) -> bool {
    let free = |p: Vec2| {
        grid.cell_of(p)
            .is_some_and(|c| !grid.blocked[grid.index(c)])
    };
    if !(free(a) && free(b)) {
        return false;
    }
    let n = ((a.distance(b) * LEG_SAMPLES_PER_CELL / grid.cell_size).ceil() as usize).max(1);
    (1..n).all(|s| free(a.lerp(b, s as f32 / n as f32)))
}

/// Per leg, how many followers (members but `leader`) cross a blocked cell on it.
pub fn blocked_per_leg(grid: &CostGrid, paths: &[MemberPath], leader: usize) -> Vec<usize> {
    let legs = paths
        .first()
        .map_or(0, |p| p.waypoints.len().saturating_sub(1));
    (0..legs)
        .map(|j| {
            paths
                .iter()
                .filter(|p| p.member != leader)
                .filter(|p| !leg_passable(grid, p.waypoints[j], p.waypoints[j + 1]))
                .count()
        })
        .collect()
}

/// Per key point, the formation the members' slots take there: the key point's own, except at a
/// transition whose new formation does not fit at the key point before it (leader there, facing
/// along the leg) and is held over the next leg: there the old one, so that the members change
/// over the leg after the transition.
pub fn held_formations(
    grid: &CostGrid,
    keys: &[KeyPoint],
    formations: &[Formation],
    leader: usize,
    headings: &[Vec2],
) -> Vec<usize> {
    (0..keys.len())
        .map(|j| {
            let to = keys[j].formation;
            if j == 0 || j + 1 >= keys.len() {
                return to;
            }
            let from = keys[j - 1].formation;
            let defer = from != to
                && keys[j + 1].formation == to
                && !fits(
                    grid,
                    &formations[to],
                    leader,
                    keys[j - 1].pos,
                    headings[j - 1],
                );
            if defer {
                from
            } else {
                to
            }
        })
        .collect()
}

/// Whether every slot of `formation` but the leader's is on a free cell of `grid`, the leader
/// at `pos` facing `heading`.
pub fn fits(
    grid: &CostGrid,
    formation: &Formation,
    leader: usize,
    pos: Vec2,
    heading: Vec2,
) -> bool {
    (0..formation.len()).filter(|&m| m != leader).all(|m| {
        let p = formation.world_slot(m, leader, pos, heading);
        grid.cell_of(p)
            .is_some_and(|c| !grid.blocked[grid.index(c)])
    })
}

/// `slot` when it is on a free cell; otherwise the farthest point from `leader` toward `slot`
/// before the first blocked cell, sampled every quarter cell (the leader's point when the first
/// sample is already blocked).
pub fn draw_in(grid: &CostGrid, leader: Vec2, slot: Vec2) -> Vec2 {
    let free = |p: Vec2| {
        grid.cell_of(p)
            .is_some_and(|c| !grid.blocked[grid.index(c)])
    };
    if free(slot) {
        return slot;
    }
    let steps = (leader.distance(slot) / (0.25 * grid.cell_size)).ceil() as usize;
    let mut last = leader;
    for s in 1..=steps {
        let p = leader.lerp(slot, s as f32 / steps as f32);
        if !free(p) {
            break;
        }
        last = p;
    }
    last
}

/// Per leg: the member's leg length over the leader's (1 where the leader does not move).
fn speed_factors(keys: &[KeyPoint], waypoints: &[Vec2]) -> Vec<f32> {
    keys.windows(2)
        .zip(waypoints.windows(2))
        .map(|(l, w)| {
            let lead = l[0].pos.distance(l[1].pos);
            if lead > 0.0 {
                w[0].distance(w[1]) / lead
            } else {
                1.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formation::shape::FormationShape;
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
            Formation::new(&FormationShape::Wedge, 3, 2.0).unwrap(),
            Formation::new(&FormationShape::Column, 3, 2.0).unwrap(),
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

    /// 30 × 11 open cells with a pass one row high (row 5) through walls from column 10 to 19.
    fn pass_grid() -> CostGrid {
        let mut g = CostGrid::open(30, 11, 1.0, Vec2::ZERO);
        for c in 10..20 {
            for r in (0..11).filter(|&r| r != 5) {
                let i = g.index(Cell::new(c, r));
                g.blocked[i] = true;
            }
        }
        g
    }

    fn free(g: &CostGrid, p: Vec2) -> bool {
        g.cell_of(p).is_some_and(|c| !g.blocked[g.index(c)])
    }

    #[test]
    fn the_wide_formation_is_restored_only_after_the_pass() {
        let g = pass_grid();
        let f = [
            Formation::new(&FormationShape::Line, 3, 1.0).unwrap(),
            Formation::new(&FormationShape::Column, 3, 1.0).unwrap(),
        ];
        // Line → column at the entrance (10, 5), column → line at the exit (20, 5).
        let keys = [
            kp(2.5, 5.5, 0, 0),
            kp(10.5, 5.5, 1, 8),
            kp(20.5, 5.5, 0, 18),
            kp(27.5, 5.5, 0, 25),
        ];
        let h = key_headings(&keys);
        // Entrance: the column fits at (2.5, 5.5) (slots (1.5, 5.5), (0.5, 5.5)): changed on the
        // leg into it. Exit: the line does not fit at the entrance (slots on rows 4 and 6 of
        // column 10): the column is held up to the exit and the line taken on the leg after.
        assert_eq!(held_formations(&g, &keys, &f, 0, &h), vec![0, 1, 1, 0]);
        let paths = member_paths_on(&g, &keys, &f, 0);
        for p in &paths[1..] {
            let m = p.member;
            assert_eq!(p.waypoints[2], f[1].world_slot(m, 0, keys[2].pos, h[2]));
            assert_eq!(p.waypoints[3], f[0].world_slot(m, 0, keys[3].pos, h[3]));
            // Inside the pass every member stays on row 5.
            for s in 0..=20 {
                let t = s as f32 / 20.0;
                assert!(free(&g, p.position_at(1, t)), "member {m} at t = {t}");
            }
        }
        // Member 1 (the line's right slot) on leg 2 goes from (19.5, 5.5) to (27.5, 6.5).
        assert_eq!(paths[1].waypoints[2], Vec2::new(19.5, 5.5));
        assert_eq!(paths[1].waypoints[3], Vec2::new(27.5, 6.5));
        // Speed factor of that leg: √(8² + 1²) / 7 = 8.0623 / 7 = 1.15175.
        assert!((paths[1].speed_factors[2] - 1.151_75).abs() < 1e-4);
        // The source's form interpolates inside the pass: halfway along leg 1 member 1 is at the
        // mean of (9.5, 5.5) and (20.5, 6.5), (15, 6), a wall cell.
        let plain = member_paths(&keys, &f, 0);
        assert_eq!(plain[1].position_at(1, 0.5), Vec2::new(15.0, 6.0));
        assert!(!free(&g, Vec2::new(15.0, 6.0)));
        // With nothing in the way, the two forms agree.
        let open = CostGrid::open(30, 11, 1.0, Vec2::ZERO);
        assert_eq!(member_paths_on(&open, &keys, &f, 0), plain);
    }

    #[test]
    fn a_slot_inside_a_wall_is_drawn_in_toward_the_leader() {
        let mut g = CostGrid::open(10, 10, 1.0, Vec2::ZERO);
        for r in 0..10 {
            for c in 7..10 {
                let i = g.index(Cell::new(c, r));
                g.blocked[i] = true;
            }
        }
        let leader = Vec2::new(2.5, 5.5);
        // Free slot: kept.
        assert_eq!(
            draw_in(&g, leader, Vec2::new(4.5, 6.5)),
            Vec2::new(4.5, 6.5)
        );
        // (8.5, 5.5) is in the wall: 6 m in 24 quarter-cell samples; x = 2.5 + 0.25·s reaches
        // column 7 at s = 18 (x = 7.0), so the last free sample is s = 17, x = 6.75.
        assert_eq!(
            draw_in(&g, leader, Vec2::new(8.5, 5.5)),
            Vec2::new(6.75, 5.5)
        );
        // Off the grid to the west: from x = 2.6, 6 m in 24 samples; x = 2.6 − 0.25·s is 0.1 at
        // s = 10 (column 0) and off the grid at s = 11.
        let p = draw_in(&g, Vec2::new(2.6, 5.5), Vec2::new(-3.4, 5.5));
        assert!((p - Vec2::new(0.1, 5.5)).length() < 1e-5, "{p}");
        // The first sample already blocked: the leader's point.
        let by_wall = Vec2::new(6.9, 5.5);
        assert_eq!(draw_in(&g, by_wall, Vec2::new(9.5, 5.5)), by_wall);
        // A line of 3 facing north fits at (4.5, 5.5); at (6.5, 5.5) its right slot (7.5, 5.5) is
        // in the wall.
        let f = [Formation::new(&FormationShape::Line, 3, 1.0).unwrap()];
        assert!(fits(
            &g,
            &f[0],
            0,
            Vec2::new(4.5, 5.5),
            Vec2::new(0.0, -1.0)
        ));
        assert!(!fits(
            &g,
            &f[0],
            0,
            Vec2::new(6.5, 5.5),
            Vec2::new(0.0, -1.0)
        ));
    }

    /// 10 × 3 cells of 2 m with cell (2, 1) (x 4–6, z 2–4) blocked.
    fn post_grid() -> CostGrid {
        let mut g = CostGrid::open(10, 3, 2.0, Vec2::ZERO);
        let i = g.index(Cell::new(2, 1));
        g.blocked[i] = true;
        g
    }

    #[test]
    fn a_leg_is_walkable_when_its_ends_and_samples_are_on_free_cells() {
        let g = post_grid();
        // Row 0 (z = 1) is open end to end.
        assert!(leg_passable(&g, Vec2::new(1.0, 1.0), Vec2::new(19.0, 1.0)));
        // Row 1 (z = 3): 18 m, ⌈18 · 4 / 2⌉ = 36 samples half a metre apart; x = 4.5 (sample 7)
        // is in the blocked cell. (Three samples, at x = 7 and 13, would miss it.)
        assert!(!leg_passable(&g, Vec2::new(1.0, 3.0), Vec2::new(19.0, 3.0)));
        // A leg shorter than a sample step has no inner sample: its ends decide.
        let (blocked, free) = (Vec2::new(5.9, 2.1), Vec2::new(5.9, 1.9));
        assert!(!leg_passable(&g, blocked, free));
        assert!(!leg_passable(&g, free, blocked));
        assert!(leg_passable(&g, free, Vec2::new(5.9, 1.5)));
        // An end off the grid, or not a number.
        assert!(!leg_passable(&g, Vec2::new(1.0, 1.0), Vec2::new(21.0, 1.0)));
        assert!(!leg_passable(&g, Vec2::new(-0.5, 1.0), Vec2::new(1.0, 1.0)));
        assert!(!leg_passable(
            &g,
            Vec2::new(1.0, 1.0),
            Vec2::new(f32::NAN, 1.0)
        ));
        // Standing still on a free cell is walkable.
        assert!(leg_passable(&g, free, free));
    }

    #[test]
    fn blocked_legs_are_counted_per_leg_without_the_leader() {
        let g = post_grid();
        let path = |member: usize, w: [(f32, f32); 3]| MemberPath {
            member,
            waypoints: w.iter().map(|&(x, z)| Vec2::new(x, z)).collect(),
            speed_factors: vec![1.0, 1.0],
        };
        let paths = [
            // Leg 0 along row 1 through the blocked cell; leg 1 north along x = 9.
            path(0, [(1.0, 3.0), (9.0, 3.0), (9.0, 1.0)]),
            path(1, [(1.0, 1.0), (9.0, 1.0), (19.0, 1.0)]),
            // Leg 0 along row 2; leg 1 ends in the blocked cell.
            path(2, [(1.0, 5.0), (5.0, 5.0), (5.0, 3.0)]),
        ];
        assert_eq!(blocked_per_leg(&g, &paths, 0), vec![0, 1]);
        assert_eq!(blocked_per_leg(&g, &paths, 1), vec![1, 1]);
        assert_eq!(blocked_per_leg(&g, &paths, 2), vec![1, 0]);
        assert!(blocked_per_leg(&g, &[], 0).is_empty());
        let one = [MemberPath {
            member: 1,
            waypoints: vec![Vec2::new(5.0, 3.0)],
            speed_factors: Vec::new(),
        }];
        assert!(blocked_per_leg(&g, &one, 0).is_empty());
    }

    #[test]
    fn a_fine_grid_is_sampled_by_its_own_cell_size() {
        // Cells of 0.25 m, cell (5, 0) (x 1.25–1.5) blocked: a 2 m leg along z = 0.1 takes
        // ⌈2 · 4 / 0.25⌉ = 32 samples 1/16 m apart and finds it (two samples, at x = 0 and 1
        // and 2, would not).
        let mut g = CostGrid::open(12, 2, 0.25, Vec2::ZERO);
        let i = g.index(Cell::new(5, 0));
        g.blocked[i] = true;
        assert!(!leg_passable(
            &g,
            Vec2::new(0.01, 0.1),
            Vec2::new(2.01, 0.1)
        ));
        assert!(leg_passable(&g, Vec2::new(0.01, 0.4), Vec2::new(2.01, 0.4)));
    }

    #[test]
    fn a_widening_is_deferred_only_when_it_lasts_and_does_not_fit_before_it() {
        let g = pass_grid();
        let f = [
            Formation::new(&FormationShape::Line, 3, 1.0).unwrap(),
            Formation::new(&FormationShape::Column, 3, 1.0).unwrap(),
        ];
        let held = |keys: &[KeyPoint]| held_formations(&g, keys, &f, 0, &key_headings(keys));
        // The last key point takes its own formation, a change there included.
        let keys = [kp(2.5, 5.5, 0, 0), kp(5.5, 5.5, 0, 3), kp(8.5, 5.5, 1, 6)];
        assert_eq!(held(&keys), vec![0, 0, 1]);
        // The column at (10.5, 5.5) is changed back at once at (20.5, 5.5): not a lasting
        // change, taken as planned, although the column does not fit at (0.5, 5.5) (its slots
        // are off the grid to the west). The line from (20.5, 5.5) on lasts and does not fit at
        // (10.5, 5.5): deferred.
        let keys = [
            kp(0.5, 5.5, 0, 0),
            kp(10.5, 5.5, 1, 10),
            kp(20.5, 5.5, 0, 20),
            kp(27.5, 5.5, 0, 27),
        ];
        assert_eq!(held(&keys), vec![0, 1, 1, 0]);
        // The fit is tested facing along the leg into the change: east from (5.5, 5.5) the
        // line's slots are (5.5, 6.5) and (5.5, 4.5), the latter blocked here; facing south
        // (the next legs) they would be (4.5, 5.5) and (6.5, 5.5), free.
        let mut open = CostGrid::open(20, 20, 1.0, Vec2::ZERO);
        let i = open.index(Cell::new(5, 4));
        open.blocked[i] = true;
        let col_line = [f[1].clone(), f[0].clone()];
        let keys = [
            kp(5.5, 5.5, 0, 0),
            kp(10.5, 5.5, 1, 5),
            kp(10.5, 10.5, 1, 10),
            kp(10.5, 15.5, 1, 15),
        ];
        let h = key_headings(&keys);
        assert_eq!(
            held_formations(&open, &keys, &col_line, 0, &h),
            vec![0, 0, 1, 1]
        );
        open.blocked[i] = false;
        assert_eq!(
            held_formations(&open, &keys, &col_line, 0, &h),
            vec![0, 1, 1, 1]
        );
    }

    #[test]
    fn a_slot_is_drawn_in_by_quarters_of_its_grid_cells() {
        // Cells of 2 m, blocked from x = 14: from (5, 11) toward (17, 11) the samples are 0.5 m
        // apart; x = 14 is the first blocked one (sample 18), so the slot stops at 13.5.
        let mut g = CostGrid::open(10, 10, 2.0, Vec2::ZERO);
        for r in 0..10 {
            for c in 7..10 {
                let i = g.index(Cell::new(c, r));
                g.blocked[i] = true;
            }
        }
        assert_eq!(
            draw_in(&g, Vec2::new(5.0, 11.0), Vec2::new(17.0, 11.0)),
            Vec2::new(13.5, 11.0)
        );
    }

    #[test]
    fn a_leg_where_the_leader_stands_still_has_speed_factor_one() {
        let f = [Formation::new(&FormationShape::Line, 3, 1.0).unwrap()];
        let keys = [kp(5.5, 5.5, 0, 0), kp(5.5, 5.5, 0, 0)];
        let paths = member_paths(&keys, &f, 0);
        assert!(paths.iter().all(|p| p.speed_factors == vec![1.0]));
    }

    #[test]
    fn single_key_point_faces_north() {
        let f = [Formation::new(&FormationShape::Line, 3, 1.0).unwrap()];
        let paths = member_paths(&[kp(5.0, 5.0, 0, 0)], &f, 0);
        assert_eq!(paths[1].waypoints, vec![Vec2::new(6.0, 5.0)]);
        assert!(paths[1].speed_factors.is_empty());
    }
}
