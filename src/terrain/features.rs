//! Feature data fused into the elevation grid, and the cost and blocked maps a species derives
//! from it, seed 004 ("build the cultural-feature database … fuse it with the terrain model").
//!
//! Not a tick stage: run once per scenario load (rasterising) and once per species mobility
//! (cost maps). A feature file is RON in serde's externally tagged form:
//!
//! ```ron
//! Features(items: [
//!     Road(points: [(10.0, 20.0), (80.0, 20.0)], width: 4.0),
//!     River(points: [(0.0, 50.0), (100.0, 60.0)], width: 6.0),
//!     Vegetation(polygon: [(0.0, 0.0), (30.0, 0.0), (30.0, 30.0)], density: 0.6),
//!     Building(polygon: [(40.0, 40.0), (48.0, 40.0), (48.0, 46.0), (40.0, 46.0)]),
//!     Water(polygon: [(60.0, 60.0), (70.0, 60.0), (65.0, 70.0)]),
//!     Point(at: (20.0, 70.0), kind: Building),
//! ])
//! ```
//!
//! Coordinates are world `(x, z)`. A line feature covers the cells whose centre lies within half
//! its width of the line, and every cell the line itself passes through; an area covers the cells
//! whose centre lies inside it and every cell its outline passes through.

use super::grid::{supercover, Cell};
use super::{CostGrid, Terrain};
use crate::diag::{Diagnostic, Diagnostics};
use glam::Vec2;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Per-cell attributes fused from the feature data.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CellAttrs {
    /// Bit set of [`CellAttrs::ROAD`], [`CellAttrs::RIVER`], [`CellAttrs::BUILDING`],
    /// [`CellAttrs::WATER`], [`CellAttrs::NODATA`].
    pub flags: u8,
    /// Vegetation density in `[0, 1]` (the densest feature covering the cell).
    pub vegetation: f32,
}

impl CellAttrs {
    /// A road crosses the cell.
    pub const ROAD: u8 = 1;
    /// A river crosses the cell.
    pub const RIVER: u8 = 2;
    /// A building stands on the cell.
    pub const BUILDING: u8 = 4;
    /// Standing water (lake, pond) covers the cell.
    pub const WATER: u8 = 8;
    /// The elevation data had no value for the cell.
    pub const NODATA: u8 = 16;

    /// Whether a road crosses the cell.
    pub fn road(&self) -> bool {
        self.flags & Self::ROAD != 0
    }
    /// Whether a river crosses the cell.
    pub fn river(&self) -> bool {
        self.flags & Self::RIVER != 0
    }
    /// Whether a building stands on the cell.
    pub fn building(&self) -> bool {
        self.flags & Self::BUILDING != 0
    }
    /// Whether standing water covers the cell.
    pub fn water(&self) -> bool {
        self.flags & Self::WATER != 0
    }
    /// Whether the elevation data had no value for the cell.
    pub fn nodata(&self) -> bool {
        self.flags & Self::NODATA != 0
    }
}

/// What a single-cell point feature is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PointKind {
    /// A building (hut, tower) filling one cell.
    Building,
    /// A well, pond or crater filling one cell.
    Water,
    /// A tree or thicket of the given density.
    Vegetation(f32),
}

/// One feature of a feature file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Feature {
    /// A road along a polyline, `width` world units wide.
    Road {
        /// The polyline, world `(x, z)`, at least two points.
        points: Vec<(f32, f32)>,
        /// Full width in world units, > 0.
        width: f32,
    },
    /// A river along a polyline.
    River {
        /// The polyline, world `(x, z)`, at least two points.
        points: Vec<(f32, f32)>,
        /// Full width in world units, > 0.
        width: f32,
    },
    /// An area of vegetation.
    Vegetation {
        /// The outline, world `(x, z)`, at least three points.
        polygon: Vec<(f32, f32)>,
        /// Density in `[0, 1]`.
        density: f32,
    },
    /// A building's footprint.
    Building {
        /// The outline, world `(x, z)`, at least three points.
        polygon: Vec<(f32, f32)>,
    },
    /// Standing water.
    Water {
        /// The outline, world `(x, z)`, at least three points.
        polygon: Vec<(f32, f32)>,
    },
    /// A feature filling the one cell that contains `at`.
    Point {
        /// World `(x, z)`.
        at: (f32, f32),
        /// What stands there.
        kind: PointKind,
    },
}

