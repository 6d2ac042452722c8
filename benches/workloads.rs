//! The standard workloads under divan (`cargo bench`): one tick of each world at 1k, 10k and
//! 100k agents (50k for `reef`), and the stage workloads at 10k. Worlds are built and warmed up
//! outside the timed region; each iteration is one tick (or one pass over every agent), so divan's
//! "time per iteration" is ms/tick and ticks/s is its inverse. Each world is timed over 20
//! consecutive ticks (10 samples of 2), like `shoal bench`'s first ticks: flocks condense over
//! thousands of ticks, so longer runs measure a denser world. `SHOAL_BENCH_MAX` caps the agent
//! counts (e.g. `SHOAL_BENCH_MAX=10000 cargo bench`).

use shoal::bench::{self, BenchWorld, Workload};

fn main() {
    divan::main();
}

fn max_agents() -> usize {
    std::env::var("SHOAL_BENCH_MAX")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(usize::MAX)
}

/// The sizes of `workload` up to `SHOAL_BENCH_MAX`.
fn sizes(workload: Workload) -> Vec<usize> {
    let max = max_agents();
    workload
        .default_agents()
        .iter()
        .copied()
        .filter(|&n| n <= max)
        .collect()
}

/// Agents of the stage workloads: 10,000, or `SHOAL_BENCH_MAX` when lower.
fn stage_size() -> usize {
    max_agents().min(10_000)
}

fn warm(workload: Workload, n: usize) -> Option<BenchWorld> {
    if n > max_agents() {
        return None;
    }
    let mut w = bench::world_of(workload, n, &bench::default_behaviors_dir())
        .unwrap_or_else(|d| panic!("{d}"));
    bench::warm_up(&mut w, bench::WARMUP_TICKS);
    Some(w)
}

fn ticks(bencher: divan::Bencher, workload: Workload, n: usize) {
    let Some(mut w) = warm(workload, n) else {
        return;
    };
    bencher
        .counter(divan::counter::ItemsCount::new(w.run.world.agents.len()))
        .bench_local(|| w.run.step());
}

/// Classic flocking at the peers' density.
#[divan::bench(args = sizes(Workload::Boids), sample_count = 10, sample_size = 2)]
fn boids(bencher: divan::Bencher, n: usize) {
    ticks(bencher, Workload::Boids, n);
}

/// 3D flocking with obstacle avoidance, ~20 neighbors (engine core).
#[divan::bench(args = sizes(Workload::Flock), sample_count = 10, sample_size = 2)]
fn flock(bencher: divan::Bencher, n: usize) {
    ticks(bencher, Workload::Flock, n);
}

/// Reef fish and sharks with their scripts.
#[divan::bench(args = sizes(Workload::Reef), sample_count = 10, sample_size = 2)]
fn reef(bencher: divan::Bencher, n: usize) {
    ticks(bencher, Workload::Reef, n);
}

/// The same reef with script conditions replaced by native ones.
#[divan::bench(args = sizes(Workload::ReefNative), sample_count = 10, sample_size = 2)]
fn reef_native(bencher: divan::Bencher, n: usize) {
    ticks(bencher, Workload::ReefNative, n);
}

/// The decision stage alone on a 10k reef (`stage_size`), a script call per agent (items: agents).
#[divan::bench(args = [true, false], sample_count = 10, sample_size = 2)]
fn decide(bencher: divan::Bencher, scripted: bool) {
    let Some(w) = warm(Workload::Decide, stage_size()) else {
        return;
    };
    bencher
        .counter(divan::counter::ItemsCount::new(w.run.world.agents.len()))
        .bench_local(|| bench::decide_timed(&w, 1, scripted));
}

/// Spatial index and perception alone on a 10k reef (`stage_size`) (items: agents).
#[divan::bench(sample_count = 10, sample_size = 2)]
fn perceive(bencher: divan::Bencher) {
    let Some(mut w) = warm(Workload::Perceive, stage_size()) else {
        return;
    };
    bencher
        .counter(divan::counter::ItemsCount::new(w.run.world.agents.len()))
        .bench_local(|| w.run.sim.pipeline.perceive(&w.run.sim.world));
}

/// Formation A* + smoothing + follower paths on a 1024² terrain (see `src/bench/plan.rs`).
#[divan::bench(sample_count = 5)]
fn plan() {
    divan::black_box(bench::plan::measure(1, 1.0));
}

/// The same plan with the weighted search (`search_weight` 1.25).
#[divan::bench(sample_count = 5)]
fn plan_weighted() {
    divan::black_box(bench::plan::measure(
        1,
        shoal::formation::astar::SEARCH_WEIGHT_FAST,
    ));
}
