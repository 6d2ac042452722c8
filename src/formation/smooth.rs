//! Leader-path smoothing into the key-point table and the formation-transition table, seed 004
//! ("Leader path optimisation").
//!
//! Not a tick stage: path planning, after the leader's A* path is found. The formation at each
//! path node is the widest formation of the team's list whose slots are all free there (the
//! formation vector of the source; only the primary when the formation may not change). From key
//! point `i` the smoother looks ahead to `k`, the first node where the formation changes (or the
//! goal), and tests the straight line `i → k`: every cell it touches must be free, and the
//! formation taken on every cell of the line (facing along it) must be the one of node `i` — up
//! to but not including `k` when `k` is a transition. If the test fails, `k = ⌊(i + k)/2⌋` and it
//! tests again; the next node (`k = i + 1`) is always accepted, being a valid A* step. When it
//! passes, `k` is the next key point, and a transition there goes into the transition table.

use super::astar::{dir_between, GridFormations, SlotOffsets};
use crate::terrain::{supercover, Cell, CostGrid};
use glam::Vec2;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// One row of the key-point table: a corner of the smoothed leader path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KeyPoint {
    /// Grid cell.
    pub cell: Cell,
    /// World `(x, z)` of the cell centre.
    pub pos: Vec2,
    /// Index into the team's formation list of the formation held at this point.
    pub formation: usize,
    /// Index of this point in the leader's A* path.
    pub path_index: usize,
}

/// One row of the formation-transition table: where the formation changes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FormationChange {
    /// Grid cell where the new formation holds.
    pub cell: Cell,
    /// World `(x, z)` of the cell centre.
    pub pos: Vec2,
    /// Formation before (index into the team's list).
    pub from: usize,
    /// Formation from here on.
    pub to: usize,
    /// Index of the key point at this place.
    pub key_index: usize,
}

/// The formation at each node of a leader path, with whether all its slots are free there.
/// The heading at node 0 is the first step's, at node `k > 0` the step into it.
pub fn formation_along(
    grid: &CostGrid,
    path: &[Cell],
    team: &GridFormations<'_>,
    may_change: bool,
) -> Vec<(usize, bool)> {
    formation_along_from(grid, path, team, may_change, &[])
}

/// [`formation_along`] where node `k` may only take formations from index `floor[k]` on (0 for
/// nodes past the end of `floor`): the narrowing of [`crate::formation`] where a member's way
/// crossed a wall.
pub fn formation_along_from(
    grid: &CostGrid,
    path: &[Cell],
    team: &GridFormations<'_>,
    may_change: bool,
    floor: &[usize],
) -> Vec<(usize, bool)> {
    (0..path.len())
        .map(|k| {
            let d = match k {
                0 if path.len() > 1 => dir_between(path[0], path[1]),
                0 => Some(6),
                _ => dir_between(path[k - 1], path[k]),
            }
            .expect("a leader path moves between adjacent cells");
            let first = floor.get(k).copied().unwrap_or(0);
            team.choose_from(grid, path[k], may_change, first, |j| {
                Cow::Borrowed(team.tables[j].dir(d))
            })
        })
        .collect()
}

/// Smooths `path` (with `along` from [`formation_along`]) into key points and transitions.
pub fn smooth(
    grid: &CostGrid,
    path: &[Cell],
    along: &[(usize, bool)],
    team: &GridFormations<'_>,
    may_change: bool,
) -> (Vec<KeyPoint>, Vec<FormationChange>) {
    smooth_from(grid, path, along, team, may_change, &[])
}

/// [`smooth`] with the per-node `floor` given to [`formation_along_from`]: a shortcut from node
/// `i` takes formations from `floor[i]` on along its line.
pub fn smooth_from(
    grid: &CostGrid,
    path: &[Cell],
    along: &[(usize, bool)],
    team: &GridFormations<'_>,
    may_change: bool,
    floor: &[usize],
) -> (Vec<KeyPoint>, Vec<FormationChange>) {
    assert_eq!(path.len(), along.len());
    let key = |k: usize| KeyPoint {
        cell: path[k],
        pos: grid.center_of(path[k]),
        formation: along[k].0,
        path_index: k,
    };
    let mut keys = vec![key(0)];
    let mut transitions = Vec::new();
    let last = path.len() - 1;
    let mut i = 0;
    while i < last {
        let change = (i + 1..=last)
            .find(|&k| along[k].0 != along[k - 1].0)
            .unwrap_or(last);
        let first = floor.get(i).copied().unwrap_or(0);
        let mut k = change;
        while k > i + 1 && !segment_holds(grid, path, along, team, may_change, first, i, k, change)
        {
            k = (i + k) / 2;
        }
        keys.push(key(k));
        if along[k].0 != along[k - 1].0 {
            transitions.push(FormationChange {
                cell: path[k],
                pos: grid.center_of(path[k]),
                from: along[k - 1].0,
                to: along[k].0,
                key_index: keys.len() - 1,
            });
        }
        i = k;
    }
    (keys, transitions)
}