/// A feature file: the list of features to rasterise onto a terrain.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Features {
    /// The features, applied in order (later ones add to earlier ones).
    pub items: Vec<Feature>,
}

impl Features {
    /// Reads and parses a feature file.
    pub fn load(path: &Path) -> Result<Features, Diagnostics> {
        let text = crate::diag::read_text(path, "feature file")?;
        Features::parse(&text, path)
    }

    /// Parses a feature file's text; `file` names it in diagnostics. Syntax errors, unknown
    /// fields or variants and out-of-range values are located at their line and column.
    pub fn parse(text: &str, file: impl AsRef<Path>) -> Result<Features, Diagnostics> {
        let file = file.as_ref();
        let features: Features =
            ron::from_str(text).map_err(|e| crate::load::ron_diag(file, text, &e))?;
        let problems: Vec<Diagnostic> = features
            .items
            .iter()
            .enumerate()
            .filter_map(|(i, f)| f.problem().map(|msg| (i, msg)))
            .map(|(i, msg)| {
                let (line, col) = nth_item_position(text, i).unwrap_or((0, 0));
                Diagnostic::new(
                    file,
                    line,
                    col,
                    format!("feature {}: {msg}", i + 1),
                    Some(text),
                )
            })
            .collect();
        if problems.is_empty() {
            Ok(features)
        } else {
            Err(Diagnostics(problems))
        }
    }
}

impl Feature {
    /// What is wrong with this feature's values, if anything.
    fn problem(&self) -> Option<String> {
        let bad_width = |w: f32| !(w.is_finite() && w > 0.0);
        let bad_points =
            |p: &[(f32, f32)]| p.iter().any(|&(x, z)| !(x.is_finite() && z.is_finite()));
        let area = |p: &[(f32, f32)]| {
            if p.len() < 3 {
                Some("an area needs at least three points".to_string())
            } else if bad_points(p) {
                Some("point coordinates must be finite".to_string())
            } else {
                None
            }
        };
        match self {
            Feature::Road { points, width } | Feature::River { points, width } => {
                if points.len() < 2 {
                    Some("a line needs at least two points".into())
                } else if bad_points(points) {
                    Some("point coordinates must be finite".into())
                } else if bad_width(*width) {
                    Some(format!("width must be a positive number, found {width}"))
                } else {
                    None
                }
            }
            Feature::Vegetation { polygon, density } => {
                if !(0.0..=1.0).contains(density) {
                    Some(format!("density must lie in [0, 1], found {density}"))
                } else {
                    area(polygon)
                }
            }
            Feature::Building { polygon } | Feature::Water { polygon } => area(polygon),
            Feature::Point { at, kind } => {
                if !(at.0.is_finite() && at.1.is_finite()) {
                    Some("point coordinates must be finite".into())
                } else if matches!(kind, PointKind::Vegetation(d) if !(0.0..=1.0).contains(d)) {
                    Some("density must lie in [0, 1]".into())
                } else {
                    None
                }
            }
        }
    }
}

/// Line and column of the `n`th element of the first `[ … ]` list after `items`, found by a
/// bracket-aware scan (strings and comments skipped); used to locate value errors found after
/// parsing.
fn nth_item_position(text: &str, n: usize) -> Option<(usize, usize)> {
    let start = text.find("items")?;
    let open = start + text[start..].find('[')?;
    let (mut depth, mut index, mut expecting) = (0i32, 0usize, true);
    let mut chars = text[open + 1..].char_indices().peekable();
    while let Some((off, ch)) = chars.next() {
        let abs = open + 1 + off;
        match ch {
            '/' if matches!(chars.peek(), Some((_, '/'))) => {
                for (_, c) in chars.by_ref() {
                    if c == '\n' {
                        break;
                    }
                }
                continue;
            }
            '"' => {
                let mut escaped = false;
                for (_, c) in chars.by_ref() {
                    if c == '"' && !escaped {
                        break;
                    }
                    escaped = c == '\\' && !escaped;
                }
                continue;
            }
            c if c.is_whitespace() => continue,
            _ => {}
        }
        if depth == 0 && expecting {
            if ch == ']' {
                return None;
            }
            if index == n {
                let before = &text[..abs];
                let line = before.matches('\n').count() + 1;
                let col = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
                return Some((line, col));
            }
            expecting = false;
        }
        match ch {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' | '}' if depth == 0 => return None,
            ')' | ']' | '}' => depth -= 1,
            ',' if depth == 0 => {
                index += 1;
                expecting = true;
            }
            _ => {}
        }
    }
    None
}

