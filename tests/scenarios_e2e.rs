//! End to end: every shipped scenario runs through the CLI, its recording has the documented
//! schema and the content the scenario is about, and a re-run gives identical bytes.

mod common;

use common::{named_figures, shoal};
use std::path::{Path, PathBuf};

struct Row {
    tick: u64,
    species: String,
    pos: [f64; 3],
    fwd: [f64; 3],
    behavior: String,
}

fn read_rows(dir: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(dir.join("trajectories.csv")).unwrap();
    let mut lines = text.lines();
    let header = shoal::record::schema::header(&shoal::record::schema::TRAJECTORY_COLUMNS);
    assert_eq!(lines.next(), Some(header.as_str()));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 18, "row {l}");
            let n = |i: usize| {
                f[i].parse::<f64>()
                    .unwrap_or_else(|_| panic!("field {i} of {l}"))
            };
            for i in [1, 4, 5, 6, 7, 8, 9, 10, 13, 14, 15, 16, 17] {
                assert!(n(i).is_finite(), "{l}");
            }
            for i in [13, 14, 15] {
                assert!((0.0..=1.0).contains(&n(i)), "drive out of range: {l}");
            }
            let fwd = [n(7), n(8), n(9)];
            let len = (fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-3, "heading not unit: {l}");
            Row {
                tick: f[0].parse().unwrap(),
                species: f[3].to_string(),
                pos: [n(4), n(5), n(6)],
                fwd,
                behavior: f[11].to_string(),
            }
        })
        .collect()
}

fn events(dir: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(dir.join("events.jsonl"))
        .unwrap()
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            assert!(
                v["tick"].is_u64() && v["kind"].is_string() && v["time"].is_number(),
                "{l}"
            );
            v
        })
        .collect()
}

/// Runs a scenario, checks the common schema, re-runs it and checks the bytes match.
fn run_checked(scenario: &str, extra: &[&str]) -> (tempfile::TempDir, PathBuf) {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("run");
    let d = dir.to_str().unwrap();
    let mut args = vec!["run", scenario, "--out", d, "--quiet"];
    args.extend_from_slice(extra);
    let (code, out, err) = shoal(&args);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("output written to"), "{out}");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["status"], "complete");
    assert!(!dir.join("INCOMPLETE").exists());
    // Where the wall time went: six shares of the whole (each rounded to 0.1 %).
    let shares = manifest["summary"]["time_shares"].as_object().unwrap();
    let keys: Vec<&str> = shares.keys().map(|k| k.as_str()).collect();
    assert_eq!(
        keys,
        [
            "agents",
            "events",
            "index",
            "other",
            "perception",
            "recording"
        ]
    );
    let share = |k: &str| shares[k].as_f64().unwrap();
    let total: f64 = shares.values().map(|v| v.as_f64().unwrap()).sum();
    assert!((total - 1.0).abs() <= 0.004, "{shares:?}");
    // The rest is what the tick's stages and the recording leave: a stage missing from the
    // sums would land there.
    let staged = share("index") + share("perception") + share("agents") + share("events");
    assert!(staged >= 0.5, "{shares:?}");
    assert!(
        share("perception") > 0.0 && share("agents") > 0.0,
        "{shares:?}"
    );
    assert!(manifest["files"]
        .as_object()
        .unwrap()
        .values()
        .all(|h| h.as_str().unwrap().len() == 64));
    let world: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("world.json")).unwrap()).unwrap();
    assert!(world["species"]
        .as_array()
        .unwrap()
        .iter()
        .all(|s| s["behaviors"].as_array().is_some_and(|b| !b.is_empty())));
    let food = std::fs::read_to_string(dir.join("food.csv")).unwrap();
    assert!(food.starts_with("tick,id,x,y,z\n"));
    // Re-run from the stored inputs: identical bytes.
    let (code, out, err) = shoal(&["rerun", d]);
    assert_eq!(code, 0, "rerun differs:\n{out}{err}");
    for f in ["trajectories.csv", "events.jsonl", "food.csv"] {
        assert_eq!(
            std::fs::read(dir.join(f)).unwrap(),
            std::fs::read(dir.join("rerun").join(f)).unwrap(),
            "{f}"
        );
    }
    (t, dir)
}

