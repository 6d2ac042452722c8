//! `shoal watch` in a real browser: the binary runs a project in a temporary folder, headless
//! Debian Chromium (driven by `tests/browser/watch.test.mjs`, playwright-core) connects to it,
//! sees the agents move, sees the error overlay appear after a broken edit and disappear after
//! the fix, pauses, steps and inspects an agent. Under CI (`CI` set) a missing browser, node or
//! `npm ci --prefix tests/browser` is a failure; locally the test skips with a visible message.

mod browser_support;
mod live_support;

use browser_support::{browser_available, repo};
use live_support::{line_col, Project, DEBUG_FISH};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// Kills the watch process when the test ends, however it ends.
struct Child(std::process::Child);

impl Drop for Child {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `shoal watch` on `p`'s scenario (any port, plus `extra` arguments) and reads its
/// terminal in the background: the URL it serves, then the log, returned when it exits.
fn watch(p: &Project, extra: &[&str]) -> (Child, String, std::thread::JoinHandle<Vec<String>>) {
    let mut child = Child(
        Command::new(env!("CARGO_BIN_EXE_shoal"))
            .arg("watch")
            .arg(p.scenario())
            .args(["--port", "0"])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("start shoal watch"),
    );
    let stdout = child.0.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel();
    let reader = std::thread::spawn(move || {
        let mut log = Vec::new();
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if let Some(url) = line.strip_prefix("live view: ") {
                let _ = tx.send(url.split_whitespace().next().unwrap_or("").to_string());
            }
            log.push(line);
        }
        log
    });
    let url = rx
        .recv_timeout(Duration::from_secs(60))
        .expect("shoal watch printed no URL");
    (child, url, reader)
}

#[test]
fn shoal_watch_in_chromium_moves_shows_and_clears_the_error_overlay_and_inspects() {
    if !browser_available("shoal_watch_in_chromium") {
        return;
    }
    let p = Project::new();
    let (child, url, reader) = watch(&p, &[]);
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");

    let out = Command::new("node")
        .arg(repo().join("tests/browser/watch.test.mjs"))
        .args(["--url", &url, "--agents", "24", "--species"])
        .arg(p.path("behaviors/fish.ron"))
        .output()
        .expect("run node");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    eprintln!("{stderr}");
    drop(child);
    let log = reader.join().unwrap();
    println!("shoal watch printed:\n{}", log.join("\n"));
    assert!(
        out.status.success(),
        "watch.test.mjs failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    // The terminal logged the rejected edit with its diagnostic and the accepted fix, stamped.
    let stamped = |l: &&String| l.starts_with('[') && l.as_bytes().get(13) == Some(&b']');
    assert!(log
        .iter()
        .filter(stamped)
        .any(|l| l.contains("rejected: version 0 keeps running")));
    assert!(log
        .iter()
        .any(|l| l.contains("fish.ron:15:19: unknown condition `Abov`")));
    assert!(log
        .iter()
        .filter(stamped)
        .any(|l| l.contains("accepted: version 1")));
}

#[test]
fn breakpoints_pause_at_their_tick_and_script_errors_show_in_chromium() {
    if !browser_available("breakpoints_and_script_errors_in_chromium") {
        return;
    }
    let p = Project::debugging();
    let (child, url, reader) = watch(&p, &["--paused"]);
    let (dart_line, _) = line_col(DEBUG_FISH, "name: \"dart\"");
    let mut cmd = Command::new("node");
    cmd.arg(repo().join("tests/browser/debug.test.mjs")).args([
        "--url",
        &url,
        "--dart-line",
        &dart_line.to_string(),
    ]);
    if let Ok(dir) = std::env::var("SHOAL_SHOTS") {
        cmd.args(["--shots", &dir]);
    }
    let out = cmd.output().expect("run node");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    eprintln!("{stderr}");
    drop(child);
    let log = reader.join().unwrap();
    println!("shoal watch printed:\n{}", log.join("\n"));
    assert!(
        out.status.success(),
        "debug.test.mjs failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    // The terminal names the agent, species and function of the script error, and the pause.
    assert!(
        log.iter()
            .any(|l| l.contains("script error at tick") && l.contains("(fish) in `oops()`")),
        "{log:#?}"
    );
    assert!(log
        .iter()
        .any(|l| l.contains("by breakpoint 1: agent") && l.contains("entered dart")));
}
