//! A species written from the designers' reference alone — avoid rocks, escape sharks, wander,
//! nothing tuned — behaves believably in the default reef: it meets every run-health bound,
//! stated as the scenario's own expectations, on seeds 1–5 (30 s each to keep the test short).

use shoal::scenario::expect::Tracker;
use shoal::scenario::{Overrides, Run, Scenario};
use std::path::Path;

const NAIVE: &str = r#"// A fish written from the designers' reference alone, with no tuning.
Species(
    name: "naive_fish",
    body: (size: (0.3, 0.5, 1.0), limits: (max_speed: 3.0)),
    senses: (vision_radius: 10.0, smell_radius: 20.0),
    relations: (predators: ["shark"]),
    initial: "wander",
    behaviors: [
        Behavior(name: "avoid_static", priority: 1, when: ObstacleNear, done: Not(ObstacleNear), steer: AvoidStatic()),
        Behavior(name: "escape", priority: 1, when: Sees(Predator), done: EscapeDone, steer: Priority([AvoidStatic(), Escape()])),
        Behavior(name: "wander", priority: 5, steer: Priority([Contain(), Wander()])),
    ],
)
"#;

/// The run-health bounds of the issue that introduced them, as expectations.
const BOUNDS: &str = r#"    expect: [
        MaxFrozen("naive_fish", 0),
        MaxPitchLimitShare("naive_fish", 0.05),
        MaxSwitchRate("naive_fish", 0.5),
        MaxShortEpisodes("naive_fish", 0.1),
        MaxTurningWaste("naive_fish", 2.0),
        MaxInterpenetration("naive_fish", 0.01),
        MaxObstaclePenetration("naive_fish", 0),
    ],
"#;

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

#[test]
fn a_naive_fish_meets_every_health_bound_in_the_reef() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    copy_dir(&root.join("behaviors"), &dir.path().join("behaviors"));
    std::fs::write(dir.path().join("behaviors/naive_fish.ron"), NAIVE).unwrap();
    let reef = std::fs::read_to_string(root.join("scenarios/reef.ron")).unwrap();
    let end = reef.rfind(')').unwrap();
    let text =
        format!("{}{BOUNDS}{}", &reef[..end], &reef[end..]).replace("reef_fish", "naive_fish");
    std::fs::create_dir_all(dir.path().join("scenarios")).unwrap();
    let file = dir.path().join("scenarios/reef.ron");
    std::fs::write(&file, &text).unwrap();
    let mut failed = Vec::new();
    for seed in 1..=5 {
        let scenario = Scenario::load(&file).unwrap_or_else(|e| panic!("{e:?}"));
        let mut tracker = Tracker::new(&scenario).unwrap_or_else(|e| panic!("{e:?}"));
        let mut run = Run::new(
            scenario,
            Overrides {
                seed: Some(seed),
                duration: Some(30.0),
                set: Vec::new(),
            },
        );
        while !run.finished() {
            run.step();
            tracker.observe_run(&run);
        }
        for v in tracker.finish(&run.world, &run.pipeline) {
            if !v.passed {
                failed.push(format!("seed {seed}: {} ({})", v.expected, v.observed));
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