/// |mean heading| of a species at a tick (1 = all aligned).
fn polarization(rows: &[Row], tick: u64, species: &str) -> f64 {
    let mut s = [0.0; 3];
    let mut n = 0.0;
    for r in rows
        .iter()
        .filter(|r| r.tick == tick && r.species == species)
    {
        for (acc, f) in s.iter_mut().zip(r.fwd) {
            *acc += f;
        }
        n += 1.0;
    }
    (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt() / n
}

/// Mean distance from the species' centroid at a tick.
fn spread(rows: &[Row], tick: u64, species: &str) -> f64 {
    let pts: Vec<[f64; 3]> = rows
        .iter()
        .filter(|r| r.tick == tick && r.species == species)
        .map(|r| r.pos)
        .collect();
    let n = pts.len() as f64;
    let c: Vec<f64> = (0..3)
        .map(|k| pts.iter().map(|p| p[k]).sum::<f64>() / n)
        .collect();
    pts.iter()
        .map(|p| {
            let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .sum::<f64>()
        / n
}

#[test]
fn reef_runs_records_and_reruns_identically() {
    let (_t, dir) = run_checked("scenarios/reef.ron", &["--duration", "8"]);
    let rows = read_rows(&dir);
    let species: std::collections::BTreeSet<&str> =
        rows.iter().map(|r| r.species.as_str()).collect();
    assert_eq!(
        species.into_iter().collect::<Vec<_>>(),
        vec!["jellyfish", "reef_fish", "sardine", "shark"]
    );
    let ev = events(&dir);
    assert!(ev.iter().any(|e| e["kind"] == "transition"
        && e["cause"].is_string()
        && e["condition"].is_string()));
    assert!(ev.iter().filter(|e| e["kind"] == "spawn").count() >= 501);
}

#[test]
fn predator_attack_sharks_catch_fish() {
    let (_t, dir) = run_checked("scenarios/predator_attack.ron", &[]);
    let ev = events(&dir);
    let catches = ev.iter().filter(|e| e["kind"] == "catch").count();
    let deaths = ev.iter().filter(|e| e["kind"] == "death").count();
    eprintln!("catches {catches}");
    assert!(catches >= 1, "no catch in predator_attack");
    assert_eq!(catches, deaths);
    // Sharks arrive at t = 5 s: sardines escape.
    let rows = read_rows(&dir);
    let escaping = rows
        .iter()
        .filter(|r| r.species == "sardine" && r.behavior == "escape" && r.tick > 100)
        .count();
    assert!(escaping > 0, "no sardine ever escaped");
}

#[test]
fn school_formation_sardines_form_one_school() {
    let (_t, dir) = run_checked("scenarios/school_formation.ron", &[]);
    let rows = read_rows(&dir);
    let ticks: std::collections::BTreeSet<u64> = rows.iter().map(|r| r.tick).collect();
    let last = *ticks.iter().next_back().unwrap();
    let p0 = polarization(&rows, 0, "sardine");
    // The school forms: polarization crosses 0.8 and the first tick it does is reported.
    let crossed = ticks
        .iter()
        .find(|&&t| polarization(&rows, t, "sardine") > 0.8)
        .copied();
    let (s0, s1) = (spread(&rows, 0, "sardine"), spread(&rows, last, "sardine"));
    eprintln!("polarization {p0:.3} at tick 0, above 0.8 first at tick {crossed:?}; spread {s0:.2} -> {s1:.2}");
    assert!(p0 < 0.5, "starts unordered: {p0}");
    assert!(crossed.is_some(), "polarization never crossed 0.8");
    assert!(s1 < 12.0, "ends cohesive: mean distance to centroid {s1}");
}

#[test]
fn the_run_summary_says_where_the_wall_time_went() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("run");
    let (code, out, err) = shoal(&[
        "run",
        "scenarios/tiny.ron",
        "--out",
        dir.to_str().unwrap(),
        "--duration",
        "2",
    ]);
    assert_eq!(code, 0, "{out}{err}");
    let speed = out
        .lines()
        .find_map(|l| l.trim().strip_prefix("speed: "))
        .unwrap_or_else(|| panic!("no speed line:\n{out}"));
    let whole = speed.strip_suffix(" ticks/s").expect("ticks/s");
    assert!(whole.parse::<u64>().is_ok_and(|v| v > 0), "{out}");
    let line = out
        .lines()
        .find_map(|l| l.trim().strip_prefix("wall time: "))
        .unwrap_or_else(|| panic!("no wall time line:\n{out}"));
    let parts = named_figures(line);
    let names: Vec<&str> = parts.iter().map(|p| p.0).collect();
    assert_eq!(
        names,
        [
            "index",
            "perception",
            "agents",
            "events",
            "recording",
            "other"
        ],
        "{out}"
    );
    let total: f64 = parts.iter().map(|p| p.1).sum();
    assert!((total - 100.0).abs() <= 0.4, "{out}");
}
