//! Local routing on a cost grid: how a squad member reaches its slot without touching a blocked
//! cell, seed 004 ("members track their slots ... re-planning when blocked").
//!
//! Not a tick stage: called by the squad runtime between ticks, sequentially, so every result is
//! deterministic. The slot a member must reach comes from the plan's tables; when the straight
//! way to it is not clear (a wall, a canyon mouth, a slot that lies on a blocked cell), the member
//! is given an intermediate target instead: the farthest cell of a local grid A* path that it can
//! walk to in a straight line.

use crate::terrain::{Cell, CostGrid};
use glam::Vec2;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// How far (in cells) the nearest free cell to a blocked slot is looked for.
pub const NEAREST_FREE_RADIUS: usize = 8;

/// Cells added around the start and goal cells to bound a local search.
pub const SEARCH_MARGIN: usize = 24;

/// Largest side (in cells) of a local search window.
pub const MAX_WINDOW: usize = 192;

/// Whether the cell containing `p` is free (inside the grid and not blocked).
pub fn free_at(grid: &CostGrid, p: Vec2) -> bool {
    grid.cell_of(p)
        .is_some_and(|c| !grid.blocked[grid.index(c)])
}

/// Whether every point of the segment `a → b`, widened by `clearance` on both sides along X and
/// Z, lies on free cells. The segment is sampled at most a quarter cell apart.
pub fn segment_clear(grid: &CostGrid, a: Vec2, b: Vec2, clearance: f32) -> bool {
    let step = 0.25 * grid.cell_size;
    let n = ((a.distance(b) / step).ceil() as usize).max(1);
    let offsets = [
        Vec2::ZERO,
        Vec2::new(clearance, 0.0),
        Vec2::new(-clearance, 0.0),
        Vec2::new(0.0, clearance),
        Vec2::new(0.0, -clearance),
    ];
    (0..=n).all(|i| {
        let p = a.lerp(b, i as f32 / n as f32);
        offsets.iter().all(|&o| free_at(grid, p + o))
    })
}

/// The centre of the free cell nearest to `p` (by distance between centres, ties in row-major
/// order), searched in growing square rings up to `radius` cells; `None` when there is none.
pub fn nearest_free(grid: &CostGrid, p: Vec2, radius: usize) -> Option<Vec2> {
    let fx = ((p.x - grid.origin.x) / grid.cell_size).floor() as i64;
    let fz = ((p.y - grid.origin.y) / grid.cell_size).floor() as i64;
    let mut best: Option<(f32, Vec2)> = None;
    for ring in 0..=radius as i64 {
        for r in fz - ring..=fz + ring {
            for c in fx - ring..=fx + ring {
                if (r - fz).abs() != ring && (c - fx).abs() != ring {
                    continue;
                }
                if grid.is_blocked(c, r) {
                    continue;
                }
                let centre = grid.center_of(Cell::new(c as usize, r as usize));
                let d = centre.distance_squared(p);
                if best.is_none_or(|(bd, _)| d < bd) {
                    best = Some((d, centre));
                }
            }
        }
        // A cell of ring k + 1 is at least k cells away, farther than any of ring k − 1.
        if best.is_some_and(|(d, _)| d.sqrt() <= ring as f32 * grid.cell_size) {
            break;
        }
    }
    best.map(|(_, c)| c)
}

/// Reusable buffers of the local A* search.
#[derive(Debug, Default, Clone)]
pub struct Router {
    g: Vec<u32>,
    parent: Vec<u32>,
    stamp: Vec<u32>,
    closed: Vec<u32>,
    generation: u32,
    heap: BinaryHeap<(Reverse<u32>, Reverse<u32>, u32)>,
    /// Cells of the last path found, start first.
    pub path: Vec<Cell>,
}

const STRAIGHT: u32 = 1000;
const DIAGONAL: u32 = 1414;

fn octile(a: (i64, i64), b: (i64, i64)) -> u32 {
    let dx = (a.0 - b.0).unsigned_abs() as u32;
    let dz = (a.1 - b.1).unsigned_abs() as u32;
    let (lo, hi) = (dx.min(dz), dx.max(dz));
    DIAGONAL * lo + STRAIGHT * (hi - lo)
}

impl Router {
    /// A router with empty buffers.
    pub fn new() -> Self {
        Router::default()
    }

