//! Determinism across runs and thread counts: the demo reef world (1,000 reef fish and their
//! sharks, with scripts, food and rocks) run for 1,000 ticks twice with one seed on 2 threads and
//! once on 1 thread gives bit-identical agents. One of the 2-thread runs switches between the
//! pool and one thread every tick (what the tick governor may do at any tick); another does so
//! stepped from a thread outside any pool (an embedding program's, or a live session's), where a
//! one-thread tick runs on that thread itself.

mod common;

use shoal::bench;
use shoal::tick::governor::Schedule;

/// Every agent's id and the bits of its position, heading, speed and drives after `ticks` ticks,
/// plus a running digest of all positions at every tick.
/// `threads`: a pool of that many to run in; `None`: a plain thread outside any pool (rayon's
/// global pool serves its passes).
fn run(threads: Option<usize>, ticks: u64, schedule: Schedule) -> (Vec<(u32, [u32; 8])>, u64) {
    let Some(threads) = threads else {
        return std::thread::spawn(move || steps(ticks, schedule))
            .join()
            .expect("the run's thread");
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| steps(ticks, schedule))
}

fn steps(ticks: u64, schedule: Schedule) -> (Vec<(u32, [u32; 8])>, u64) {
    let mut w =
        bench::reef(1_000, &bench::default_behaviors_dir(), true).unwrap_or_else(|d| panic!("{d}"));
    w.run.sim.pipeline.governor.schedule = schedule;
    let mut digest = 0xcbf2_9ce4_8422_2325u64;
    for _ in 0..ticks {
        w.run.step();
        for a in &w.run.world.agents {
            for x in [
                a.id.0,
                a.pos.x.to_bits(),
                a.pos.y.to_bits(),
                a.pos.z.to_bits(),
            ] {
                digest = (digest ^ x as u64).wrapping_mul(0x100_0000_01b3);
            }
        }
    }
    let agents = w.run.world.agents.iter().map(common::state_bits).collect();
    (agents, digest)
}

#[test]
fn one_seed_gives_bit_identical_runs_on_one_and_two_threads() {
    let ticks = 1_000;
    let a = run(Some(2), ticks, Schedule::Adaptive);
    let b = run(Some(2), ticks, Schedule::Alternate);
    let c = run(Some(1), ticks, Schedule::Adaptive);
    let d = run(None, ticks, Schedule::Alternate);
    assert!(a.0.len() > 900, "most fish are alive: {}", a.0.len());
    assert_eq!(a.1, b.1, "two runs on 2 threads diverged");
    assert_eq!(a.0, b.0, "two runs on 2 threads ended differently");
    assert_eq!(a.1, c.1, "1 and 2 threads diverged");
    assert_eq!(a.0, c.0, "1 and 2 threads ended differently");
    assert_eq!(a.1, d.1, "the run stepped outside any pool diverged");
    assert_eq!(
        a.0, d.0,
        "the run stepped outside any pool ended differently"
    );
}
