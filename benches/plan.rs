//! Planning time of formation-aware A* + smoothing + follower paths (seed 004) on procedural
//! hills of 256², 1024² and 2048² cells, for a 5- and a 12-member team (wedge, falling back to a
//! column), task class "may change rarely". Run with `cargo bench --bench plan`.

use divan::Bencher;
use shoal::bench::plan::{self, hills};
use shoal::formation::{Formation, FormationShape, PlanRequest, Planner, TaskClass, Weights};
use shoal::terrain::{Cell, CostGrid, Mobility, Terrain};

fn main() {
    divan::main();
}

/// The free cell nearest to `c` (the benchmark maps always have one).
fn free_near(grid: &CostGrid, c: Cell) -> Cell {
    plan::free_near(grid, c).expect("no free cell")
}

#[divan::bench(args = [256, 1024, 2048], consts = [5, 12], sample_count = 10, sample_size = 1)]
fn plan<const MEMBERS: usize>(bencher: Bencher, n: usize) {
    let grid = hills(n);
    let formations = [
        Formation::new(&FormationShape::Wedge, MEMBERS, 4.0).unwrap(),
        Formation::new(&FormationShape::Column, MEMBERS, 3.0).unwrap(),
    ];
    let start = free_near(&grid, Cell::new(n / 16, n / 16));
    let goal = free_near(&grid, Cell::new(n - n / 16, n - n / 12));
    let req = PlanRequest {
        grid: &grid,
        start: grid.center_of(start),
        goal: grid.center_of(goal),
        formations: &formations,
        leader: 0,
        weights: TaskClass::MayChangeRarely.weights(),
    };
    let mut planner = Planner::new();
    let first = planner.plan(&req).expect("the benchmark map is connected");
    let blocked = grid.blocked.iter().filter(|&&b| b).count() as f32 / grid.blocked.len() as f32;
    eprintln!(
        "{n}² {MEMBERS} members: {:.0}% blocked, path {} cells, {} key points, {} transitions, {} expanded, tried {:?}",
        100.0 * blocked,
        first.leader_cells.len(),
        first.key_points.len(),
        first.transitions.len(),
        first.expanded,
        first.tried
    );
    bencher.bench_local(|| planner.plan(&req).unwrap());
}

/// The same hills with slope costing nothing below the limit (cost 1 off roads): the
/// heuristic is then tight away from obstacles, which shows how much of the time above is
/// spent on cost variation rather than on the formation term.
#[divan::bench(args = [1024, 2048], sample_count = 10, sample_size = 1)]
fn plan_uniform_cost(bencher: Bencher, n: usize) {
    let mobility = Mobility {
        slope_cost: 0.0,
        ..Mobility::default()
    };
    let grid = Terrain::procedural(n, n, 2.0, 60.0, 2007).cost_grid(&mobility);
    let formations = [
        Formation::new(&FormationShape::Wedge, 5, 4.0).unwrap(),
        Formation::new(&FormationShape::Column, 5, 3.0).unwrap(),
    ];
    let start = free_near(&grid, Cell::new(n / 16, n / 16));
    let goal = free_near(&grid, Cell::new(n - n / 16, n - n / 12));
    let req = PlanRequest {
        grid: &grid,
        start: grid.center_of(start),
        goal: grid.center_of(goal),
        formations: &formations,
        leader: 0,
        weights: TaskClass::MayChangeRarely.weights(),
    };
    let mut planner = Planner::new();
    let first = planner.plan(&req).expect("the benchmark map is connected");
    eprintln!("{n}² uniform cost: {} expanded", first.expanded);
    bencher.bench_local(|| planner.plan(&req).unwrap());
}

/// The leader search alone (no smoothing or follower paths).
#[divan::bench(args = [1024], sample_count = 10, sample_size = 1)]
fn leader_search_only(bencher: Bencher, n: usize) {
    let grid = hills(n);
    let formations = [Formation::new(&FormationShape::Wedge, 5, 4.0).unwrap()];
    let team = shoal::formation::GridFormations::new(&formations, 0, grid.cell_size);
    let start = free_near(&grid, Cell::new(n / 16, n / 16));
    let goal = free_near(&grid, Cell::new(n - n / 16, n - n / 12));
    let mut planner = Planner::new();
    bencher.bench_local(|| {
        planner.search(
            &grid,
            start,
            goal,
            &team,
            Weights {
                k1: 0.1,
                k2: 0.9,
                may_change: true,
                ..Weights::default()
            },
        )
    });
}
