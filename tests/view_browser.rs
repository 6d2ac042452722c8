//! The replay page in a real browser: headless Debian Chromium driven by
//! `tests/browser/view.test.mjs` (playwright-core). Under CI (`CI` set) a missing browser, node or
//! `npm ci --prefix tests/browser` is a failure; locally the test skips with a visible message.

mod browser_support;
mod fixtures;

use browser_support::{browser_available, repo, run_node};
use std::process::Command;

use fixtures::{write_run, FixtureSpec};

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

/// A `health.json` for the default fixture: `reef_fish` at the pitch limit (warning at tick 131,
/// between the recorded ticks 130 and 132, agent 7) and `wrasse` within every bound.
fn health_json() -> String {
    let species = |name: &str, pitch: f64, at: &str| {
        format!(
            r#"{{"name":"{name}","agents":100,"agent_ticks":10000,"stopped_share":0.0,
            "frozen_agents":0,"frozen_episodes":0,"pitch_limit_share":{pitch},
            "pitch_limit_at":{at},"transitions":10,"switch_rate":0.1,"episodes":10,
            "short_episode_share":0.0,"one_tick_share":0.0,"flips":[],"turning":1.0,
            "net_turning":1.0,"turning_waste":1.0,"neighbor_pairs":0,"overlapping_pairs":0,
            "overlap_share":0.0,"obstacles":{{"agent_ticks":0,"inside_ticks":0,"agents_inside":0}},
            "messages":0,"messages_per_agent_second":0.0,"behaviors":[],"frozen":[]}}"#
        )
    };
    format!(
        r#"{{"format":1,"dt":0.05,"ticks":200,"pair_interval":5,"species":[{},{}],
        "coincident":{{"samples":40,"mean":0.0,"max":0}}}}"#,
        species("reef_fish", 0.4, r#"{"tick":131,"agent":7}"#),
        species("wrasse", 0.0, "null"),
    )
}

#[test]
fn replay_page_shows_run_health_and_jumps_to_a_warning_in_chromium() {
    if !browser_available("replay_page_shows_run_health_and_jumps_to_a_warning_in_chromium") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let run = write_run(&tmp.path().join("reef-7"), &FixtureSpec::default());
    std::fs::write(run.join(shoal::health::FILE), health_json()).unwrap();
    let page = shoal::view::write_html(&run).unwrap();
    let bare = write_run(
        &tmp.path().join("old-1"),
        &FixtureSpec {
            agents: 30,
            frames: 10,
            ..FixtureSpec::default()
        },
    );
    let without = shoal::view::write_html(&bare).unwrap();
    run_node(
        "view.test.mjs",
        &[
            "--health".as_ref(),
            page.as_os_str(),
            "--no-health".as_ref(),
            without.as_os_str(),
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

#[test]
fn state_machine_graph_follows_the_selected_agent_in_chromium() {
    if !browser_available("state_machine_graph_follows_the_selected_agent_in_chromium") {
        return;
    }
    // A real recording: the tiny scenario run by the binary.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("tiny");
    let run = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .current_dir(repo())
        .args(["run", "scenarios/tiny.ron", "--quiet", "--out"])
        .arg(&dir)
        .output()
        .expect("run shoal");
    assert!(run.status.success(), "{run:?}");
    let page = shoal::view::write_html(&dir).unwrap();
    let mut args: Vec<&std::ffi::OsStr> = vec!["--page".as_ref(), page.as_os_str()];
    let shot =
        std::env::var_os("SHOAL_SHOTS").map(|d| std::path::Path::new(&d).join("viewer-graph.png"));
    if let Some(s) = &shot {
        args.extend(["--shot".as_ref(), s.as_os_str()]);
    }
    run_node("graph.test.mjs", &args);
}
