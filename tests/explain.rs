//! `shoal run --explain`: the recording gains `explain.jsonl` and nothing else changes (the
//! trajectories and events are byte for byte those of the same run without it); the replay page
//! built from it draws the selected agent's target line and perception volume and shows why it
//! moves, and hides a walker's fish-only fields (`tests/browser/explain.test.mjs`, headless Debian
//! Chromium).

mod browser_support;

use browser_support::{browser_available, repo, run_node};
use std::path::Path;
use std::process::Command;

/// Runs `shoal run <scenario>` for `seconds` into `out`, with `extra` arguments.
fn shoal_run(scenario: &str, seconds: &str, out: &Path, extra: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .current_dir(repo())
        .args(["run", scenario, "--duration", seconds, "--quiet", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .expect("run shoal");
    assert!(
        o.status.success(),
        "shoal run failed: {}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn explaining_adds_its_file_and_changes_no_result() {
    let tmp = tempfile::tempdir().unwrap();
    for scenario in ["scenarios/showcase.ron", "scenarios/squad_march.ron"] {
        let off = tmp.path().join("off");
        let on = tmp.path().join("on");
        shoal_run(scenario, "5", &off, &[]);
        shoal_run(scenario, "5", &on, &["--explain"]);
        for f in ["trajectories.csv", "food.csv", "events.jsonl"] {
            let a = std::fs::read(off.join(f)).unwrap();
            let b = std::fs::read(on.join(f)).unwrap();
            assert!(a == b, "{scenario}: {f} differs with --explain");
        }
        assert!(!off.join("explain.jsonl").exists());
        let text = std::fs::read_to_string(on.join("explain.jsonl")).unwrap();
        let lines: Vec<serde_json::Value> = text
            .lines()
            .map(|l| serde_json::from_str(l).expect("one JSON object a line"))
            .collect();
        let frames = lines.iter().filter(|v| v["type"] == "frame").count();
        assert!(frames > 0, "{scenario}: no frame explained");
        let manifest: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(on.join("manifest.json")).unwrap())
                .unwrap();
        assert!(
            manifest["outputs"]
                .as_array()
                .unwrap()
                .iter()
                .any(|o| o == "explain.jsonl"),
            "{scenario}: the manifest lists explain.jsonl"
        );
        // Every explained frame is a recorded frame.
        let interval = manifest["record_interval"].as_u64().unwrap();
        assert!(lines
            .iter()
            .filter(|v| v["type"] == "frame")
            .all(|v| v["tick"].as_u64().unwrap() % interval == 0));
        std::fs::remove_dir_all(&off).unwrap();
        std::fs::remove_dir_all(&on).unwrap();
    }
}

#[test]
fn replay_page_draws_the_selected_agents_target_and_perception_in_chromium() {
    if !browser_available("replay_page_draws_the_selected_agents_target_and_perception_in_chromium")
    {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("showcase");
    shoal_run("scenarios/showcase.ron", "8", &run, &["--explain"]);
    let page = shoal::view::write_html(&run).unwrap();
    let squad = tmp.path().join("squad");
    shoal_run("scenarios/squad_march.ron", "3", &squad, &["--explain"]);
    let walker = shoal::view::write_html(&squad).unwrap();
    let mut args = vec![
        "--page".into(),
        page.into_os_string(),
        "--walker".into(),
        walker.into_os_string(),
    ];
    // Screenshots for docs/viewer.md, when asked for.
    if let Some(dir) = std::env::var_os("SHOAL_EXPLAIN_SHOTS") {
        args.extend(["--shots".into(), dir]);
    }
    run_node("explain.test.mjs", &args);
}
