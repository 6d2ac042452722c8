//! Stage 1 of the tick: the spatial index, rebuilt from scratch every tick.
//!
//! A uniform grid over the world bounds, filled by a counting sort so that the entries of one
//! cell are contiguous and in ascending index order. Neighbor queries visit only the cells that
//! overlap the query sphere, so perception costs O(N·k), not O(N²). Entries carry a copy of the
//! position so that a query walks memory linearly.
//!
//! Cells are [`X_SPLIT`] times narrower along x than along y and z: the cells of one (y, z) row
//! are adjacent in memory, so a query reads a row as one run, and narrow cells let that run
//! stop within a narrow cell of the query box's own x extent instead of a whole cell of the
//! radius beyond it. With cells of the query radius, a flat query then reads ~66 candidates for
//! 31 neighbors instead of ~87, at no extra cost per row.

mod obstacles;

pub use obstacles::ObstacleGrid;

use crate::world::Aabb;
use glam::{IVec3, Vec3, Vec3A};
use rayon::prelude::*;

/// A uniform grid of point entries (agents or food).
#[derive(Debug, Clone, Default)]
pub struct Grid {
    layout: Layout,
    /// `starts[c]..starts[c+1]` are the entries of cell `c`.
    starts: Vec<u32>,
    /// Entry indices sorted by cell, ascending within a cell.
    entries: Vec<u32>,
    /// Positions of `entries`, in the same order (16-byte lanes: one vector operation each).
    positions: Vec<Vec3A>,
    /// Scratch: the input points of [`Grid::rebuild`] (12 bytes each: only copied into
    /// `positions`; [`Grid::rebuild_with`] reads its points twice instead), and the cell of each.
    points: Vec<Vec3>,
    cell_of: Vec<u32>,
    /// Slot of each entry index (the inverse of `entries`).
    slots: Vec<u32>,
    /// Scratch: fill cursor per cell.
    cursor: Vec<u32>,
}

/// Entries of one row examined at a time by a query.
const CHUNK: usize = 32;

/// Most cells along one axis; larger worlds get bigger cells.
const MAX_DIM: i32 = 256;

/// Cells along x per cell along y and z (fewer where the cell table would grow too large).
pub const X_SPLIT: i32 = 4;

impl Grid {
    /// An empty grid.
    pub fn new() -> Self {
        Self::default()
    }

    /// Cell size in use along each axis (narrower along x, see [`X_SPLIT`]).
    pub fn cell_sizes(&self) -> Vec3 {
        self.layout.cell
    }

    /// Where the grid puts a point: a grid rebuilt with the same layout ([`Grid::rebuild_in`])
    /// lists any of its points in the same cell, so a query walks its entries in the same order
    /// as this grid's.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Rebuilds the grid over `bounds` with cells of about `cell` for the given points.
    /// Reuses its buffers: no allocation once warmed up.
    pub fn rebuild(
        &mut self,
        bounds: Aabb,
        cell: f32,
        points: impl ExactSizeIterator<Item = Vec3>,
    ) {
        self.points.clear();
        self.points.extend(points);
        self.place_in(Layout::new(bounds, cell, self.points.len()));
    }

    /// Rebuilds the grid for the given points with the cells of `layout` (another grid's, say:
    /// see [`Grid::layout`]).
    pub fn rebuild_in(&mut self, layout: Layout, points: impl ExactSizeIterator<Item = Vec3>) {
        self.points.clear();
        self.points.extend(points);
        self.place_in(layout);
    }

    /// Sorts `self.points` by cell of `layout`.
    fn place_in(&mut self, layout: Layout) {
        self.layout = layout;
        self.cell_of.clear();
        self.cell_of.par_extend(
            self.points
                .par_iter()
                .with_min_len(crate::par::min_len(256))
                .map(|&p| layout.cell_of(p)),
        );
        self.place();
    }

