//! Terrain: the ground a team plans over, seed 004 ("CGF terrain database").
//!
//! Not a tick stage: loaded once per scenario, then read by path planning (the cost and blocked
//! maps) and by perception (line of sight over the ground). A regular grid of elevations (a DEM,
//! [`dem`]) is fused with feature data (roads, rivers, vegetation, buildings, water,
//! [`features`]) into per-cell attributes; a species' [`Mobility`] turns those into a
//! [`CostGrid`]. The source keeps features in a quadtree only to find the cells they cover; here
//! they are rasterised straight into the grid, which gives the same per-cell attributes.
//!
//! Coordinates: world up is +Y and the grid lies in the X–Z plane, +X east and +Z south (north is
//! −Z, so the frame is right-handed). Cell `(0, 0)` is the north-west cell — the first value of an
//! ESRI grid's first line — and `origin` is its north-west corner. Heights sit at cell centres.

pub mod dem;
pub mod features;
pub mod grid;
pub mod procedural;

pub use dem::{load_asc, load_pgm, parse_asc, parse_pgm};
pub use features::{CellAttrs, Feature, Features, Mobility, PointKind};
pub use grid::{supercover, Cell, CostGrid};
pub use procedural::SplitMix64;

use glam::{Vec2, Vec3};

/// A height field on a regular grid with per-cell feature attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct Terrain {
    /// World `(x, z)` of the north-west corner of cell `(0, 0)`.
    pub origin: Vec2,
    /// Edge length of a cell in world units.
    pub cell_size: f32,
    /// Number of columns (west–east).
    pub cols: usize,
    /// Number of rows (north–south).
    pub rows: usize,
    /// Row-major heights (world Y) at cell centres, all finite.
    pub heights: Vec<f32>,
    /// Row-major feature attributes; cells without data carry [`CellAttrs::NODATA`].
    pub attrs: Vec<CellAttrs>,
}

impl Terrain {
    /// A terrain from row-major heights (row 0 north).
    ///
    /// # Panics
    /// When `heights.len() != cols * rows`, the grid is empty or `cell_size` is not positive.
    pub fn from_heights(
        cols: usize,
        rows: usize,
        cell_size: f32,
        origin: Vec2,
        heights: Vec<f32>,
    ) -> Self {
        assert!(cols > 0 && rows > 0, "terrain must have at least one cell");
        assert_eq!(
            heights.len(),
            cols * rows,
            "heights must hold cols × rows values"
        );
        assert!(cell_size > 0.0, "cell size must be positive");
        Terrain {
            origin,
            cell_size,
            cols,
            rows,
            attrs: vec![CellAttrs::default(); heights.len()],
            heights,
        }
    }

    /// Row-major index of `cell`.
    #[inline]
    pub fn index(&self, cell: Cell) -> usize {
        cell.row * self.cols + cell.col
    }

    /// The cell containing world `(x, z)`, or `None` outside the grid.
    pub fn cell_of(&self, pos: Vec2) -> Option<Cell> {
        grid::cell_of(self.origin, self.cell_size, self.cols, self.rows, pos)
    }

    /// World `(x, z)` of the centre of `cell`.
    pub fn center_of(&self, cell: Cell) -> Vec2 {
        grid::center_of(self.origin, self.cell_size, cell)
    }

    /// Height stored for `cell`.
    pub fn height_of(&self, cell: Cell) -> f32 {
        self.heights[self.index(cell)]
    }

    /// Fractional grid coordinates of `(x, z)` in units of cells, measured between cell centres
    /// and clamped to the grid, with the cell indices to interpolate from.
    fn lattice(&self, x: f32, z: f32) -> (usize, usize, f32, f32, bool, bool) {
        let fx = (x - self.origin.x) / self.cell_size - 0.5;
        let fz = (z - self.origin.y) / self.cell_size - 0.5;
        let maxx = (self.cols - 1) as f32;
        let maxz = (self.rows - 1) as f32;
        let (cx, inx) = (fx.clamp(0.0, maxx), (0.0..=maxx).contains(&fx));
        let (cz, inz) = (fz.clamp(0.0, maxz), (0.0..=maxz).contains(&fz));
        let i0 = (cx.floor() as usize).min(self.cols.saturating_sub(2));
        let j0 = (cz.floor() as usize).min(self.rows.saturating_sub(2));
        (i0, j0, cx - i0 as f32, cz - j0 as f32, inx, inz)
    }