    /// Shortest 8-connected path of free cells from `from` to `to` (uniform cost, no corner
    /// cutting), searched inside a window around both cells; `false` when there is none there.
    /// The path, start first, is left in [`Router::path`].
    pub fn search(&mut self, grid: &CostGrid, from: Cell, to: Cell) -> bool {
        self.path.clear();
        let blocked = |c: Cell| grid.blocked[grid.index(c)];
        if blocked(from) || blocked(to) {
            return false;
        }
        let span = |a: usize, b: usize, n: usize| {
            let lo = a.min(b).saturating_sub(SEARCH_MARGIN);
            let hi = (a.max(b) + SEARCH_MARGIN).min(n - 1);
            // Too wide: keep the part nearest the start.
            if hi - lo + 1 > MAX_WINDOW {
                let lo = a
                    .saturating_sub(MAX_WINDOW / 2)
                    .min(n.saturating_sub(MAX_WINDOW));
                (lo, (lo + MAX_WINDOW - 1).min(n - 1))
            } else {
                (lo, hi)
            }
        };
        let (c0, c1) = span(from.col, to.col, grid.cols);
        let (r0, r1) = span(from.row, to.row, grid.rows);
        let inside =
            |c: i64, r: i64| c >= c0 as i64 && c <= c1 as i64 && r >= r0 as i64 && r <= r1 as i64;
        if !inside(to.col as i64, to.row as i64) {
            return false;
        }
        let w = c1 - c0 + 1;
        let n = w * (r1 - r0 + 1);
        if self.g.len() < n {
            self.g.resize(n, 0);
            self.parent.resize(n, 0);
            self.stamp.resize(n, 0);
            self.closed.resize(n, 0);
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.closed.iter_mut().for_each(|s| *s = 0);
            self.generation = 1;
        }
        let gen = self.generation;
        let local = |c: i64, r: i64| (r as usize - r0) * w + (c as usize - c0);
        let goal = (to.col as i64, to.row as i64);
        let start = (from.col as i64, from.row as i64);
        self.heap.clear();
        let s = local(start.0, start.1);
        self.g[s] = 0;
        self.stamp[s] = gen;
        self.parent[s] = s as u32;
        let mut seq = 0u32;
        self.heap
            .push((Reverse(octile(start, goal)), Reverse(seq), s as u32));
        let free = |c: i64, r: i64| inside(c, r) && !grid.is_blocked(c, r);
        let mut found = false;
        while let Some((_, _, i)) = self.heap.pop() {
            let i = i as usize;
            if self.closed[i] == gen {
                continue;
            }
            self.closed[i] = gen;
            let (c, r) = ((i % w + c0) as i64, (i / w + r0) as i64);
            if (c, r) == goal {
                found = true;
                break;
            }
            for (dc, dr) in [
                (1, 0),
                (-1, 0),
                (0, 1),
                (0, -1),
                (1, 1),
                (1, -1),
                (-1, 1),
                (-1, -1),
            ] {
                let (nc, nr) = (c + dc, r + dr);
                if !free(nc, nr) {
                    continue;
                }
                let diagonal = dc != 0 && dr != 0;
                if diagonal && (!free(c + dc, r) || !free(c, r + dr)) {
                    continue;
                }
                let j = local(nc, nr);
                if self.closed[j] == gen {
                    continue;
                }
                let g = self.g[i] + if diagonal { DIAGONAL } else { STRAIGHT };
                if self.stamp[j] != gen || g < self.g[j] {
                    self.stamp[j] = gen;
                    self.g[j] = g;
                    self.parent[j] = i as u32;
                    seq += 1;
                    self.heap
                        .push((Reverse(g + octile((nc, nr), goal)), Reverse(seq), j as u32));
                }
            }
        }
        if !found {
            return false;
        }
        let mut i = local(goal.0, goal.1);
        loop {
            self.path.push(Cell::new(i % w + c0, i / w + r0));
            let p = self.parent[i] as usize;
            if p == i {
                break;
            }
            i = p;
        }
        self.path.reverse();
        true
    }