    /// Like [`Grid::rebuild`] for points `0..n`, `point(i)` giving point `i` (gathered in
    /// parallel).
    pub fn rebuild_with(
        &mut self,
        bounds: Aabb,
        cell: f32,
        n: usize,
        point: impl Fn(usize) -> Vec3 + Sync,
    ) {
        let layout = Layout::new(bounds, cell, n);
        self.layout = layout;
        // The cells in one parallel pass; the points are read again as they are placed, not
        // kept (12 bytes an agent).
        self.points = Vec::new();
        self.cell_of.resize(n, 0);
        self.cell_of
            .par_iter_mut()
            .enumerate()
            .with_min_len(crate::par::min_len(256))
            .for_each(|(i, c)| *c = layout.cell_of(point(i)));
        self.place_by(point);
    }

    /// Sorts `self.points` (in cells `self.cell_of`) by cell.
    fn place(&mut self) {
        let points = std::mem::take(&mut self.points);
        self.place_by(|i| points[i]);
        self.points = points;
    }

    /// Sorts points `0..n`, `point(i)` giving point `i` (in cells `self.cell_of`), by cell.
    fn place_by(&mut self, point: impl Fn(usize) -> Vec3) {
        let dims = self.layout.dims;
        let ncells = (dims.x * dims.y * dims.z) as usize;
        self.starts.clear();
        self.starts.resize(ncells + 1, 0);
        for &c in &self.cell_of {
            self.starts[c as usize + 1] += 1;
        }
        for c in 0..ncells {
            self.starts[c + 1] += self.starts[c];
        }
        // Stable placement: entries of a cell stay in ascending index order.
        let n = self.cell_of.len();
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.starts);
        self.entries.clear();
        self.entries.resize(n, 0);
        self.positions.clear();
        self.positions.resize(n, Vec3A::ZERO);
        self.slots.clear();
        self.slots.resize(n, 0);
        for (i, &c) in self.cell_of.iter().enumerate() {
            let slot = self.cursor[c as usize] as usize;
            self.cursor[c as usize] += 1;
            self.entries[slot] = i as u32;
            self.positions[slot] = Vec3A::from(point(i));
            self.slots[i] = slot as u32;
        }
    }

    #[inline]
    fn cell_coord(&self, p: Vec3) -> IVec3 {
        self.layout.coord(p)
    }

    /// Entry indices in the grid's order (by cell, ascending within a cell): slot `k` of
    /// [`Grid::for_each_slot_within`] holds entry `entries()[k]`.
    pub fn entries(&self) -> &[u32] {
        &self.entries
    }

    /// Calls `visit(index, position, squared distance)` for every entry within `radius` of
    /// `center`, in a fixed order (cells by z, y, x; indices ascending within a cell).
    #[inline]
    pub fn for_each_within(
        &self,
        center: Vec3,
        radius: f32,
        mut visit: impl FnMut(u32, Vec3, f32),
    ) {
        self.for_each_slot_within(center, radius, |k, p, d2| {
            visit(self.entries[k], p.into(), d2)
        });
    }

    /// Like [`Grid::for_each_within`], but passes the entry's slot in the grid's order (see
    /// [`Grid::entries`]), so that data laid out in that order is read sequentially.
    #[inline]
    pub fn for_each_slot_within(
        &self,
        center: Vec3,
        radius: f32,
        mut visit: impl FnMut(usize, Vec3A, f32),
    ) {
        let c = Vec3A::from(center);
        // Filled before it is read, row by row: initialized once per query.
        let mut hits = [(0u32, 0.0f32); CHUNK];
        let r2 = radius * radius;
        self.for_each_row_within(center, radius, |mut s, e| {
            // Candidates in range are first gathered without a branch (about half of them are
            // out of range, at random: a branch per candidate mispredicts often), then visited
            // in order.
            while s < e {
                let end = e.min(s + CHUNK);
                let mut m = 0;
                for (k, &p) in self.positions[s..end].iter().enumerate() {
                    let d2 = (p - c).length_squared();
                    hits[m] = ((s + k) as u32, d2);
                    m += (d2 <= r2) as usize;
                }
                for &(k, d2) in &hits[..m] {
                    visit(k as usize, self.positions[k as usize], d2);
                }
                s = end;
            }
        });
    }

    /// Calls `visit(start, end)` for each run of slots (see [`Grid::entries`]) that may hold
    /// entries within `radius` of `center`: the cells of one row of the query box, whose
    /// entries are contiguous. Runs come in the order of [`Grid::for_each_within`].
    #[inline]
    pub fn for_each_row_within(
        &self,
        center: Vec3,
        radius: f32,
        mut visit: impl FnMut(usize, usize),
    ) {
        if self.entries.is_empty() || radius.is_nan() || radius < 0.0 {
            return;
        }
        let lo = self.cell_coord(center - Vec3::splat(radius));
        let hi = self.cell_coord(center + Vec3::splat(radius));
        // Narrow cells along x: the query box's own x extent, [center.x − r, center.x + r],
        // bounds every row to within a cell's width.
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                let row = self.cell_index(IVec3::new(lo.x, y, z));
                let row_end = self.cell_index(IVec3::new(hi.x, y, z));
                // Cells lo.x..=hi.x of one row are adjacent, so their entries are contiguous.
                let (s, e) = (self.starts[row] as usize, self.starts[row_end + 1] as usize);
                if s < e {
                    visit(s, e);
                }
            }
        }
    }

    #[inline]
    fn cell_index(&self, c: IVec3) -> usize {
        cell_index(self.layout.dims, c)
    }

    /// Slot of each entry index in the grid's order: `entries()[slots()[i]] == i`.
    pub fn slots(&self) -> &[u32] {
        &self.slots
    }

    /// Positions of the entries, in the grid's order.
    pub fn positions(&self) -> &[Vec3A] {
        &self.positions
    }
}

