//! Interpreted script calls on one and two threads (`cargo bench --bench script_calls`): an
//! `on_tick()` like the sardine's (blackboard reads and writes, a module call) kept out of the
//! native evaluator by an array, 2,000 calls a thread an iteration. `pool_of_two` runs them on a
//! two-thread rayon pool, as the tick does (each worker past the first calls a replica of the
//! engine: `Script::local`); `plain_threads_of_two` on two threads outside any pool, which share
//! the one engine. With an engine each, two threads take about the time one takes.

use rhai::{Dynamic, Scope};
use shoal::script::memory::{MemType, MemorySpec};
use shoal::script::{AgentView, SandboxLimits, Script};
use shoal::world::MemValue;
use std::sync::Arc;

fn main() {
    divan::main();
}

const CALLS: usize = 2_000;

const TEXT: &str = r#"
import "common/schooling" as school;
fn on_tick() {
    let prev = if this.has("mean_speed") { this["mean_speed"] } else { () };
    let elapsed = if this.has("sampled_at") { this.time - this["sampled_at"] } else { 0.0 };
    this["mean_speed"] = school::running_mean(prev, this.speed, elapsed, 2.0);
    this["sampled_at"] = this.time;
    let kept_interpreted = [elapsed];
}
"#;

fn script() -> Script {
    let root = shoal::bench::default_behaviors_dir();
    let mut s = Script::compile(
        &root.join("bench.rhai"),
        TEXT,
        &root,
        &SandboxLimits::default(),
    )
    .unwrap_or_else(|d| panic!("{d}"));
    s.declare_memory(Arc::new(MemorySpec::declaring(&[
        ("mean_speed", MemType::Float),
        ("sampled_at", MemType::Float),
    ])));
    s
}

/// `CALLS` calls of `on_tick()` on this thread, with a view of its own.
fn calls(s: &Script) {
    let mut view = AgentView {
        speed: 1.5,
        time: 4.0,
        ..Default::default()
    };
    view.memory = [("mean_speed", 1.0), ("sampled_at", 3.5)]
        .into_iter()
        .map(|(k, v)| (Arc::from(k), MemValue::Float(v)))
        .collect();
    let mut this = Dynamic::from(view);
    let mut scope = Scope::new();
    for _ in 0..CALLS {
        let _: Dynamic = s.call(&mut scope, &mut this, "on_tick").unwrap();
    }
}

#[divan::bench(sample_count = 20)]
fn one_thread(bencher: divan::Bencher) {
    let s = script();
    bencher.bench_local(|| calls(&s));
}

#[divan::bench(sample_count = 20)]
fn pool_of_two(bencher: divan::Bencher) {
    let s = script();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    // Past the replica threshold before timing.
    pool.broadcast(|_| calls(&s));
    bencher.bench_local(|| pool.broadcast(|_| calls(&s)));
}

#[divan::bench(sample_count = 20)]
fn plain_threads_of_two(bencher: divan::Bencher) {
    let s = script();
    bencher.bench_local(|| {
        std::thread::scope(|sc| {
            let a = sc.spawn(|| calls(&s));
            calls(&s);
            a.join().unwrap();
        })
    });
}