/// The source's test of a shortcut `i → k`: clear line of sight, and the formation vector of
/// node `i` on every cell of the line (the transition cell itself excluded).
#[allow(clippy::too_many_arguments)]
fn segment_holds(
    grid: &CostGrid,
    path: &[Cell],
    along: &[(usize, bool)],
    team: &GridFormations<'_>,
    may_change: bool,
    first: usize,
    i: usize,
    k: usize,
    change: usize,
) -> bool {
    let (a, b) = (path[i], path[k]);
    if !grid.clear_line(a, b) {
        return false;
    }
    let heading = grid.center_of(b) - grid.center_of(a);
    let tables: Vec<Vec<(i32, i32)>> = team
        .formations
        .iter()
        .map(|f| SlotOffsets::for_heading(f, team.leader, team.cell_size, heading))
        .collect();
    let formation = along[i].0;
    // A shortcut may not keep the formation worse than the path it replaces.
    let full = along[i..k].iter().all(|&(_, full)| full);
    let is_transition = k == change && along[k].0 != along[k - 1].0;
    supercover(a, b, |c, r| {
        let cell = Cell::new(c as usize, r as usize);
        if is_transition && cell == b {
            return true;
        }
        let (j, fits) =
            team.choose_from(grid, cell, may_change, first, |j| Cow::Borrowed(&tables[j]));
        j == formation && (fits || !full)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formation::astar::{Planner, TaskClass, Weights};
    use crate::formation::shape::{Formation, FormationShape};
    use crate::terrain::SplitMix64;
    use proptest::prelude::*;

    fn random_grid(cols: usize, rows: usize, seed: u64, density: f32) -> CostGrid {
        let mut rng = SplitMix64::new(seed);
        let mut g = CostGrid::open(cols, rows, 1.0, Vec2::ZERO);
        for i in 0..cols * rows {
            g.blocked[i] = rng.next_f32() < density;
            g.cost[i] = 1.0 + (rng.next_f32() * 3.0).floor();
        }
        g
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]
        #[test]
        fn key_point_segments_never_cross_a_blocked_cell(
            cols in 3usize..40, rows in 3usize..40, seed in any::<u64>(), density in 0.0f32..0.4,
            k2 in prop_oneof![Just(0.0f32), Just(0.5), Just(0.9)], may_change in any::<bool>()
        ) {
            let mut grid = random_grid(cols, rows, seed, density);
            let (start, goal) = (Cell::new(0, rows / 2), Cell::new(cols - 1, rows / 3));
            let si = grid.index(start);
            grid.blocked[si] = false;
            let gi = grid.index(goal);
            grid.blocked[gi] = false;
            let f = [
                Formation::new(&FormationShape::Wedge, 5, 1.0).unwrap(),
                Formation::new(&FormationShape::Column, 5, 1.0).unwrap(),
            ];
            let team = GridFormations::new(&f, 0, 1.0);
            let Some(found) = Planner::new().search(&grid, start, goal, &team, Weights { k1: 1.0 - k2, k2, may_change, ..Weights::default() }) else {
                return Ok(());
            };
            let along = formation_along(&grid, &found.cells, &team, may_change);
            let (keys, transitions) = smooth(&grid, &found.cells, &along, &team, may_change);
            prop_assert_eq!(keys[0].cell, start);
            prop_assert_eq!(keys.last().unwrap().cell, goal);
            for w in keys.windows(2) {
                prop_assert!(w[0].path_index < w[1].path_index);
                prop_assert!(grid.clear_line(w[0].cell, w[1].cell), "{:?} → {:?}", w[0].cell, w[1].cell);
            }
            // Every change of formation along the path is a transition at a key point.
            let changes = (1..along.len()).filter(|&k| along[k].0 != along[k - 1].0).count();
            prop_assert_eq!(changes, transitions.len());
            for t in &transitions {
                prop_assert_eq!(keys[t.key_index].cell, t.cell);
                prop_assert_eq!(keys[t.key_index].formation, t.to);
            }
        }
    }

    #[test]
    fn the_first_node_faces_the_first_step_and_a_lone_node_faces_north() {
        // A line of 3 (spacing 1) with the leader on (1, 1) and cell (0, 1) blocked: facing east
        // its slots are (1, 2) and (1, 0), free; facing north they are (2, 1) and (0, 1).
        let mut grid = CostGrid::open(4, 3, 1.0, Vec2::ZERO);
        let i = grid.index(Cell::new(0, 1));
        grid.blocked[i] = true;
        let f = [Formation::new(&FormationShape::Line, 3, 1.0).unwrap()];
        let team = GridFormations::new(&f, 0, 1.0);
        let east = [Cell::new(1, 1), Cell::new(2, 1)];
        assert_eq!(
            formation_along(&grid, &east, &team, true),
            vec![(0, true), (0, true)]
        );
        assert_eq!(
            formation_along(&grid, &east[..1], &team, true),
            vec![(0, false)]
        );
    }

    #[test]
    fn a_transition_cell_is_exempt_from_the_old_formation_and_the_goal_is_not() {
        // A line of 3 (spacing 1) and a column; rows 1–3 open up to column 4, then row 2 only.
        // Heading east the line fits on columns 0–4 (slots on rows 1 and 3), the column from 5.
        let mut grid = CostGrid::open(10, 5, 1.0, Vec2::ZERO);
        for c in 0..10 {
            for r in 0..5 {
                let open = r == 2 || ((1..=3).contains(&r) && c <= 4);
                let i = grid.index(Cell::new(c, r));
                grid.blocked[i] = !open;
            }
        }
        let f = [
            Formation::new(&FormationShape::Line, 3, 1.0).unwrap(),
            Formation::new(&FormationShape::Column, 3, 1.0).unwrap(),
        ];
        let team = GridFormations::new(&f, 0, 1.0);
        let path: Vec<Cell> = (0..10).map(|c| Cell::new(c, 2)).collect();
        let along = formation_along(&grid, &path, &team, true);
        let held: Vec<usize> = along.iter().map(|a| a.0).collect();
        assert_eq!(held, vec![0, 0, 0, 0, 0, 1, 1, 1, 1, 1]);
        // The shortcut 0 → 5 ends on the transition, where the line does not fit: that cell is
        // not held to the line, so it is taken at once; then 5 → 9 in the column.
        let (keys, transitions) = smooth(&grid, &path, &along, &team, true);
        let at: Vec<usize> = keys.iter().map(|k| k.path_index).collect();
        assert_eq!(at, vec![0, 5, 9]);
        assert_eq!(transitions.len(), 1);
        assert_eq!((transitions[0].from, transitions[0].to), (0, 1));

        // The goal is held to the formation like any cell: east along row 5, then a diagonal
        // step to (5, 4). Facing along that step the line's slots (6, 5) and (4, 3) are free;
        // facing along the shortcut 0 → 4 ((4, −1)) they are (5, 5) and (5, 3), and (5, 3) is
        // blocked: refused, k = ⌊4/2⌋ = 2; then 2 → 4 ((2, −1)) is refused the same way, and
        // 2 → 3, 3 → 4 are single steps.
        let mut grid = CostGrid::open(8, 8, 1.0, Vec2::ZERO);
        let i = grid.index(Cell::new(5, 3));
        grid.blocked[i] = true;
        let line = [Formation::new(&FormationShape::Line, 3, 1.0).unwrap()];
        let team = GridFormations::new(&line, 0, 1.0);
        let path = [
            Cell::new(1, 5),
            Cell::new(2, 5),
            Cell::new(3, 5),
            Cell::new(4, 5),
            Cell::new(5, 4),
        ];
        let along = formation_along(&grid, &path, &team, true);
        assert!(along.iter().all(|&a| a == (0, true)));
        let (keys, _) = smooth(&grid, &path, &along, &team, true);
        let at: Vec<usize> = keys.iter().map(|k| k.path_index).collect();
        assert_eq!(at, vec![0, 2, 3, 4]);
    }

    #[test]
    fn a_shortcut_lays_the_formation_along_its_own_heading() {
        // A corridor one column wide (column 5) heading north, a column of 3: facing north its
        // followers stand south of the leader, in the corridor, on every cell of the shortcut
        // from the first node to the last, which is taken at once. (Facing any other way they
        // would stand in the walls.)
        let mut grid = CostGrid::open(11, 11, 1.0, Vec2::ZERO);
        for c in (0..11).filter(|&c| c != 5) {
            for r in 0..11 {
                let i = grid.index(Cell::new(c, r));
                grid.blocked[i] = true;
            }
        }
        let f = [Formation::new(&FormationShape::Column, 3, 1.0).unwrap()];
        let team = GridFormations::new(&f, 0, 1.0);
        let path: Vec<Cell> = (1..=8).rev().map(|r| Cell::new(5, r)).collect();
        let along = formation_along(&grid, &path, &team, true);
        assert!(along.iter().all(|&a| a == (0, true)));
        let (keys, transitions) = smooth(&grid, &path, &along, &team, true);
        let at: Vec<usize> = keys.iter().map(|k| k.path_index).collect();
        assert_eq!(at, vec![0, 7]);
        assert!(transitions.is_empty());
    }

    #[test]
    fn a_floor_narrows_the_nodes_it_covers_and_the_shortcuts_from_them() {
        // Open ground, a wedge and a column of 5 (spacing 1), the leader 6 cells east.
        let grid = CostGrid::open(30, 30, 1.0, Vec2::ZERO);
        let f = [
            Formation::new(&FormationShape::Wedge, 5, 1.0).unwrap(),
            Formation::new(&FormationShape::Column, 5, 1.0).unwrap(),
        ];
        let team = GridFormations::new(&f, 0, 1.0);
        let path: Vec<Cell> = (10..=16).map(|c| Cell::new(c, 10)).collect();
        let plain = formation_along(&grid, &path, &team, true);
        assert!(plain.iter().all(|&a| a == (0, true)));
        // Nodes 2–4 may only take the column; a floor past the list is the last formation; a
        // floor shorter than the path leaves the rest free.
        let floor = [0, 0, 1, 1, 7];
        let along = formation_along_from(&grid, &path, &team, true, &floor);
        let held: Vec<usize> = along.iter().map(|a| a.0).collect();
        assert_eq!(held, vec![0, 0, 1, 1, 1, 0, 0]);
        assert!(along.iter().all(|a| a.1));
        // When the formation may not change, only the primary.
        let strict = formation_along_from(&grid, &path, &team, false, &floor);
        assert!(strict.iter().all(|&a| a == (0, true)));
        // Smoothing: changes at nodes 2 and 5. From node 2 the shortcut to 5 holds only when
        // its line takes the column too (the floor of node 2); without it, the wedge fits on
        // the line's cells and the shortcut halves: 2 → ⌊(2 + 5)/2⌋ = 3, 3 → 4, 4 → 5.
        let (keys, transitions) = smooth_from(&grid, &path, &along, &team, true, &floor);
        let at: Vec<usize> = keys.iter().map(|k| k.path_index).collect();
        assert_eq!(at, vec![0, 2, 5, 6]);
        assert_eq!(
            transitions
                .iter()
                .map(|t| (t.from, t.to, t.key_index))
                .collect::<Vec<_>>(),
            vec![(0, 1, 1), (1, 0, 2)]
        );
        let (keys, _) = smooth(&grid, &path, &along, &team, true);
        let at: Vec<usize> = keys.iter().map(|k| k.path_index).collect();
        assert_eq!(at, vec![0, 2, 3, 4, 5, 6]);
    }

    #[test]
    fn open_ground_smooths_to_a_straight_line() {
        let grid = CostGrid::open(30, 30, 1.0, Vec2::ZERO);
        let f = [Formation::new(&FormationShape::Wedge, 5, 1.0).unwrap()];
        let team = GridFormations::new(&f, 0, 1.0);
        let found = Planner::new()
            .search(
                &grid,
                Cell::new(10, 10),
                Cell::new(25, 17),
                &team,
                TaskClass::MayChangeRarely.weights(),
            )
            .unwrap();
        let along = formation_along(&grid, &found.cells, &team, true);
        let (keys, transitions) = smooth(&grid, &found.cells, &along, &team, true);
        assert_eq!(keys.len(), 2);
        assert!(transitions.is_empty());
    }
}