    fn h(&self, c: usize, r: usize) -> f32 {
        self.heights[r.min(self.rows - 1) * self.cols + c.min(self.cols - 1)]
    }

    /// Ground height at world `(x, z)`: bilinear between cell centres, held flat beyond the edge.
    pub fn height_at(&self, x: f32, z: f32) -> f32 {
        let (i, j, tx, tz, _, _) = self.lattice(x, z);
        let top = self.h(i, j) + (self.h(i + 1, j) - self.h(i, j)) * tx;
        let bottom = self.h(i, j + 1) + (self.h(i + 1, j + 1) - self.h(i, j + 1)) * tx;
        top + (bottom - top) * tz
    }

    /// Gradient `(∂h/∂x, ∂h/∂z)` of the bilinear surface at `(x, z)`.
    pub fn gradient_at(&self, x: f32, z: f32) -> Vec2 {
        let (i, j, tx, tz, inx, inz) = self.lattice(x, z);
        let cs = self.cell_size;
        let dx = if inx && self.cols > 1 {
            ((self.h(i + 1, j) - self.h(i, j)) * (1.0 - tz)
                + (self.h(i + 1, j + 1) - self.h(i, j + 1)) * tz)
                / cs
        } else {
            0.0
        };
        let dz = if inz && self.rows > 1 {
            ((self.h(i, j + 1) - self.h(i, j)) * (1.0 - tx)
                + (self.h(i + 1, j + 1) - self.h(i + 1, j)) * tx)
                / cs
        } else {
            0.0
        };
        Vec2::new(dx, dz)
    }

    /// Unit surface normal at `(x, z)` (pointing up, +Y).
    pub fn normal_at(&self, x: f32, z: f32) -> Vec3 {
        let g = self.gradient_at(x, z);
        Vec3::new(-g.x, 1.0, -g.y).normalize()
    }

    /// Slope at `(x, z)` in degrees from the horizontal.
    pub fn slope_at(&self, x: f32, z: f32) -> f32 {
        crate::math::atan(self.gradient_at(x, z).length()).to_degrees()
    }

    /// Slope of `cell` in degrees, from central differences of its neighbours' heights
    /// (one-sided at the edges); this is the slope a species' limit is checked against.
    pub fn cell_slope_deg(&self, cell: Cell) -> f32 {
        let (c, r) = (cell.col, cell.row);
        let diff = |lo: f32, hi: f32, steps: usize| {
            if steps == 0 {
                0.0
            } else {
                (hi - lo) / (steps as f32 * self.cell_size)
            }
        };
        let (cl, ch) = (c.saturating_sub(1), (c + 1).min(self.cols - 1));
        let (rl, rh) = (r.saturating_sub(1), (r + 1).min(self.rows - 1));
        let gx = diff(self.h(cl, r), self.h(ch, r), ch - cl);
        let gz = diff(self.h(c, rl), self.h(c, rh), rh - rl);
        crate::math::atan((gx * gx + gz * gz).sqrt()).to_degrees()
    }

    /// Whether the straight segment from `a` to `b` stays above the ground. The ground is sampled
    /// along the segment at most half a cell apart; the end points themselves are not tested, and
    /// the parts of the segment beyond the grid have no ground under them.
    pub fn line_of_sight(&self, a: Vec3, b: Vec3) -> bool {
        let horizontal = Vec2::new(b.x - a.x, b.z - a.z).length();
        let n = ((horizontal / (0.5 * self.cell_size)).ceil() as usize).max(1);
        (1..n).all(|i| {
            let p = a.lerp(b, i as f32 / n as f32);
            self.cell_of(Vec2::new(p.x, p.z)).is_none() || self.height_at(p.x, p.z) <= p.y
        })
    }

