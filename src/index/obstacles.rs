//! Stage 1 of the tick, static part: a uniform grid over the world bounds listing, for each cell,
//! the obstacles whose bounding sphere, grown by the largest sensing range, reaches into it. A
//! perceiver looks only at its own cell's list (ascending obstacle index, as a scan of every
//! obstacle would meet them), so perception costs O(N·k) however many obstacles the world holds.
//! Rebuilt only when the obstacles, the bounds or the range change.

use crate::world::{Aabb, Obstacle};
use glam::{IVec3, Vec3};

/// Obstacles by cell.
#[derive(Debug, Clone, Default)]
pub struct ObstacleGrid {
    origin: Vec3,
    inv_cell: f32,
    dims: IVec3,
    /// `starts[c]..starts[c+1]` are the obstacles of cell `c`.
    starts: Vec<u32>,
    entries: Vec<u32>,
    /// What the grid was built from.
    built_from: Option<(Aabb, f32, Vec<Obstacle>)>,
    /// Scratch: cell ranges per obstacle.
    spans: Vec<(IVec3, IVec3)>,
}

/// Most cells of an obstacle grid.
const MAX_CELLS: i64 = 1 << 18;

impl ObstacleGrid {
    /// An empty grid.
    pub fn new() -> Self {
        Self::default()
    }

    /// Makes the grid list every active obstacle within `reach` of each cell of `bounds`
    /// (`reach`: the largest distance a query will ask about). Does nothing when nothing changed.
    pub fn update(&mut self, bounds: Aabb, reach: f32, obstacles: &[Obstacle]) {
        if let Some((b, r, o)) = &self.built_from {
            if *b == bounds && *r == reach && o.as_slice() == obstacles {
                return;
            }
        }
        let reach = if reach.is_finite() {
            reach.max(0.0)
        } else {
            0.0
        };
        let size = bounds.size().max(Vec3::splat(1e-3));
        let mut cell = reach.max(size.max_element() / 256.0).max(1e-3);
        let dims_for = |cell: f32| ((size / cell).ceil().as_ivec3()).max(IVec3::ONE);
        while {
            let d = dims_for(cell).as_i64vec3();
            d.x * d.y * d.z > MAX_CELLS
        } {
            cell *= 1.25;
        }
        self.origin = bounds.min;
        self.inv_cell = 1.0 / cell;
        self.dims = dims_for(cell);
        let ncells = (self.dims.x * self.dims.y * self.dims.z) as usize;
        self.starts.clear();
        self.starts.resize(ncells + 1, 0);
        self.spans.clear();
        for o in obstacles {
            let grow = o.shape.bounding_radius() + reach;
            let c = o.shape.center();
            let span = if o.active && grow.is_finite() && c.is_finite() {
                (
                    self.cell_coord(c - Vec3::splat(grow)),
                    self.cell_coord(c + Vec3::splat(grow)),
                )
            } else {
                // Inactive (or degenerate): listed nowhere.
                (IVec3::ONE, IVec3::ZERO)
            };
            self.spans.push(span);
            for_cells(span, self.dims, |c| self.starts[c + 1] += 1);
        }
        for c in 0..ncells {
            self.starts[c + 1] += self.starts[c];
        }
        self.entries.clear();
        self.entries.resize(self.starts[ncells] as usize, 0);
        let mut cursor = self.starts.clone();
        for (k, &span) in self.spans.iter().enumerate() {
            for_cells(span, self.dims, |c| {
                self.entries[cursor[c] as usize] = k as u32;
                cursor[c] += 1;
            });
        }
        self.built_from = Some((bounds, reach, obstacles.to_vec()));
    }

    #[inline]
    fn cell_coord(&self, p: Vec3) -> IVec3 {
        let q = (p - self.origin) * self.inv_cell;
        let q = if q.is_finite() { q } else { Vec3::ZERO };
        super::floor_clamped(q, self.dims)
    }

    /// Indices (ascending) of the obstacles that may lie within the grid's reach of `p`: every
    /// active obstacle whose surface is within reach is among them.
    #[inline]
    pub fn near(&self, p: Vec3) -> &[u32] {
        if self.entries.is_empty() {
            return &[];
        }
        let c = self.cell_coord(p);
        let i = ((c.z * self.dims.y + c.y) * self.dims.x + c.x) as usize;
        &self.entries[self.starts[i] as usize..self.starts[i + 1] as usize]
    }
}

/// Calls `f` with the index of every cell of `span` (inclusive; empty when `lo > hi`).
fn for_cells((lo, hi): (IVec3, IVec3), dims: IVec3, mut f: impl FnMut(usize)) {
    for z in lo.z..=hi.z {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                f(((z * dims.y + y) * dims.x + x) as usize);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Rng, Shape};

    #[test]
    fn lists_every_obstacle_a_scan_finds_in_order() {
        let bounds = Aabb::new(Vec3::ZERO, Vec3::new(200.0, 40.0, 200.0));
        let mut rng = Rng::new(3, 0);
        let mut obstacles: Vec<Obstacle> = (0..300)
            .map(|k| {
                let c = Vec3::new(
                    rng.range(-10.0, 210.0),
                    rng.range(0.0, 40.0),
                    rng.range(-10.0, 210.0),
                );
                let shape = if k % 3 == 0 {
                    Shape::Box(Aabb::new(c, c + Vec3::new(6.0, 2.0, 9.0)))
                } else {
                    Shape::Sphere {
                        center: c,
                        radius: rng.range(0.5, 4.0),
                    }
                };
                Obstacle {
                    id: k,
                    shape,
                    active: true,
                }
            })
            .collect();
        obstacles[7].active = false;
        let mut g = ObstacleGrid::new();
        let reach = 12.0;
        g.update(bounds, reach, &obstacles);
        for _ in 0..2000 {
            let p = Vec3::new(
                rng.range(0.0, 200.0),
                rng.range(0.0, 40.0),
                rng.range(0.0, 200.0),
            );
            let scan: Vec<u32> = (0..obstacles.len() as u32)
                .filter(|&k| {
                    let o = &obstacles[k as usize];
                    o.active && (o.shape.closest_point(p) - p).length() <= reach
                })
                .collect();
            let near = g.near(p);
            assert!(near.windows(2).all(|w| w[0] < w[1]), "ascending");
            assert!(!near.contains(&7), "inactive obstacles are not listed");
            let kept: Vec<u32> = near
                .iter()
                .copied()
                .filter(|&k| {
                    let o = &obstacles[k as usize];
                    (o.shape.closest_point(p) - p).length() <= reach
                })
                .collect();
            assert_eq!(kept, scan);
        }
        // A point with a coordinate that is not finite looks in the first cell, whatever its
        // other coordinates; one far outside but finite, in the edge cell along each axis.
        let first = g.near(bounds.min).to_vec();
        let corner = g.near(bounds.max).to_vec();
        assert_ne!(first, corner, "the two corners list different obstacles");
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for axis in 0..3 {
                let mut p = bounds.max;
                p[axis] = bad;
                assert_eq!(g.near(p), first.as_slice(), "{p}");
            }
        }
        assert_eq!(g.near(bounds.max * 1e6), corner.as_slice());
    }
}