/// Where a grid over some bounds puts a point: its cells' size, origin and count along each axis.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Layout {
    cell: Vec3,
    inv_cell: Vec3,
    origin: Vec3,
    dims: IVec3,
}

impl Layout {
    /// The layout [`Grid::rebuild`] uses for `n` points over `bounds` with cells of about
    /// `cell`.
    pub fn new(bounds: Aabb, cell: f32, n: usize) -> Layout {
        let size = bounds.size().max(Vec3::splat(1e-3));
        let mut cell = if cell.is_finite() && cell > 1e-3 {
            cell
        } else {
            1.0
        };
        let max_extent = size.max_element();
        if max_extent / cell > MAX_DIM as f32 {
            cell = max_extent / MAX_DIM as f32;
        }
        // A few cells per point at most: a large, sparse world gets larger cells instead of a
        // cell table bigger than the points it indexes.
        let max_cells = 4 * n as i64 + 4096;
        let dims_for = |cell: Vec3| ((size / cell).ceil().as_ivec3()).max(IVec3::ONE);
        let cells = |d: IVec3| {
            let d = d.as_i64vec3();
            d.x * d.y * d.z
        };
        while cells(dims_for(Vec3::splat(cell))) > max_cells {
            cell *= 1.25;
        }
        // Narrower cells along x, as many as the same limits allow.
        let mut cells3 = Vec3::splat(cell);
        for split in (1..=X_SPLIT).rev() {
            let c = Vec3::new(cell / split as f32, cell, cell);
            let d = dims_for(c);
            if split == 1 || (d.x <= MAX_DIM * X_SPLIT && cells(d) <= max_cells) {
                cells3 = c;
                break;
            }
        }
        let inv_cell = cells3.recip();
        Layout {
            cell: cells3,
            inv_cell,
            origin: bounds.min,
            dims: ((size * inv_cell).ceil().as_ivec3()).max(IVec3::ONE),
        }
    }