    /// Whether the segment between the centres of `a` and `b` touches no blocked cell; `blocked`
    /// is row-major over this terrain. Cells outside the grid count as blocked.
    pub fn clear_line(&self, a: Cell, b: Cell, blocked: &[bool]) -> bool {
        assert_eq!(blocked.len(), self.cols * self.rows, "blocked map size");
        supercover(a, b, |c, r| {
            c >= 0
                && r >= 0
                && (c as usize) < self.cols
                && (r as usize) < self.rows
                && !blocked[r as usize * self.cols + c as usize]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Terrain {
        // 3×3, heights grow 1 per cell eastwards and 10 per cell southwards.
        let h = (0..9)
            .map(|i| (i % 3) as f32 + 10.0 * (i / 3) as f32)
            .collect();
        Terrain::from_heights(3, 3, 2.0, Vec2::new(0.0, 0.0), h)
    }

    #[test]
    fn height_is_bilinear_between_centres_and_flat_beyond() {
        let t = ramp();
        assert_eq!(t.height_at(1.0, 1.0), 0.0);
        assert_eq!(t.height_at(2.0, 1.0), 0.5);
        assert_eq!(t.height_at(3.0, 4.0), 16.0);
        assert_eq!(t.height_at(-5.0, 1.0), 0.0);
        assert_eq!(t.height_at(100.0, 100.0), 22.0);
    }

    #[test]
    fn normal_and_slope_follow_the_gradient() {
        let t = ramp();
        let g = t.gradient_at(2.0, 2.0);
        assert!((g.x - 0.5).abs() < 1e-6 && (g.y - 5.0).abs() < 1e-6);
        let n = t.normal_at(2.0, 2.0);
        assert!((n - Vec3::new(-0.5, 1.0, -5.0).normalize()).length() < 1e-6);
        let s = t.slope_at(2.0, 2.0);
        assert!((s - crate::math::atan(crate::math::hypot(0.5, 5.0)).to_degrees()).abs() < 1e-4);
        let flat = Terrain::from_heights(2, 2, 1.0, Vec2::ZERO, vec![3.0; 4]);
        assert_eq!(flat.normal_at(0.7, 1.2), Vec3::Y);
        assert_eq!(flat.cell_slope_deg(Cell::new(1, 1)), 0.0);
    }

    #[test]
    fn line_of_sight_is_blocked_by_a_ridge() {
        let mut h = vec![0.0; 20 * 5];
        for r in 0..5 {
            h[r * 20 + 10] = 10.0;
        }
        let t = Terrain::from_heights(20, 5, 1.0, Vec2::ZERO, h);
        let a = Vec3::new(2.5, 1.0, 2.5);
        let b = Vec3::new(17.5, 1.0, 2.5);
        assert!(!t.line_of_sight(a, b));
        assert!(t.line_of_sight(a + Vec3::Y * 11.0, b + Vec3::Y * 11.0));
        assert!(t.line_of_sight(a, Vec3::new(8.5, 1.0, 2.5)));
    }

    #[test]
    fn cell_of_maps_world_to_grid() {
        let t = ramp();
        assert_eq!(t.cell_of(Vec2::new(5.9, 0.1)), Some(Cell::new(2, 0)));
        assert_eq!(t.cell_of(Vec2::new(6.0, 0.1)), None);
        assert_eq!(t.center_of(Cell::new(1, 2)), Vec2::new(3.0, 5.0));
        let blocked = [false, false, false, false, true, false, false, false, false];
        assert!(!t.clear_line(Cell::new(0, 0), Cell::new(2, 2), &blocked));
        assert!(t.clear_line(Cell::new(0, 0), Cell::new(2, 0), &blocked));
    }
}
