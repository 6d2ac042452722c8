//! Determinism across thread counts for the species that keep no percepts (the plain kin path
//! and the group sums) and for flockers with obstacles: bit-identical agents on one and two
//! threads.

mod common;

use shoal::bench;

fn run(threads: usize, boids: bool) -> Vec<(u32, [u32; 8])> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let mut w = if boids {
            bench::boids(700)
        } else {
            bench::flock(700)
        };
        for _ in 0..40 {
            w.run.step();
        }
        w.run.world.agents.iter().map(common::state_bits).collect()
    })
}

#[test]
fn group_rule_worlds_are_bit_identical_on_one_and_two_threads() {
    for boids in [true, false] {
        assert_eq!(run(1, boids), run(2, boids), "boids: {boids}");
    }
}
