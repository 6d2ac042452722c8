//! The `plan` benchmark workload: formation-keeping A* + smoothing + follower paths (seed 004) on
//! a 1024² procedural terrain (rolling hills, 2 m cells), a 5-member team (wedge, falling back to
//! a column), task class "may change rarely", corner to opposite corner. `agents` is the team
//! size, `ticks` the number of plans timed and `updates` the search nodes expanded. The
//! `plan-weighted` row plans with a heuristic weight above 1 and notes what the path gave up
//! against the exact plan.

use super::Sample;
use crate::formation::{Formation, FormationShape, PlanRequest, Planner, TaskClass, Weights};
use crate::terrain::{Cell, CostGrid, Mobility, Terrain};
use std::time::Instant;

/// Side of the terrain grid the workload plans on.
pub const TERRAIN_SIDE: usize = 1024;

/// Team size.
pub const MEMBERS: usize = 5;

/// Rolling hills of `n × n` cells of 2 m, relief growing with the map so slopes look alike at
/// every size (the map of this workload and of `benches/plan.rs`).
pub fn hills(n: usize) -> CostGrid {
    Terrain::procedural(n, n, 2.0, 60.0, 2007).cost_grid(&Mobility::default())
}

/// The free cell nearest to `c`, searching outwards in rings.
pub fn free_near(grid: &CostGrid, c: Cell) -> Option<Cell> {
    for radius in 0..grid.cols as i64 {
        for dr in -radius..=radius {
            for dc in -radius..=radius {
                let (col, row) = (c.col as i64 + dc, c.row as i64 + dr);
                if !grid.is_blocked(col, row) {
                    return Some(Cell::new(col as usize, row as usize));
                }
            }
        }
    }
    None
}

/// Measures `passes` plans (at least one) on the workload's terrain with heuristic weight
/// `search_weight` (1: exact); `None` if the map has no path (it always has one with the seed
/// used).
pub fn measure(passes: u64, search_weight: f32) -> Option<Sample> {
    let n = TERRAIN_SIDE;
    let grid = hills(n);
    let formations = [
        Formation::new(&FormationShape::Wedge, MEMBERS, 4.0).ok()?,
        Formation::new(&FormationShape::Column, MEMBERS, 3.0).ok()?,
    ];
    let start = free_near(&grid, Cell::new(n / 16, n / 16))?;
    let goal = free_near(&grid, Cell::new(n - n / 16, n - n / 12))?;
    let exact = PlanRequest {
        grid: &grid,
        start: grid.center_of(start),
        goal: grid.center_of(goal),
        formations: &formations,
        leader: 0,
        weights: TaskClass::MayChangeRarely.weights(),
    };
    let req = PlanRequest {
        weights: Weights {
            search_weight,
            ..exact.weights
        },
        ..exact
    };
    let mut planner = Planner::new();
    // One untimed plan warms the search buffers; against the exact plan it also tells what the
    // weighted search gave up.
    let first = planner.plan(&req).ok()?;
    let note = (search_weight > 1.0)
        .then(|| planner.plan(&exact).ok())
        .flatten()
        .map(|best| {
            format!(
                "search weight {search_weight}: score {:.1} vs {:.1} exact (+{:.2} %, bound +{:.0} %), \
                 terrain cost +{:.2} %, {} vs {} nodes expanded",
                first.score,
                best.score,
                100.0 * (first.score / best.score - 1.0),
                100.0 * (search_weight - 1.0),
                100.0 * (first.cost / best.cost - 1.0),
                first.expanded,
                best.expanded
            )
        });
    let passes = passes.clamp(1, 20);
    let t = Instant::now();
    let mut expanded = 0u64;
    for _ in 0..passes {
        expanded += planner.plan(&req).ok()?.expanded as u64;
    }
    Some(Sample {
        workload: if search_weight > 1.0 {
            "plan-weighted"
        } else {
            "plan"
        }
        .into(),
        agents: MEMBERS,
        ticks: passes,
        seconds: t.elapsed().as_secs_f64(),
        updates: expanded,
        neighbors: 0.0,
        bytes_per_agent: None,
        stages: None,
        note,
        steady: None,
    })
}
