//! Malformed scenarios: each gives a `file:line:col` diagnostic and exit code 2.

use std::path::Path;
use std::process::Command;

fn check(dir: &Path, name: &str, text: &str) -> (i32, String) {
    let file = dir.join(name);
    std::fs::write(&file, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A scenario folder beside a copy of the shipped species.
fn setup() -> tempfile::TempDir {
    let t = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(t.path().join("scenarios")).unwrap();
    std::fs::create_dir_all(t.path().join("behaviors")).unwrap();
    for f in ["reef_fish.ron", "reef_fish.rhai", "shark.ron"] {
        std::fs::copy(
            Path::new("behaviors").join(f),
            t.path().join("behaviors").join(f),
        )
        .unwrap();
    }
    t
}

const GOOD: &str = r#"Scenario(
    duration: 1.0,
    bounds: (min: (-10.0, 0.0, -10.0), max: (10.0, 10.0, 10.0)),
    species: ["reef_fish"],
    groups: [
        (species: "reef_fish", count: 5, region: (min: (-5.0, 1.0, -5.0), max: (5.0, 5.0, 5.0))),
    ],
)
"#;

#[test]
fn a_good_scenario_runs() {
    let t = setup();
    let (code, err) = check(&t.path().join("scenarios"), "good.ron", GOOD);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn syntax_error_is_located() {
    let t = setup();
    let text = GOOD.replace("duration: 1.0,", "duration: 1.0");
    let (code, err) = check(&t.path().join("scenarios"), "bad.ron", &text);
    assert_eq!(code, 2);
    assert!(
        err.contains("bad.ron:2:18: expected a `,` here, between two fields or list entries"),
        "{err}"
    );
    assert!(err.contains("2 |     duration: 1.0\n"), "{err}");
}

#[test]
fn unknown_species_is_located() {
    let t = setup();
    let text = GOOD.replace(
        "(species: \"reef_fish\", count",
        "(species: \"reef_fsh\", count",
    );
    let (code, err) = check(&t.path().join("scenarios"), "bad.ron", &text);
    assert_eq!(code, 2);
    assert!(
        err.contains(
            "bad.ron:6:19: unknown species \"reef_fsh\" (did you mean `reef_fish`?): the scenario \
             loads reef_fish"
        ),
        "{err}"
    );
}

#[test]
fn negative_count_is_located() {
    let t = setup();
    let text = GOOD.replace("count: 5", "count: -3");
    let (code, err) = check(&t.path().join("scenarios"), "bad.ron", &text);
    assert_eq!(code, 2);
    assert!(
        err.contains("bad.ron:6:32: `count` must be ≥ 0, not -3"),
        "{err}"
    );
}

#[test]
fn an_unknown_key_in_a_box_is_located() {
    let t = setup();
    let text = GOOD.replace("max: (5.0, 5.0, 5.0))", "max: (5.0, 5.0, 5.0), size: 3.0)");
    assert_ne!(text, GOOD);
    let (code, err) = check(&t.path().join("scenarios"), "bad.ron", &text);
    assert_eq!(code, 2);
    assert!(err.contains("bad.ron:6:") && err.contains("size"), "{err}");
}

#[test]
fn region_outside_bounds_is_located() {
    let t = setup();
    let text = GOOD.replace("max: (5.0, 5.0, 5.0)", "max: (50.0, 5.0, 5.0)");
    let (code, err) = check(&t.path().join("scenarios"), "bad.ron", &text);
    assert_eq!(code, 2);
    assert!(
        err.contains("bad.ron:6:42: group of \"reef_fish\": spawn region [-5.0, 1.0, -5.0]..[50.0, 5.0, 5.0] is outside the world bounds"),
        "{err}"
    );
}

#[test]
fn missing_species_file_is_located() {
    let t = setup();
    let text = GOOD.replace(
        "species: [\"reef_fish\"]",
        "species: [\"reef_fish\", \"octopus\"]",
    );
    let (code, err) = check(&t.path().join("scenarios"), "bad.ron", &text);
    assert_eq!(code, 2);
    assert!(err.contains("bad.ron:4:28: species file \""), "{err}");
    assert!(err.contains("octopus.ron\" not found"), "{err}");
    // Where it looked, why there, and how to point elsewhere.
    assert!(err.contains("species are looked for in"), "{err}");
    assert!(
        err.contains("the default `behaviors: \"../behaviors\"`"),
        "{err}"
    );
    assert!(err.contains("set `behaviors: \"<folder>\"`"), "{err}");
}

#[test]
fn a_scenario_copied_away_from_its_species_says_where_it_looked_once() {
    let t = setup();
    // A copy two folders down: `../behaviors` is a folder that does not exist.
    let dir = t.path().join("copies").join("mine");
    std::fs::create_dir_all(&dir).unwrap();
    let text = GOOD.replace(
        "species: [\"reef_fish\"]",
        "species: [\"reef_fish\", \"shark\"]",
    );
    let (code, err) = check(&dir, "reef.ron", &text);
    assert_eq!(code, 2);
    let looked = t.path().join("copies").join("behaviors");
    assert!(
        err.contains(&format!(
            "reef.ron:4:15: species file \"{}\" not found; species are looked for in {}, a folder \
             that does not exist (the default `behaviors: \"../behaviors\"`, relative to the \
             scenario file's folder); set `behaviors: \"<folder>\"` in the scenario (relative to \
             the scenario file, or absolute) to load them from elsewhere",
            looked.join("reef_fish.ron").display(),
            looked.display()
        )),
        "{err}"
    );
    // The second missing file does not repeat the explanation.
    assert!(
        err.contains("shark.ron\" not found; looked for in the same folder as above"),
        "{err}"
    );
    assert_eq!(err.matches("species are looked for in").count(), 1, "{err}");
    // Pointing `behaviors:` at the species makes it run.
    let fixed = GOOD.replace(
        "Scenario(",
        &format!(
            "Scenario(\n    behaviors: \"{}\",",
            t.path().join("behaviors").display()
        ),
    );
    let (code, err) = check(&dir, "reef.ron", &fixed);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn misspelt_species_gets_a_near_name() {
    let t = setup();
    let text = GOOD.replace("species: [\"reef_fish\"]", "species: [\"reef_fsh\"]");
    let (_, err) = check(&t.path().join("scenarios"), "bad.ron", &text);
    assert!(err.contains("(did you mean `reef_fish`?)"), "{err}");
}

#[test]
fn missing_scenario_file_is_reported() {
    let t = setup();
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["run", "no/such/scenario.ron"])
        .current_dir(t.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no/such/scenario.ron: cannot read scenario: No such file"),
        "{err}"
    );
}

#[test]
fn a_region_inside_obstacles_is_located() {
    let t = setup();
    // The whole spawn region is inside one box: no room for the group.
    let text = GOOD.replace(
        "    species: [\"reef_fish\"],\n",
        "    species: [\"reef_fish\"],\n    obstacles: [Box(min: (-6.0, 0.0, -6.0), max: (6.0, 6.0, 6.0))],\n",
    );
    let (code, err) = check(&t.path().join("scenarios"), "bad.ron", &text);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bad.ron:7:42: group of \"reef_fish\": its spawn region [-5.0, 1.0, -5.0]..[5.0, 5.0, 5.0] lies inside obstacles"),
        "{err}"
    );
    // Half of it free: accepted (spawning finds the room).
    let text = text.replace("max: (6.0, 6.0, 6.0)", "max: (0.0, 6.0, 6.0)");
    let (code, err) = check(&t.path().join("scenarios"), "ok.ron", &text);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn a_bad_expectation_stops_the_run_with_its_location() {
    let t = setup();
    let text = GOOD.replace(
        "    ],\n)",
        "    ],\n    expect: [MinAlive(\"tuna\", 1)],\n)",
    );
    assert_ne!(text, GOOD);
    let dir = t.path().join("scenarios");
    let (code, err) = check(&dir, "bad.ron", &text);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bad.ron:8:23: unknown species \"tuna\" in `expect`"),
        "{err}"
    );
    // Nothing that looks like a run.
    assert!(!dir.join("out").join("trajectories.csv").exists());
}

