//! Sweep plans and settings through the library API: every key form of a setting, unknown keys
//! with their did-you-mean, bad values located and named; grid, range, random, Latin hypercube
//! and SALib sample-file expansion, deterministic, with seeds per point.

use shoal::scenario::{Scenario, Setting};
use shoal::sweep::Plan;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn load(set: &[&str]) -> Result<Scenario, String> {
    let set: Vec<Setting> = set.iter().map(|s| Setting::parse(s).unwrap()).collect();
    Scenario::load_with(&root().join("scenarios/tiny.ron"), &set).map_err(|d| d.to_string())
}

#[test]
fn settings_reach_every_key_form() {
    let s = load(&[
        "scenario.duration=3",
        "scenario.groups[0].count=7",
        "scenario.groups[shark].count=2",
        "scenario.groups[0].heading=Yaw(90)",
        "reef_fish.senses.vision_radius=6.5",
    ])
    .unwrap();
    assert_eq!(s.def.duration, 3.0);
    assert_eq!(s.def.groups[0].count, 7);
    assert_eq!(s.def.groups[1].count, 2);
    assert_eq!(
        s.def.groups[0].heading,
        shoal::scenario::HeadingDef::Yaw(90.0)
    );
    let fish = &s.species.species[0];
    assert_eq!(fish.name, "reef_fish");
    assert_eq!(fish.def.senses.vision_radius, 6.5);
    assert_eq!(s.settings.len(), 5);
    // A plain load patches nothing.
    assert!(load(&[]).unwrap().patched.is_empty());
}

#[test]
fn unknown_keys_and_bad_values_are_located_and_named() {
    let e = load(&["scenario.grups[0].count=3"]).unwrap_err();
    assert!(
        e.contains("tiny.ron:2:1: setting `scenario.grups[0].count=3`: no key `grups` in the scenario (did you mean `groups`?)"),
        "{e}"
    );
    let e = load(&["reef_fsh.senses.vision_radius=3"]).unwrap_err();
    assert!(e.contains("`reef_fsh` is neither `scenario` nor a species the scenario loads (did you mean `reef_fish`?)"), "{e}");
    let e = load(&["reef_fish.senses.vison_radius=3"]).unwrap_err();
    assert!(e.contains("reef_fish.ron:30:"), "{e}");
    assert!(e.contains("setting `reef_fish.senses.vison_radius=3`: unknown field `vison_radius` in SenseParams (did you mean `vision_radius`?)"), "{e}");
    let e = load(&["scenario.groups[0].count=-1"]).unwrap_err();
    assert!(
        e.contains(
            "tiny.ron:11:32: setting `scenario.groups[0].count=-1`: `count` must be ≥ 0, not -1"
        ),
        "{e}"
    );
    let e = load(&["scenario.groups[5].count=1"]).unwrap_err();
    assert!(
        e.contains("`groups` has 2 element(s); index 5 is out of range"),
        "{e}"
    );
    let e = load(&["scenario.groups[sardine].count=1"]).unwrap_err();
    assert!(
        e.contains("no element named `sardine` in `groups`: its elements are `reef_fish`, `shark`"),
        "{e}"
    );
    assert!(Setting::parse("scenario.duration")
        .unwrap_err()
        .contains("expected KEY=VALUE"));
    assert!(Setting::parse("duration=3")
        .unwrap_err()
        .contains("`scenario.<key>` or `<species>.<key>`"));
}

fn sweep(dir: &Path, body: &str) -> Result<Plan, String> {
    let f = dir.join("s.ron");
    let scenario = root().join("scenarios/tiny.ron");
    std::fs::write(
        &f,
        format!(
            "Sweep(scenario: {:?}, {body})",
            scenario.display().to_string()
        ),
    )
    .unwrap();
    Plan::load(&f).map_err(|d| d.to_string())
}

fn values(p: &Plan) -> Vec<Vec<String>> {
    p.entries()
        .iter()
        .map(|e| e.values().map(str::to_string).collect())
        .collect()
}

