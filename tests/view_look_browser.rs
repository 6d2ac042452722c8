//! How the replay page looks, on pixels: real recordings of every shipped scenario
//! (`scenarios/*.ron`, a few seconds each) opened in headless Debian Chromium and checked by
//! `tests/browser/look.test.mjs` (species shapes and colors, solid obstacles, the camera above the
//! ground, distinct behavior colors, a legend that fits, blended playback). Skips locally when the
//! browser is missing, like `view_browser.rs`.

mod browser_support;
mod fixtures;

use browser_support::{browser_available, repo, run_node};
use fixtures::{write_run, FixtureSpec};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;

/// `shoal run <scenario> --duration <seconds>` into `dir`, then `shoal view`; the page's path.
fn record(scenario: &Path, dir: &Path, seconds: f32) -> PathBuf {
    let shoal = env!("CARGO_BIN_EXE_shoal");
    let run = Command::new(shoal)
        .current_dir(repo())
        .arg("run")
        .arg(scenario)
        .args(["--quiet", "--duration", &seconds.to_string(), "--out"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}: {}",
        scenario.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    let view = Command::new(shoal).arg("view").arg(dir).output().unwrap();
    assert!(
        view.status.success(),
        "{}",
        String::from_utf8_lossy(&view.stderr)
    );
    dir.join("view.html")
}

/// Every shipped scenario, recorded for a few seconds: distinct shapes and colors per species,
/// solid obstacles and the rest of `look.test.mjs`. With `SHOAL_LOOK_SHOTS=<dir>` it also saves
/// a screenshot of each page there.
#[test]
fn shipped_scenarios_look_right_in_chromium() {
    if !browser_available("shipped_scenarios_look_right_in_chromium") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let mut scenarios: Vec<PathBuf> = std::fs::read_dir(repo().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    scenarios.sort();
    assert!(scenarios.len() >= 5, "shipped scenarios: {scenarios:?}");
    let mut args: Vec<OsString> = Vec::new();
    for s in &scenarios {
        let name = s.file_stem().unwrap().to_string_lossy().into_owned();
        args.push("--page".into());
        args.push(record(s, &tmp.path().join(name), 3.0).into());
    }
    if let Some(dir) = std::env::var_os("SHOAL_LOOK_SHOTS") {
        args.push("--shots".into());
        args.push(dir);
    }
    run_node("look.test.mjs", &args);
}

/// Frame rate of the replay of 10,000 agents × 600 recorded frames (all frames in the page);
/// run with `cargo test --release --test view_look_browser -- --ignored --nocapture`.
/// `SHOAL_FPS_FRAMES=<n>` records another number of frames; `SHOAL_FPS_KEEP=<file>` keeps a copy
/// of the page (to measure it elsewhere with `node tests/browser/look.test.mjs --fps <file>`).
#[test]
#[ignore = "measurement, not a check: prints page size and playback frame rate"]
fn replay_of_10k_agents_600_frames_frame_rate() {
    if !browser_available("replay_of_10k_agents_600_frames_frame_rate") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let run = write_run(
        &tmp.path().join("reef-10k-600"),
        &FixtureSpec {
            agents: 10_000,
            frames: std::env::var("SHOAL_FPS_FRAMES")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(600),
            ..FixtureSpec::default()
        },
    );
    let options = shoal::view::ViewOptions {
        max_payload_bytes: usize::MAX,
    };
    let html = shoal::view::build_html_with(&run, &options).unwrap();
    let page = run.join("view.html");
    std::fs::write(&page, html).unwrap();
    if let Some(keep) = std::env::var_os("SHOAL_FPS_KEEP") {
        std::fs::copy(&page, keep).unwrap();
    }
    run_node::<OsString>("look.test.mjs", &["--fps".into(), page.into()]);
}