#[test]
fn check_with_no_argument_reports_a_species_error_once() {
    let t = setup();
    // The shark's prey, so that the only problem is the one made below.
    let behaviors = t.path().join("behaviors");
    std::fs::create_dir_all(behaviors.join("common")).unwrap();
    for f in ["sardine.ron", "sardine.rhai", "common/schooling.rhai"] {
        std::fs::copy(Path::new("behaviors").join(f), behaviors.join(f)).unwrap();
    }
    let fish = t.path().join("behaviors/reef_fish.ron");
    let text = std::fs::read_to_string(&fish).unwrap();
    assert!(text.contains("predators: [\"shark\"]"));
    std::fs::write(
        &fish,
        text.replace("predators: [\"shark\"]", "predators: [\"sharc\"]"),
    )
    .unwrap();
    // Two scenarios load the broken species with different company, as the shipped ones do.
    let scenarios = t.path().join("scenarios");
    std::fs::write(scenarios.join("a.ron"), GOOD).unwrap();
    std::fs::write(
        scenarios.join("b.ron"),
        GOOD.replace(
            "species: [\"reef_fish\"]",
            "species: [\"reef_fish\", \"shark\"]",
        ),
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .arg("check")
        .current_dir(t.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("unknown species \"sharc\"").count(), 1, "{err}");
    // The one kept lists every species of the folder.
    assert!(
        err.contains(
            "unknown species \"sharc\" in `predators`: loaded species are reef_fish, sardine, shark"
        ),
        "{err}"
    );
    assert!(err.contains("1 error"), "{err}");
}