/// How a species moves over terrain: what blocks it and what slows it.
///
/// The cost of a cell is a multiplier of distance:
/// `(1 + slope_cost · slope / max_slope_deg) · (1 + vegetation_factor · density)`, times
/// `road_factor` on roads and `water_factor` on rivers and water that do not block. A road over a
/// river is a bridge: neither blocks nor slows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Mobility {
    /// Cells steeper than this (degrees) are blocked.
    pub max_slope_deg: f32,
    /// Extra cost at the slope limit (0 = slope costs nothing below the limit).
    pub slope_cost: f32,
    /// Cost multiplier on roads (< 1 makes roads attractive).
    pub road_factor: f32,
    /// Extra cost per unit of vegetation density.
    pub vegetation_factor: f32,
    /// Vegetation at least this dense blocks (above 1: never).
    pub vegetation_blocks_at: f32,
    /// Whether rivers and standing water block.
    pub water_blocks: bool,
    /// Cost multiplier on rivers and water when they do not block (wading, swimming).
    pub water_factor: f32,
    /// Whether buildings block.
    pub buildings_block: bool,
}

impl Default for Mobility {
    fn default() -> Self {
        Mobility {
            max_slope_deg: 30.0,
            slope_cost: 1.0,
            road_factor: 0.6,
            vegetation_factor: 1.5,
            vegetation_blocks_at: 1.1,
            water_blocks: true,
            water_factor: 4.0,
            buildings_block: true,
        }
    }
}

impl Terrain {
    /// Rasterises `features` into the per-cell attributes (adding to what is there).
    pub fn apply_features(&mut self, features: &Features) {
        for f in &features.items {
            match f {
                Feature::Road { points, width } => {
                    self.mark_line(points, *width, |a| a.flags |= CellAttrs::ROAD)
                }
                Feature::River { points, width } => {
                    self.mark_line(points, *width, |a| a.flags |= CellAttrs::RIVER)
                }
                Feature::Vegetation { polygon, density } => {
                    let d = *density;
                    self.mark_area(polygon, |a| a.vegetation = a.vegetation.max(d))
                }
                Feature::Building { polygon } => {
                    self.mark_area(polygon, |a| a.flags |= CellAttrs::BUILDING)
                }
                Feature::Water { polygon } => {
                    self.mark_area(polygon, |a| a.flags |= CellAttrs::WATER)
                }
                Feature::Point { at, kind } => {
                    if let Some(c) = self.cell_of(Vec2::new(at.0, at.1)) {
                        let i = self.index(c);
                        let a = &mut self.attrs[i];
                        match kind {
                            PointKind::Building => a.flags |= CellAttrs::BUILDING,
                            PointKind::Water => a.flags |= CellAttrs::WATER,
                            PointKind::Vegetation(d) => a.vegetation = a.vegetation.max(*d),
                        }
                    }
                }
            }
        }
    }

    /// Fractional cell coordinates of world `p` (cell `(c, r)` spans `[c, c+1) × [r, r+1)`).
    fn to_grid(&self, p: (f32, f32)) -> Vec2 {
        (Vec2::new(p.0, p.1) - self.origin) / self.cell_size
    }

    /// Cells along the segment between two fractional grid points (clamped to the grid).
    fn mark_segment_cells(&mut self, a: Vec2, b: Vec2, mark: &mut impl FnMut(&mut CellAttrs)) {
        let clamp = |p: Vec2| {
            Cell::new(
                (p.x.floor().max(0.0) as usize).min(self.cols - 1),
                (p.y.floor().max(0.0) as usize).min(self.rows - 1),
            )
        };
        let (ca, cb) = (clamp(a), clamp(b));
        let cols = self.cols;
        let attrs = &mut self.attrs;
        supercover(ca, cb, |c, r| {
            mark(&mut attrs[r as usize * cols + c as usize]);
            true
        });
    }

