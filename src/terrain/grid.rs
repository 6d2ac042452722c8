//! The planning grid: per-cell cost and blocked flags, and grid line of sight (supercover).
//!
//! Not a tick stage: built once from a [`Terrain`](super::Terrain) and a
//! [`Mobility`](super::Mobility), then read by formation-aware A* and leader-path smoothing
//! (seed 004, "CGF terrain database" and "LOS test i→k").

use glam::Vec2;
use serde::{Deserialize, Serialize};

/// One grid cell: `col` grows east (+X), `row` grows south (+Z); `(0, 0)` is the north-west cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Cell {
    /// Column index, 0 at the west edge.
    pub col: usize,
    /// Row index, 0 at the north edge.
    pub row: usize,
}

impl Cell {
    /// The cell at `col`, `row`.
    pub const fn new(col: usize, row: usize) -> Self {
        Cell { col, row }
    }
}

/// A grid of traversal costs and blocked cells, the whole input of path planning.
///
/// `cost` is a per-cell multiplier of distance (1.0 = open ground); a step into a cell costs
/// `step length in cells × cost of that cell`. Blocked cells are never entered.
#[derive(Debug, Clone, PartialEq)]
pub struct CostGrid {
    /// Number of columns (west–east).
    pub cols: usize,
    /// Number of rows (north–south).
    pub rows: usize,
    /// Edge length of a cell in world units.
    pub cell_size: f32,
    /// World `(x, z)` of the north-west corner of cell `(0, 0)`.
    pub origin: Vec2,
    /// Row-major cost multipliers, all finite and > 0.
    pub cost: Vec<f32>,
    /// Row-major blocked flags.
    pub blocked: Vec<bool>,
}

impl CostGrid {
    /// An open grid: every cell costs 1 and none is blocked.
    pub fn open(cols: usize, rows: usize, cell_size: f32, origin: Vec2) -> Self {
        CostGrid {
            cols,
            rows,
            cell_size,
            origin,
            cost: vec![1.0; cols * rows],
            blocked: vec![false; cols * rows],
        }
    }

    /// A grid drawn as text, one line per row (north first): `#` blocked, `.` cost 1,
    /// `1`–`9` that cost. Cell size 1, origin `(0, 0)`. Meant for tests and examples.
    ///
    /// # Panics
    /// When the lines differ in length or hold another character.
    pub fn from_ascii(map: &str) -> Self {
        let lines: Vec<&str> = map
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        let rows = lines.len();
        let cols = lines.first().map_or(0, |l| l.len());
        let mut grid = CostGrid::open(cols, rows, 1.0, Vec2::ZERO);
        for (r, line) in lines.iter().enumerate() {
            assert_eq!(
                line.len(),
                cols,
                "row {r} of the map has a different length"
            );
            for (c, ch) in line.bytes().enumerate() {
                let i = r * cols + c;
                match ch {
                    b'#' => grid.blocked[i] = true,
                    b'.' => {}
                    b'1'..=b'9' => grid.cost[i] = f32::from(ch - b'0'),
                    _ => panic!("unexpected map character {:?}", ch as char),
                }
            }
        }
        grid
    }

    /// Row-major index of `cell`.
    #[inline]
    pub fn index(&self, cell: Cell) -> usize {
        cell.row * self.cols + cell.col
    }

    /// The cell at row-major index `i`.
    #[inline]
    pub fn cell_at(&self, i: usize) -> Cell {
        Cell::new(i % self.cols, i / self.cols)
    }

    /// The cell containing world `(x, z)`, or `None` outside the grid.
    pub fn cell_of(&self, pos: Vec2) -> Option<Cell> {
        cell_of(self.origin, self.cell_size, self.cols, self.rows, pos)
    }

    /// World `(x, z)` of the centre of `cell`.
    pub fn center_of(&self, cell: Cell) -> Vec2 {
        center_of(self.origin, self.cell_size, cell)
    }

    /// Whether `(col, row)` is blocked; cells outside the grid count as blocked.
    #[inline]
    pub fn is_blocked(&self, col: i64, row: i64) -> bool {
        if col < 0 || row < 0 || col >= self.cols as i64 || row >= self.rows as i64 {
            return true;
        }
        self.blocked[row as usize * self.cols + col as usize]
    }

    /// Whether the segment between the centres of `a` and `b` touches no blocked cell.
    pub fn clear_line(&self, a: Cell, b: Cell) -> bool {
        supercover(a, b, |c, r| !self.is_blocked(c, r))
    }

    /// The smallest cost of any unblocked cell (1.0 for a grid with none), used by the heuristic.
    pub fn min_cost(&self) -> f32 {
        let min = self
            .cost
            .iter()
            .zip(&self.blocked)
            .filter(|(_, &b)| !b)
            .map(|(&c, _)| c)
            .fold(f32::INFINITY, f32::min);
        if min.is_finite() {
            min
        } else {
            1.0
        }
    }
}

pub(crate) fn cell_of(
    origin: Vec2,
    cell_size: f32,
    cols: usize,
    rows: usize,
    p: Vec2,
) -> Option<Cell> {
    let fx = ((p.x - origin.x) / cell_size).floor();
    let fz = ((p.y - origin.y) / cell_size).floor();
    if fx < 0.0
        || fz < 0.0
        || fx >= cols as f32
        || fz >= rows as f32
        || !fx.is_finite()
        || !fz.is_finite()
    {
        return None;
    }
    Some(Cell::new(fx as usize, fz as usize))
}

