//! An interrupted run (Ctrl-C) leaves its folder marked incomplete, with what it recorded so far
//! and no file that looks complete.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn ctrl_c_leaves_an_incomplete_folder() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("run");
    // Long enough that it is still running when interrupted.
    let child = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args([
            "run",
            "scenarios/reef.ron",
            "--duration",
            "3600",
            "--quiet",
            "--out",
        ])
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until it has started recording.
    let start = Instant::now();
    while !dir.join("trajectories.csv.partial").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "run never started"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["status"], "incomplete");
    assert!(manifest["summary"]["stopped"]
        .as_str()
        .unwrap()
        .contains("interrupted"));
    let marker = std::fs::read_to_string(dir.join("INCOMPLETE")).unwrap();
    assert!(marker.contains("stopped at tick"), "{marker}");
    // What was recorded is there, whole lines only.
    let traj = std::fs::read_to_string(dir.join("trajectories.csv")).unwrap();
    assert!(traj.lines().count() > 1);
    assert!(traj.ends_with('\n'));
    assert!(!dir.join("trajectories.csv.partial").exists());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("incomplete output left in"), "{stdout}");
}
