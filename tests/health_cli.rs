//! Run health end to end: `shoal run` writes `health.json` and prints the section, `shoal health`
//! prints the same section from the file or, for a folder without one, from a re-run; a scenario
//! whose health bound is too strict fails `shoal test` with the measured figure.

mod common;

use common::shoal;

/// The lines of the run-health section (from its heading to the warnings); the heading without
/// its figures, as the monitor's share of wall time differs from run to run.
fn section(out: &str) -> Vec<String> {
    out.lines()
        .skip_while(|l| !l.starts_with("run health ("))
        .take_while(|l| !l.starts_with("output written"))
        .map(|l| {
            if l.starts_with("run health (") {
                "run health".to_string()
            } else {
                l.to_string()
            }
        })
        .collect()
}

#[test]
fn shoal_health_prints_the_section_of_a_run_folder() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("run");
    let d = dir.to_str().unwrap();
    let (code, out, err) = shoal(&["run", "scenarios/tiny.ron", "--out", d]);
    assert_eq!(code, 0, "{out}{err}");
    let printed = section(&out);
    assert!(printed.len() > 4, "{out}");
    assert!(printed[1].trim_start().starts_with("species"), "{out}");
    assert!(printed
        .iter()
        .any(|l| l.trim_start().starts_with("reef_fish")));
    // The report is in the folder, listed with the outputs, its headline in the summary.
    let health: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("health.json")).unwrap()).unwrap();
    assert_eq!(health["format"], 1);
    assert_eq!(health["ticks"], 200);
    assert!(health["warnings"].is_array());
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    assert!(manifest["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .any(|f| f == "health.json"));
    let headline = &manifest["summary"]["health"];
    assert!(headline["species"]["reef_fish"]["switch_rate"].is_number());
    assert!(headline["warnings"].is_array());

    // From the file: the same section.
    let (code, out, err) = shoal(&["health", d]);
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(section(&out), printed, "{out}");

    // A folder from before health.json: re-run from the stored inputs, same figures.
    std::fs::remove_file(dir.join("health.json")).unwrap();
    let (code, out, err) = shoal(&["health", d]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(err.contains("re-running its stored inputs"), "{err}");
    assert_eq!(section(&out), printed, "{out}");

    // --quiet stays quiet; --no-health leaves no report.
    let (code, out, _) = shoal(&["run", "scenarios/tiny.ron", "--quiet", "--out", d]);
    assert_eq!(code, 0);
    assert!(!out.contains("run health"), "{out}");
    assert!(dir.join("health.json").is_file());
    let (code, _, _) = shoal(&["run", "scenarios/tiny.ron", "--no-health", "--out", d]);
    assert_eq!(code, 0);
    assert!(!dir.join("health.json").exists());
}

#[test]
fn a_too_strict_switch_rate_fails_with_the_figure() {
    let t = tempfile::tempdir().unwrap();
    let behaviors = common::behaviors();
    let file = t.path().join("strict.ron");
    std::fs::write(
        &file,
        format!(
            r#"Scenario(
    seed: 5,
    duration: 4.0,
    bounds: (min: (-15.0, 0.0, -15.0), max: (15.0, 12.0, 15.0)),
    behaviors: Some("{}"),
    species: ["reef_fish"],
    food: (initial: 30),
    groups: [(species: "reef_fish", count: 12, region: (min: (-10.0, 2.0, -10.0), max: (10.0, 10.0, 10.0)),
              drives: (hunger: Some(Fixed(0.9))))],
    expect: [MaxSwitchRate("reef_fish", 0.001), MaxTurningWaste("reef_fish", 1000.0)],
)"#,
            behaviors.display()
        ),
    )
    .unwrap();
    let (code, out, err) = shoal(&["test", file.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}{err}");
    let line = out
        .lines()
        .find(|l| l.contains("FAIL expected at most 0.001 behavior switches per reef_fish"))
        .unwrap_or_else(|| panic!("no failed switch-rate line:\n{out}"));
    // The measured figure, then the bound.
    let figure = line
        .split(": ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|x| x.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("no figure in {line}"));
    assert!(figure > 0.001, "{line}");
    assert!(
        line.contains("switches per agent per second (bound 0.001)"),
        "{line}"
    );
    assert!(
        out.contains("ok   expected reef_fish turning waste at most 1000×"),
        "{out}"
    );
}