pub(crate) fn center_of(origin: Vec2, cell_size: f32, cell: Cell) -> Vec2 {
    origin + Vec2::new(cell.col as f32 + 0.5, cell.row as f32 + 0.5) * cell_size
}

/// Visits every cell the segment between the centres of `a` and `b` touches, in order from `a`,
/// stopping early (and returning `false`) as soon as `visit` returns `false`.
///
/// Where the segment passes exactly through a cell corner, both side cells are visited too, so a
/// blocked cell that the segment only grazes is never skipped (a "supercover" line).
pub fn supercover(a: Cell, b: Cell, mut visit: impl FnMut(i64, i64) -> bool) -> bool {
    let (mut x, mut y) = (a.col as i64, a.row as i64);
    let dx = (b.col as i64 - x).abs();
    let dy = (b.row as i64 - y).abs();
    let sx = (b.col as i64 - x).signum();
    let sy = (b.row as i64 - y).signum();
    if !visit(x, y) {
        return false;
    }
    let (mut ix, mut iy) = (0i64, 0i64);
    while ix < dx || iy < dy {
        // Compare the parameters at which the segment crosses the next vertical and the next
        // horizontal cell boundary, scaled by 2·dx·dy to stay in integers.
        let tx = (2 * ix + 1) * dy;
        let ty = (2 * iy + 1) * dx;
        if tx == ty {
            if !visit(x + sx, y) || !visit(x, y + sy) {
                return false;
            }
            x += sx;
            y += sy;
            ix += 1;
            iy += 1;
        } else if tx < ty {
            x += sx;
            ix += 1;
        } else {
            y += sy;
            iy += 1;
        }
        if !visit(x, y) {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Exact test whether the segment between two cell centres touches the closed square of
    /// cell `(c, r)`; coordinates doubled so centres are odd integers.
    fn touches(a: Cell, b: Cell, c: i64, r: i64) -> bool {
        let (x0, y0) = (2 * a.col as i64 + 1, 2 * a.row as i64 + 1);
        let (x1, y1) = (2 * b.col as i64 + 1, 2 * b.row as i64 + 1);
        let (lx, hx, ly, hy) = (2 * c, 2 * c + 2, 2 * r, 2 * r + 2);
        // Clip the parametric segment against the box with rationals t = num/den (den > 0).
        let mut t0 = (0i64, 1i64);
        let mut t1 = (1i64, 1i64);
        for (p0, d, lo, hi) in [(x0, x1 - x0, lx, hx), (y0, y1 - y0, ly, hy)] {
            if d == 0 {
                if p0 < lo || p0 > hi {
                    return false;
                }
                continue;
            }
            let (ta, tb) = if d > 0 {
                ((lo - p0, d), (hi - p0, d))
            } else {
                ((p0 - hi, -d), (p0 - lo, -d))
            };
            // max of lower bounds, min of upper bounds
            if ta.0 * t0.1 > t0.0 * ta.1 {
                t0 = ta;
            }
            if tb.0 * t1.1 < t1.0 * tb.1 {
                t1 = tb;
            }
        }
        t0.0 * t1.1 <= t1.0 * t0.1
    }

    proptest! {
        #[test]
        fn supercover_visits_exactly_the_touched_cells(
            ax in 0usize..12, ay in 0usize..12, bx in 0usize..12, by in 0usize..12
        ) {
            let (a, b) = (Cell::new(ax, ay), Cell::new(bx, by));
            let mut seen = std::collections::BTreeSet::new();
            supercover(a, b, |c, r| { seen.insert((c, r)); true });
            let mut expected = std::collections::BTreeSet::new();
            for c in -1..14 {
                for r in -1..14 {
                    if touches(a, b, c, r) {
                        expected.insert((c, r));
                    }
                }
            }
            prop_assert_eq!(seen, expected);
        }
    }

    #[test]
    fn diagonal_line_through_corners_checks_the_side_cells() {
        let g = CostGrid::from_ascii(
            "...
             .#.
             ...",
        );
        // The anti-diagonal from (0,2) to (2,0) crosses (1,1); the step (0,1)-(1,0) grazes its corner.
        assert!(!g.clear_line(Cell::new(0, 2), Cell::new(2, 0)));
        assert!(!g.clear_line(Cell::new(0, 1), Cell::new(1, 0)));
        assert!(g.clear_line(Cell::new(0, 0), Cell::new(2, 0)));
        let g2 = CostGrid::from_ascii(
            ".#
             ..",
        );
        // A diagonal step whose side cell is blocked is not clear (no corner cutting).
        assert!(!g2.clear_line(Cell::new(0, 0), Cell::new(1, 1)));
    }

    #[test]
    fn cell_and_centre_round_trip() {
        let g = CostGrid::open(4, 3, 2.0, Vec2::new(10.0, -6.0));
        let c = Cell::new(3, 2);
        assert_eq!(g.center_of(c), Vec2::new(17.0, -1.0));
        assert_eq!(g.cell_of(g.center_of(c)), Some(c));
        assert_eq!(g.cell_of(Vec2::new(9.9, 0.0)), None);
        assert_eq!(g.cell_of(Vec2::new(18.0, 0.0)), None);
    }
}