    /// Where an agent at `from` should head to reach `to` without touching a blocked cell:
    /// `to` itself when the straight way is clear (and `force_search` is off), else the farthest
    /// cell of a local A* path it can walk to in a straight line. A `to` on a blocked cell is
    /// first moved to the nearest free cell. Returns the point and whether it is a detour.
    pub fn route(
        &mut self,
        grid: &CostGrid,
        from: Vec2,
        to: Vec2,
        clearance: f32,
        force_search: bool,
    ) -> (Vec2, bool) {
        let to = if free_at(grid, to) {
            to
        } else {
            nearest_free(grid, to, NEAREST_FREE_RADIUS).unwrap_or(to)
        };
        if !force_search && segment_clear(grid, from, to, clearance) {
            return (to, false);
        }
        let (Some(a), Some(b)) = (grid.cell_of(from), grid.cell_of(to)) else {
            return (to, false);
        };
        if a == b || !self.search(grid, a, b) {
            return (to, false);
        }
        // The farthest path cell reachable in a straight line (the first step always is: it is
        // a free neighbour without corner cutting).
        let mut best = self.path.get(1).copied().unwrap_or(b);
        for &c in self.path.iter().skip(2) {
            if segment_clear(grid, from, grid.center_of(c), clearance) {
                best = c;
            } else {
                break;
            }
        }
        if best == b {
            return (to, true);
        }
        (grid.center_of(best), true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wall() -> CostGrid {
        // A wall across the middle with a door at the east end.
        CostGrid::from_ascii(
            "..........
             ..........
             #########.
             ..........
             ..........",
        )
    }

    #[test]
    fn segments_through_walls_are_not_clear() {
        let g = wall();
        assert!(segment_clear(
            &g,
            Vec2::new(0.5, 0.5),
            Vec2::new(9.5, 1.5),
            0.2
        ));
        assert!(!segment_clear(
            &g,
            Vec2::new(0.5, 0.5),
            Vec2::new(0.5, 4.5),
            0.0
        ));
        // Half a cell from the wall: clear without clearance, not with 0.6.
        assert!(segment_clear(
            &g,
            Vec2::new(0.5, 1.5),
            Vec2::new(8.5, 1.5),
            0.0
        ));
        assert!(!segment_clear(
            &g,
            Vec2::new(0.5, 1.5),
            Vec2::new(8.5, 1.5),
            0.6
        ));
    }

    #[test]
    fn nearest_free_cell_of_a_blocked_point() {
        let g = wall();
        assert_eq!(
            nearest_free(&g, Vec2::new(3.5, 2.5), 4),
            Some(Vec2::new(3.5, 1.5))
        );
        assert_eq!(
            nearest_free(&g, Vec2::new(3.4, 2.9), 4),
            Some(Vec2::new(3.5, 3.5))
        );
        let full = CostGrid::from_ascii("###\n###\n###");
        assert_eq!(nearest_free(&full, Vec2::new(1.5, 1.5), 3), None);
    }

    #[test]
    fn a_wall_between_agent_and_slot_gives_a_detour_through_the_door() {
        let g = wall();
        let mut r = Router::new();
        assert!(r.search(&g, Cell::new(0, 0), Cell::new(0, 4)));
        assert!(r.path.contains(&Cell::new(9, 2)), "{:?}", r.path);
        // 9 steps east (diagonals included), through the door, 9 back: octile length.
        assert_eq!(r.path.first(), Some(&Cell::new(0, 0)));
        assert_eq!(r.path.last(), Some(&Cell::new(0, 4)));
        let (t, detour) = r.route(&g, Vec2::new(0.5, 0.5), Vec2::new(0.5, 4.5), 0.1, false);
        assert!(detour);
        // Straight from the start the farthest reachable cell of the path is in row 0 or 1,
        // heading to the door, never across the wall.
        assert!(segment_clear(&g, Vec2::new(0.5, 0.5), t, 0.1));
        assert!(t.y < 2.0 && t.x > 5.0, "{t}");
        // A clear way is taken as is.
        let (t, detour) = r.route(&g, Vec2::new(0.5, 0.5), Vec2::new(6.5, 1.5), 0.1, false);
        assert_eq!((t, detour), (Vec2::new(6.5, 1.5), false));
        // A slot on the wall is moved to the nearest free cell first.
        let (t, _) = r.route(&g, Vec2::new(3.5, 0.5), Vec2::new(3.5, 2.4), 0.1, false);
        assert_eq!(t, Vec2::new(3.5, 1.5));
    }

    #[test]
    fn no_way_through_is_reported() {
        let g = CostGrid::from_ascii(
            "...
             ###
             ...",
        );
        let mut r = Router::new();
        assert!(!r.search(&g, Cell::new(0, 0), Cell::new(0, 2)));
        assert!(r.path.is_empty());
    }
}