    fn mark_line(
        &mut self,
        points: &[(f32, f32)],
        width: f32,
        mut mark: impl FnMut(&mut CellAttrs),
    ) {
        let half = 0.5 * width / self.cell_size;
        for w in points.windows(2) {
            let (a, b) = (self.to_grid(w[0]), self.to_grid(w[1]));
            self.mark_segment_cells(a, b, &mut mark);
            let lo = a.min(b) - Vec2::splat(half + 1.0);
            let hi = a.max(b) + Vec2::splat(half + 1.0);
            let (c0, c1) = (
                lo.x.floor().max(0.0) as usize,
                (hi.x.ceil().max(0.0) as usize).min(self.cols),
            );
            let (r0, r1) = (
                lo.y.floor().max(0.0) as usize,
                (hi.y.ceil().max(0.0) as usize).min(self.rows),
            );
            for r in r0..r1 {
                for c in c0..c1 {
                    let p = Vec2::new(c as f32 + 0.5, r as f32 + 0.5);
                    if distance_to_segment(p, a, b) <= half {
                        mark(&mut self.attrs[r * self.cols + c]);
                    }
                }
            }
        }
    }

    fn mark_area(&mut self, polygon: &[(f32, f32)], mut mark: impl FnMut(&mut CellAttrs)) {
        let pts: Vec<Vec2> = polygon.iter().map(|&p| self.to_grid(p)).collect();
        let (mut lo, mut hi) = (pts[0], pts[0]);
        for &p in &pts {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let (c0, c1) = (
            lo.x.floor().max(0.0) as usize,
            (hi.x.ceil().max(0.0) as usize).min(self.cols),
        );
        let (r0, r1) = (
            lo.y.floor().max(0.0) as usize,
            (hi.y.ceil().max(0.0) as usize).min(self.rows),
        );
        for r in r0..r1 {
            for c in c0..c1 {
                if point_in_polygon(Vec2::new(c as f32 + 0.5, r as f32 + 0.5), &pts) {
                    mark(&mut self.attrs[r * self.cols + c]);
                }
            }
        }
        for i in 0..pts.len() {
            self.mark_segment_cells(pts[i], pts[(i + 1) % pts.len()], &mut mark);
        }
    }

    /// The planning grid for a species: blocked where too steep, where there is no data, and
    /// where buildings, water or dense vegetation block it; costs as documented on [`Mobility`].
    pub fn cost_grid(&self, m: &Mobility) -> CostGrid {
        let mut grid = CostGrid::open(self.cols, self.rows, self.cell_size, self.origin);
        for r in 0..self.rows {
            for c in 0..self.cols {
                let i = r * self.cols + c;
                let a = self.attrs[i];
                let slope = self.cell_slope_deg(Cell::new(c, r));
                let wet = a.river() || a.water();
                let bridge = a.road() && wet;
                let blocked = a.nodata()
                    || slope > m.max_slope_deg
                    || (a.building() && m.buildings_block)
                    || (wet && !bridge && m.water_blocks)
                    || a.vegetation >= m.vegetation_blocks_at;
                let mut cost = (1.0 + m.slope_cost * (slope / m.max_slope_deg).min(1.0))
                    * (1.0 + m.vegetation_factor * a.vegetation);
                if a.road() {
                    cost *= m.road_factor;
                } else if wet {
                    cost *= m.water_factor;
                }
                grid.blocked[i] = blocked;
                grid.cost[i] = cost.max(1e-3);
            }
        }
        grid
    }
}

fn distance_to_segment(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

/// Even–odd rule.
fn point_in_polygon(p: Vec2, poly: &[Vec2]) -> bool {
    let mut inside = false;
    let mut j = poly.len() - 1;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[j]);
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
        j = i;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(cols: usize, rows: usize) -> Terrain {
        Terrain::from_heights(cols, rows, 2.0, Vec2::ZERO, vec![0.0; cols * rows])
    }

    #[test]
    fn parses_and_rasterises_features() {
        let text = r#"Features(items: [
            Road(points: [(0.0, 5.0), (40.0, 5.0)], width: 2.0),
            River(points: [(9.0, 0.0), (9.0, 40.0)], width: 4.0),
            Vegetation(polygon: [(20.0, 20.0), (40.0, 20.0), (40.0, 40.0), (20.0, 40.0)], density: 0.5),
            Building(polygon: [(2.0, 12.0), (6.0, 12.0), (6.0, 16.0), (2.0, 16.0)]),
            Water(polygon: [(30.0, 2.0), (36.0, 2.0), (33.0, 8.0)]),
            Point(at: (15.0, 35.0), kind: Building),
        ])"#;
        let f = Features::parse(text, "f.ron").unwrap();
        assert_eq!(f.items.len(), 6);
        let mut t = flat(20, 20);
        t.apply_features(&f);
        let at = |x: f32, z: f32| t.attrs[t.index(t.cell_of(Vec2::new(x, z)).unwrap())];
        assert!(at(1.0, 5.0).road() && at(39.0, 5.0).road() && !at(1.0, 9.0).road());
        assert!(at(9.0, 1.0).river() && at(9.0, 39.0).river() && !at(13.0, 20.0).river());
        assert_eq!(at(30.0, 30.0).vegetation, 0.5);
        assert_eq!(at(10.0, 30.0).vegetation, 0.0);
        assert!(at(4.0, 14.0).building() && !at(9.0, 14.0).building());
        assert!(at(33.0, 4.0).water());
        assert!(at(15.0, 35.0).building());

