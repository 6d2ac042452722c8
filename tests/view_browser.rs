//! The replay page in a real browser: headless Debian Chromium driven by
//! `tests/browser/view.test.mjs` (playwright-core). Under CI (`CI` set) a missing browser, node or
//! `npm ci --prefix tests/browser` is a failure; locally the test skips with a visible message.

mod browser_support;
mod fixtures;

use browser_support::{browser_available, repo};
use std::process::Command;

use fixtures::{write_run, FixtureSpec};

/// Runs `node tests/browser/<script> <args…>` and fails with its output when it fails.
fn run_node(script: &str, args: &[&std::ffi::OsStr]) {
    let out = Command::new("node")
        .arg(repo().join("tests/browser").join(script))
        .args(args)
        .output()
        .expect("run node");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    eprintln!("{stderr}");
    assert!(
        out.status.success(),
        "{script} failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
}

#[test]
fn replay_page_renders_scrubs_and_inspects_in_chromium() {
    if !browser_available("replay_page_renders_scrubs_and_inspects_in_chromium") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let reef = write_run(&tmp.path().join("reef-7"), &FixtureSpec::default());
    let page = shoal::view::write_html(&reef).unwrap();
    let terrain = write_run(
        &tmp.path().join("terrain-3"),
        &FixtureSpec {
            agents: 60,
            frames: 20,
            terrain_and_plan: true,
            incomplete: true,
        },
    );
    let smoke = shoal::view::write_html(&terrain).unwrap();
    run_node(
        "view.test.mjs",
        &[
            "--page".as_ref(),
            page.as_os_str(),
            "--smoke".as_ref(),
            smoke.as_os_str(),
        ],
    );
}

#[test]
fn live_page_speaks_the_watch_protocol_in_chromium() {
    if !browser_available("live_page_speaks_the_watch_protocol_in_chromium") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let page = tmp.path().join("live.html");
    std::fs::write(&page, shoal::view::live_html()).unwrap();
    run_node("live.test.mjs", &[page.as_os_str()]);
}

/// Page size and frame rate with 10,000 agents; run with `cargo test --test view_browser -- --ignored`.
#[test]
#[ignore = "measurement, not a check: prints page size and frame rate for 10,000 agents"]
fn replay_page_with_10k_agents_frame_rate() {
    if !browser_available("replay_page_with_10k_agents_frame_rate") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let run = write_run(
        &tmp.path().join("reef-10k"),
        &FixtureSpec {
            agents: 10_000,
            frames: 100,
            ..FixtureSpec::default()
        },
    );
    let page = shoal::view::write_html(&run).unwrap();
    run_node("view.test.mjs", &["--perf".as_ref(), page.as_os_str()]);
}

/// The page of a real recording (`shoal run scenarios/tiny.ron`, then `shoal view`).
#[test]
fn replay_page_of_a_recorded_run_in_chromium() {
    if !browser_available("replay_page_of_a_recorded_run_in_chromium") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("tiny");
    let run = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["run", "scenarios/tiny.ron", "--quiet", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let view = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .arg("view")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        view.status.success(),
        "{}",
        String::from_utf8_lossy(&view.stderr)
    );
    let page = dir.join("view.html");
    run_node("view.test.mjs", &["--page".as_ref(), page.as_os_str()]);
}