    /// The cell `p` falls in: a grid with this layout lists its entries by this number, in
    /// ascending order.
    #[inline]
    pub fn cell_of(&self, p: Vec3) -> u32 {
        cell_index(self.dims, self.coord(p)) as u32
    }

    /// The cell coordinates of `p` (see [`cell_coord`]).
    #[inline]
    fn coord(&self, p: Vec3) -> IVec3 {
        cell_coord(self.origin, self.inv_cell, self.dims, p)
    }
}

/// Cell of `p` in a grid at `origin` with cells of `1 / inv_cell` (a point outside, however
/// far, is clamped into an edge cell; a NaN coordinate counts as the first cell along its axis).
/// Infinities are clamped, not zeroed: a query box `center ± radius` with a huge finite radius
/// overflows to ±∞ along the narrow x cells first, and must still reach the edge cells.
#[inline]
fn cell_coord(origin: Vec3, inv_cell: Vec3, dims: IVec3, p: Vec3) -> IVec3 {
    floor_clamped((p - origin) * inv_cell, dims)
}

/// Index of cell `c` (x fastest, then y, then z).
#[inline]
fn cell_index(dims: IVec3, c: IVec3) -> usize {
    ((c.z * dims.y + c.y) * dims.x + c.x) as usize
}

/// `q.floor().as_ivec3().clamp(0, dims − 1)` (±∞ saturate, NaN is 0), without `floorf` (a
/// library call on baseline x86-64): truncated, then clamped as integers. Truncation is the
/// floor wherever the clamp keeps the result: at and above 0 they agree, and in (−1, 0), where
/// they differ (0 against −1), both clamp to 0. The cast saturates (±∞, and anything past
/// `i32`) and takes NaN to 0, so every input lands in `[0, dims − 1]`. Axis by axis in scalar
/// code (every cell lookup comes here).
#[inline]
pub(crate) fn floor_clamped(q: Vec3, dims: IVec3) -> IVec3 {
    #[inline(always)]
    fn axis(v: f32, cells: i32) -> i32 {
        (v as i32).clamp(0, (cells - 1).max(0))
    }
    IVec3::new(axis(q.x, dims.x), axis(q.y, dims.y), axis(q.z, dims.z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::Rng;

    #[test]
    fn a_layout_numbers_points_by_the_cell_its_grid_puts_them_in() {
        // Hand-computed: 40 × 8 × 40 with cells of 8 → x cells of 8 / 4 = 2, dims (20, 1, 5);
        // (5, 1, 17) is in cell (2, 0, 2), number (2·1 + 0)·20 + 2 = 42.
        let bounds = Aabb::new(Vec3::ZERO, Vec3::new(40.0, 8.0, 40.0));
        let l = Layout::new(bounds, 8.0, 1000);
        assert_eq!(
            (l.cell, l.dims),
            (Vec3::new(2.0, 8.0, 8.0), IVec3::new(20, 1, 5))
        );
        assert_eq!(l.cell_of(Vec3::new(5.0, 1.0, 17.0)), 42);
        // The grid built over the same points lists them in that order.
        let mut rng = Rng::new(5, 0);
        let bounds = Aabb::new(Vec3::new(-10.0, 0.0, -20.0), Vec3::new(30.0, 8.0, 20.0));
        let pts: Vec<Vec3> = (0..500)
            .map(|_| {
                bounds.min
                    + bounds.size() * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32())
            })
            .collect();
        let mut g = Grid::new();
        g.rebuild(bounds, 3.0, pts.iter().copied());
        let l = Layout::new(bounds, 3.0, pts.len());
        assert_eq!(g.layout, l);
        let keys: Vec<u32> = g
            .entries()
            .iter()
            .map(|&i| l.cell_of(pts[i as usize]))
            .collect();
        // Each entry's slot lies within its cell's run.
        for (slot, &k) in keys.iter().enumerate() {
            let k = k as usize;
            assert!((g.starts[k] as usize..g.starts[k + 1] as usize).contains(&slot));
        }
    }

    #[test]
    fn floor_clamped_is_floor_then_clamp() {
        let dims = IVec3::new(7, 300, 1 << 30);
        let mut rng = Rng::new(9, 0);
        let mut values = vec![
            0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 6.999, 7.0, 2.5e9, -2.5e9, 1e30,
        ];
        values.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
        values.extend([f32::MIN_POSITIVE, 1e-45]);
        values.extend((0..2000).map(|_| rng.range(-400.0, 400.0)));
        for &x in &values {
            let q = Vec3::new(x, x * 0.5, -x);
            let expect = q.floor().as_ivec3().clamp(IVec3::ZERO, dims - IVec3::ONE);
            assert_eq!(floor_clamped(q, dims), expect, "{q}");
        }
    }

    #[test]
    fn finds_exactly_the_points_a_brute_force_finds() {
        let bounds = Aabb::new(Vec3::ZERO, Vec3::splat(100.0));
        let mut rng = Rng::new(1, 0);
        let pts: Vec<Vec3> = (0..2000)
            .map(|_| {
                Vec3::new(
                    rng.range(0.0, 100.0),
                    rng.range(0.0, 100.0),
                    rng.range(0.0, 100.0),
                )
            })
            .collect();
        let mut g = Grid::new();
        g.rebuild(bounds, 7.0, pts.iter().copied());
        // The parallel gather builds the same grid; `slots` inverts `entries`.
        let mut h = Grid::new();
        h.rebuild_with(bounds, 7.0, pts.len(), |i| pts[i]);
        assert_eq!((g.entries(), g.positions()), (h.entries(), h.positions()));
        for (i, &k) in g.slots().iter().enumerate() {
            assert_eq!(g.entries()[k as usize] as usize, i);
        }
        for q in 0..50 {
            let c = pts[q * 7];
            let mut found = Vec::new();
            g.for_each_within(c, 9.0, |i, _, _| found.push(i));
            found.sort();
            assert_eq!(found, brute(&pts, c, 9.0));
        }
    }

    #[test]
    fn points_outside_bounds_are_clamped_into_edge_cells() {
        let bounds = Aabb::new(Vec3::ZERO, Vec3::splat(10.0));
        let mut g = Grid::new();
        g.rebuild(
            bounds,
            2.0,
            [Vec3::splat(-5.0), Vec3::splat(50.0)].into_iter(),
        );
        let mut n = 0;
        g.for_each_within(Vec3::splat(-5.0), 0.5, |_, _, _| n += 1);
        assert_eq!(n, 1);
    }

    /// Every point within `radius` of `c`, by brute force, sorted.
    fn brute(pts: &[Vec3], c: Vec3, radius: f32) -> Vec<u32> {
        (0..pts.len() as u32)
            .filter(|&i| (pts[i as usize] - c).length() <= radius)
            .collect()
    }

    #[test]
    fn narrow_cells_read_less_and_still_find_every_point() {
        // A flat world far from the origin (rounding in the cell arithmetic is largest there),
        // points on the sphere's rim and beyond the bounds included.
        let o = Vec3::new(10_000.0, -5.0, -20_000.0);
        let bounds = Aabb::new(o, o + Vec3::new(300.0, 10.0, 300.0));
        let mut rng = Rng::new(4, 0);
        let mut pts: Vec<Vec3> = (0..3000)
            .map(|_| o + Vec3::new(rng.range(-5.0, 305.0), 5.0, rng.range(-5.0, 305.0)))
            .collect();
        let centers: Vec<Vec3> = (0..60).map(|k| pts[k * 41]).collect();
        for (k, &c) in centers.iter().enumerate() {
            let a = k as f32 * 0.7;
            pts.push(c + Vec3::new(crate::math::cos(a), 0.0, crate::math::sin(a)) * 10.0);
        }
        let mut g = Grid::new();
        g.rebuild(bounds, 10.0, pts.iter().copied());
        assert_eq!(g.cell_sizes(), Vec3::new(10.0 / X_SPLIT as f32, 10.0, 10.0));
        let (mut candidates, mut square) = (0, 0);
        for &c in &centers {
            let mut found = Vec::new();
            g.for_each_within(c, 10.0, |i, _, _| found.push(i));
            found.sort();
            assert_eq!(found, brute(&pts, c, 10.0), "around {c}");
            g.for_each_row_within(c, 10.0, |s, e| candidates += e - s);
            // What square cells of the radius would read: the 3 × 3 cells the box overlaps.
            let cell = |v: f32, o: f32| ((v - o) / 10.0).floor();
            let near = |v: f32, at: f32, o: f32| {
                (cell(at - 10.0, o)..=cell(at + 10.0, o)).contains(&cell(v, o))
            };
            square += pts
                .iter()
                .filter(|p| near(p.x, c.x, o.x) && near(p.z, c.z, o.z))
                .count();
        }
        // Rows of 2r plus a narrow cell instead of 3r: about three quarters.
        assert!(
            (candidates as f32) < 0.85 * square as f32,
            "{candidates} candidates where square cells read {square}"
        );
    }

    #[test]
    fn a_point_on_a_slab_boundary_at_the_radius_is_still_found() {
        // Points a few units in the last place either side of each cell boundary along y, and
        // queries exactly a radius below them: the rounding of a point's cell and of the
        // slab's bound must not leave a point within the radius out of its chord.
        let o = Vec3::new(3.0, -1234.5, 7.0);
        let bounds = Aabb::new(o, o + Vec3::new(20.0, 100.0, 20.0));
        let h = 0.7;
        let r = 2.3;
        let mut pts = Vec::new();
        let mut centers = Vec::new();
        for k in 1..140 {
            let b = o.y + k as f32 * h;
            let mut y = b;
            for _ in 0..4 {
                y = f32::from_bits(y.to_bits() - 1);
            }
            for _ in 0..8 {
                pts.push(Vec3::new(10.0, y, 10.0));
                centers.push(Vec3::new(10.0, y - r, 10.0));
                centers.push(Vec3::new(10.0 + r * 0.6, y - r * 0.8, 10.0));
                y = f32::from_bits(y.to_bits() + 1);
            }
        }
        let mut g = Grid::new();
        g.rebuild(bounds, h, pts.iter().copied());
        let mut checked = 0;
        for &c in &centers {
            let want: Vec<u32> = (0..pts.len() as u32)
                .filter(|&i| (pts[i as usize] - c).length_squared() <= r * r)
                .collect();
            let mut found = Vec::new();
            g.for_each_within(c, r, |i, _, _| found.push(i));
            found.sort();
            assert_eq!(found, want, "around {c}");
            checked += want.len();
        }
        assert!(checked > 1000, "{checked}");
    }

    #[test]
    fn a_huge_radius_reaches_every_cell() {
        // With cells of 0.25 along x, `center.x + 1e38` overflows to +∞ where the same box
        // along y and z stays finite: the box must still span the grid, not collapse to a cell.
        let bounds = Aabb::new(Vec3::ZERO, Vec3::new(100.0, 0.0, 100.0));
        let pts: Vec<Vec3> = (0..100)
            .flat_map(|x| (0..100).map(move |z| Vec3::new(x as f32 + 0.5, 0.0, z as f32 + 0.5)))
            .collect();
        let mut g = Grid::new();
        g.rebuild(bounds, 1.0, pts.iter().copied());
        for r in [1e30, 1e38, 2e38, f32::MAX, f32::INFINITY] {
            let mut n = 0;
            g.for_each_within(Vec3::new(50.0, 50.0, 50.0), r, |_, _, _| n += 1);
            assert_eq!(n, pts.len(), "radius {r}");
        }
    }
}