#[test]
fn grids_and_ranges_expand_with_seeds_per_point() {
    let d = tempfile::tempdir().unwrap();
    let p = sweep(
        d.path(),
        "seeds: 2, axes: [(key: \"scenario.groups[0].count\", range: (from: 10, to: 30, step: 10)), \
         (key: \"scenario.groups[0].heading\", values: [Yaw(0), Random])]",
    )
    .unwrap();
    assert_eq!((p.len(), p.points()), (12, 6));
    let v = values(&p);
    assert_eq!(v[0], ["10", "Yaw(0)"]);
    assert_eq!(v[2], ["10", "Random"]);
    assert_eq!(v[11], ["30", "Random"]);
    // Replicate r has the same seed at every point (common random numbers).
    assert_eq!(p.entry(0).seed, p.entry(2).seed);
    assert_ne!(p.entry(0).seed, p.entry(1).seed);
    let p = sweep(
        d.path(),
        "axes: [(key: \"scenario.duration\", range: (from: 1.0, to: 2.0, count: 3))]",
    )
    .unwrap();
    assert_eq!(values(&p), [["1"], ["1.5"], ["2"]]);
}

#[test]
fn samplers_are_deterministic_and_within_bounds() {
    let d = tempfile::tempdir().unwrap();
    for sampler in ["Random(8)", "LatinHypercube(8)"] {
        let body = format!(
            "sampler: {sampler}, axes: [(key: \"reef_fish.senses.vision_radius\", bounds: (2.0, 6.0)), \
             (key: \"scenario.groups[0].count\", bounds: (10, 50), integer: true)]"
        );
        let a = values(&sweep(d.path(), &body).unwrap());
        let b = values(&sweep(d.path(), &body).unwrap());
        assert_eq!(a, b);
        assert_eq!(a.len(), 8);
        let mut strata = std::collections::BTreeSet::new();
        for row in &a {
            let x: f64 = row[0].parse().unwrap();
            assert!((2.0..6.0).contains(&x), "{x}");
            let n: i64 = row[1].parse().unwrap();
            assert!((10..=50).contains(&n), "{n}");
            strata.insert(((x - 2.0) / 4.0 * 8.0) as usize);
        }
        if sampler.starts_with("Latin") {
            assert_eq!(strata.len(), 8, "one point per stratum: {a:?}");
        }
    }
    let e = sweep(
        d.path(),
        "sampler: Random(3), axes: [(key: \"scenario.duration\", values: [1])]",
    )
    .unwrap_err();
    assert!(
        e.contains("axis `scenario.duration` has no `bounds`"),
        "{e}"
    );
}

#[test]
fn salib_sample_files_give_one_point_per_row() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("samples.txt"),
        "4.000000e+00 2.000000e+01\n5.5 3.3e1\n",
    )
    .unwrap();
    let axes = "axes: [(key: \"reef_fish.senses.vision_radius\"), (key: \"scenario.groups[0].count\", integer: true)]";
    let p = sweep(
        d.path(),
        &format!("sampler: File(\"samples.txt\"), seeds: 2, {axes}"),
    )
    .unwrap();
    assert_eq!(
        values(&p),
        [["4", "20"], ["4", "20"], ["5.5", "33"], ["5.5", "33"]]
    );
    std::fs::write(d.path().join("samples.txt"), "4.0\n").unwrap();
    let e = sweep(d.path(), &format!("sampler: File(\"samples.txt\"), {axes}")).unwrap_err();
    assert!(
        e.contains("samples.txt:1:1: 1 column(s), expected 2 (one per axis"),
        "{e}"
    );
}

#[test]
fn sweep_files_report_located_errors() {
    let d = tempfile::tempdir().unwrap();
    let e = sweep(d.path(), "seds: 2, axes: []").unwrap_err();
    assert!(
        e.contains("unknown field `seds` in Sweep (did you mean `seeds`?)"),
        "{e}"
    );
    let e = sweep(d.path(), "axes: [(key: \"scenario.duraton\", values: [1])]").unwrap_err();
    assert!(e.contains("setting `scenario.duraton=1`"), "{e}");
    assert!(e.contains("(did you mean `duration`?)"), "{e}");
    let e = sweep(
        d.path(),
        "axes: [(key: \"scenario.duration\", range: (from: 1, to: 0, step: 1))]",
    )
    .unwrap_err();
    assert!(e.contains("s.ron:1:"), "{e}");
    assert!(e.contains("a range is (from: a, to: b, step: s)"), "{e}");
}