        let g = t.cost_grid(&Mobility::default());
        let cell = |x: f32, z: f32| g.index(g.cell_of(Vec2::new(x, z)).unwrap());
        assert!(g.blocked[cell(4.0, 14.0)], "building blocks");
        assert!(g.blocked[cell(9.0, 20.0)], "river blocks");
        assert!(!g.blocked[cell(9.0, 5.0)], "the road bridges the river");
        assert_eq!(g.cost[cell(1.0, 5.0)], 0.6);
        assert_eq!(g.cost[cell(30.0, 30.0)], 1.75);
        assert_eq!(g.cost[cell(15.0, 25.0)], 1.0);
    }

    #[test]
    fn steep_cells_are_blocked_per_species() {
        // A 1-in-1 step (45°) between columns 4 and 5.
        let h = (0..100)
            .map(|i| if i % 10 >= 5 { 4.0 } else { 0.0 })
            .collect();
        let t = Terrain::from_heights(10, 10, 2.0, Vec2::ZERO, h);
        let goat = Mobility {
            max_slope_deg: 50.0,
            ..Mobility::default()
        };
        let cart = Mobility::default();
        assert!(t.cost_grid(&cart).blocked[4]);
        assert!(!t.cost_grid(&goat).blocked[4]);
        assert!(!t.cost_grid(&cart).blocked[0]);
    }

    #[test]
    fn unknown_field_is_located() {
        let text = "Features(items: [\n    Road(points: [(0.0, 0.0), (1.0, 1.0)], widht: 4.0),\n])";
        let d = Features::parse(text, "f.ron").unwrap_err().0.remove(0);
        assert_eq!((d.line, d.col), (2, 44));
        assert!(d.message.contains("widht"), "{}", d.message);
    }

    #[test]
    fn unknown_variant_is_located() {
        let text = "Features(items: [\n  Road(points: [(0.0, 0.0), (1.0, 1.0)], width: 4.0),\n  Swamp(polygon: []),\n])";
        let d = Features::parse(text, "f.ron").unwrap_err().0.remove(0);
        assert_eq!(d.line, 3);
        assert!(d.message.contains("Swamp"), "{}", d.message);
    }

    #[test]
    fn bad_values_are_located_at_their_feature() {
        let text = "Features(items: [\n  Road(points: [(0.0, 0.0), (1.0, 1.0)], width: 4.0),\n  Vegetation(polygon: [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)], density: 1.5),\n])";
        let d = Features::parse(text, "f.ron").unwrap_err().0.remove(0);
        assert_eq!((d.line, d.col), (3, 3));
        assert_eq!(
            d.message,
            "feature 2: density must lie in [0, 1], found 1.5"
        );
    }
}
