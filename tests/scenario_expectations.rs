//! Every shipped scenario's `expect:` holds as written, on seeds 1–5: the scenario file is
//! loaded as it ships, run to its end, and every verdict its expectations give must pass.
//! Nothing here restates or weakens an expectation; a scenario that stops meeting its own
//! `expect:` on any of these seeds fails this test with the figure it reached.

use shoal::scenario::expect::Tracker;
use shoal::scenario::{Overrides, Run, Scenario};
use std::path::Path;

const SEEDS: std::ops::RangeInclusive<u64> = 1..=5;

/// Runs `file` with `seed` to its end; the verdicts that did not pass, as text.
fn failures(file: &str, seed: u64) -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let scenario = Scenario::load(&path).unwrap_or_else(|e| panic!("{file}: {e:?}"));
    let mut tracker = Tracker::new(&scenario).unwrap_or_else(|e| panic!("{file}: {e:?}"));
    assert!(!tracker.is_empty(), "{file} declares no expectation");
    let mut run = Run::new(
        scenario,
        Overrides {
            seed: Some(seed),
            duration: None,
            set: Vec::new(),
        },
    );
    while !run.finished() {
        run.step();
        tracker.observe_run(&run);
    }
    tracker
        .finish(&run.world, &run.pipeline)
        .into_iter()
        .filter(|v| !v.passed)
        .map(|v| format!("{file} seed {seed}: {} ({})", v.expected, v.observed))
        .collect()
}

fn holds_on_every_seed(file: &str) {
    let failed: Vec<String> = SEEDS.flat_map(|seed| failures(file, seed)).collect();
    assert!(
        failed.is_empty(),
        "expectations not met:\n{}",
        failed.join("\n")
    );
}

#[test]
fn predator_attack_meets_its_expectations() {
    holds_on_every_seed("scenarios/predator_attack.ron");
}

#[test]
fn school_formation_meets_its_expectations() {
    holds_on_every_seed("scenarios/school_formation.ron");
}

#[test]
fn feeding_meets_its_expectations() {
    holds_on_every_seed("scenarios/tests/feeding.ron");
}

#[test]
fn shark_arrives_meets_its_expectations() {
    holds_on_every_seed("scenarios/tests/shark_arrives.ron");
}

/// Every scenario that ships with expectations is one of the above.
#[test]
fn every_shipped_scenario_with_expectations_is_checked() {
    let checked = [
        "predator_attack.ron",
        "school_formation.ron",
        "feeding.ron",
        "shark_arrives.ron",
    ];
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    for dir in [root.clone(), root.join("tests")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "ron") {
                let text = std::fs::read_to_string(&path).unwrap();
                let name = path.file_name().unwrap().to_string_lossy().into_owned();
                if text.contains("expect:") {
                    assert!(
                        checked.contains(&name.as_str()),
                        "{name} has expectations this test does not check"
                    );
                }
            }
        }
    }
}

/// Group expectations on the shipped predator attack, its sharks named `hunters`: the group's
/// catches are the sharks' (the only catchers), and each new expectation can pass and fail.
#[test]
fn group_expectations_follow_a_named_group_spawned_by_an_event() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/predator_attack.ron");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(
            "Spawn(species: \"shark\", count: 3",
            "Spawn(species: \"shark\", name: \"hunters\", count: 3",
        )
        .replace(
            "        SpeciesCatches(\"shark\", 1),\n",
            "        SpeciesCatches(\"shark\", 1), GroupCatches(\"hunters\", 1), \
             GroupCatches(\"hunters\", 1000), GroupMinAlive(\"hunters\", 3), \
             GroupMaxAlive(\"hunters\", 2), GroupMinAlive(\"sardine\", 1), \
             GroupMeals(\"hunters\", 1),\n",
        );
    let scenario = Scenario::load_str(&path, &text).unwrap_or_else(|e| panic!("{e}"));
    let mut tracker = Tracker::new(&scenario).unwrap();
    let mut run = Run::new(scenario, Overrides::default());
    while !run.finished() {
        run.step();
        tracker.observe_run(&run);
    }
    let v = tracker.finish(&run.world, &run.pipeline);
    let passed: Vec<bool> = v.iter().map(|v| v.passed).collect();
    assert_eq!(
        passed,
        [true, true, false, true, false, true, false, true],
        "{v:#?}"
    );
    assert_eq!(v[1].observed, v[0].observed, "{v:#?}");
    assert_eq!(v[2].expected, "group hunters: at least 1000 catches");
    assert_eq!(v[4].observed, "3 alive");
    assert_eq!(v[6].observed, "0 meals", "sharks eat no food items: {v:#?}");
}
