//! Seed 001's perceived strength and seed 000 §4.3–4.4's direction sectors read from data: a
//! species whose condition reads `Strength(Predator)` and `InSector(Predator, …)` bolts from a
//! predator coming up behind it only once the predator is near enough, and never from one ahead.

mod common;

use common::{folder, load, Sim};
use glam::Vec3;
use shoal::events::Cause;
use shoal::world::Aabb;

/// Holds still until a predator behind it is strongly perceived: strength `(1/d)²` above 0.04,
/// so nearer than 5.
const MINNOW: &str = r#"Species(
    name: "minnow",
    relations: (predators: ["pike"]),
    drives: (native: false),
    senses: (vision_radius: 10.0, smell_radius: 20.0, strength: (power: 2.0, near: 1.0)),
    initial: "rest",
    behaviors: [
        Behavior(name: "rest", priority: 2, steer: Stop),
        Behavior(
            name: "bolt",
            priority: 1,
            when: All([InSector(Predator, [Rear, LeftRear, RightRear]), Above(Strength(Predator), 0.04)]),
            steer: Stop,
        ),
    ],
)
"#;

/// Sits still.
const PIKE: &str = r#"Species(
    name: "pike",
    drives: (native: false),
    initial: "sit",
    behaviors: [Behavior(name: "sit", priority: 1, steer: Stop)],
)
"#;

/// A minnow at the origin heading +z (yaw 0) and a pike at `offset` from it; the minnow's
/// behavior after a few ticks and its transitions.
fn minnow_with_pike_at(offset: Vec3) -> (String, Vec<common::Change>) {
    let dir = folder(&[("minnow.ron", MINNOW), ("pike.ron", PIKE)]);
    let root = dir.path();
    let mut sim = Sim::new(
        vec![
            load(&root.join("minnow.ron"), root),
            load(&root.join("pike.ron"), root),
        ],
        Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)),
    );
    let m = sim.spawn("minnow", Vec3::ZERO, 0.0);
    sim.spawn("pike", offset, 0.0);
    sim.run(5);
    (sim.behavior(m), sim.changes(m))
}

#[test]
fn a_predator_behind_is_fled_only_once_it_is_strongly_perceived() {
    // Straight behind (−z) at 8: strength (1/8)² = 0.015625 < 0.04: the minnow rests.
    let (b, changes) = minnow_with_pike_at(Vec3::new(0.0, 0.0, -8.0));
    assert_eq!(b, "rest", "{changes:?}");
    // At 4: (1/4)² = 0.0625 > 0.04: it bolts, and the transition says why.
    let (b, changes) = minnow_with_pike_at(Vec3::new(0.0, 0.0, -4.0));
    assert_eq!(b, "bolt");
    let c = &changes[0];
    assert_eq!(c.cause, Cause::Interrupted);
    assert_eq!(
        c.condition.as_deref(),
        Some("predator in rear or left_rear or right_rear and strength of predator > 0.04")
    );
    // Behind to the left (+x is the left of a fish heading +z), 3·√2 ≈ 4.24 away:
    // (1/4.24)² = 1/18 ≈ 0.056 > 0.04.
    let (b, _) = minnow_with_pike_at(Vec3::new(3.0, 0.0, -3.0));
    assert_eq!(b, "bolt");
}

#[test]
fn a_predator_ahead_is_not_in_a_rear_sector() {
    // Ahead at 2 (strength 0.25) and ahead to the right (−x) at 3·√2: not a rear sector.
    for offset in [Vec3::new(0.0, 0.0, 2.0), Vec3::new(-3.0, 0.0, 3.0)] {
        let (b, changes) = minnow_with_pike_at(offset);
        assert_eq!(b, "rest", "{offset}: {changes:?}");
    }
}

#[test]
fn levels_read_the_elevation_of_the_nearest() {
    // Same fish, bolting from a predator above it (elevation ≥ π/6) instead.
    let ron = MINNOW.replace(
        "InSector(Predator, [Rear, LeftRear, RightRear])",
        "AtLevel(Predator, [Above])",
    );
    let dir = folder(&[("minnow.ron", &ron), ("pike.ron", PIKE)]);
    let root = dir.path();
    let run = |offset: Vec3| {
        let mut sim = Sim::new(
            vec![
                load(&root.join("minnow.ron"), root),
                load(&root.join("pike.ron"), root),
            ],
            Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)),
        );
        let m = sim.spawn("minnow", Vec3::ZERO, 0.0);
        sim.spawn("pike", offset, 0.0);
        sim.run(5);
        (sim.behavior(m), sim.changes(m))
    };
    // 3 up and 1 ahead: elevation atan(3) ≈ 71.6° ≥ 30°: above.
    let (b, changes) = run(Vec3::new(0.0, 3.0, 1.0));
    assert_eq!(b, "bolt", "{changes:?}");
    assert_eq!(
        changes[0].condition.as_deref(),
        Some("predator at above and strength of predator > 0.04")
    );
    // 1 up and 3 ahead: atan(1/3) ≈ 18.4° < 30°: level.
    let (b, _) = run(Vec3::new(0.0, 1.0, 3.0));
    assert_eq!(b, "rest");
}

#[test]
fn strength_alone_reads_the_summary_of_a_species_that_keeps_no_percepts() {
    // Nothing else of the species reads percepts, so it keeps none: the strength comes from the
    // nearest distance of the summary. Ahead at 4: (1/4)² = 0.0625 > 0.04; at 6: 1/36 ≈ 0.028.
    let ron = MINNOW.replace(
        "All([InSector(Predator, [Rear, LeftRear, RightRear]), Above(Strength(Predator), 0.04)])",
        "Above(Strength(Predator), 0.04)",
    );
    let dir = folder(&[("minnow.ron", &ron), ("pike.ron", PIKE)]);
    let root = dir.path();
    for (z, want) in [(4.0, "bolt"), (6.0, "rest")] {
        let mut sim = Sim::new(
            vec![
                load(&root.join("minnow.ron"), root),
                load(&root.join("pike.ron"), root),
            ],
            Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)),
        );
        let m = sim.spawn("minnow", Vec3::ZERO, 0.0);
        sim.spawn("pike", Vec3::new(0.0, 0.0, z), 0.0);
        sim.run(5);
        assert_eq!(sim.behavior(m), want, "pike at {z}");
    }
}
