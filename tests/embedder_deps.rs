//! An embedder depends on `shoal` with `default-features = false`: its build must hold no
//! command line, file watcher, signal handler or tool-only crate.

use std::process::Command;

#[test]
fn the_engine_without_tools_pulls_in_no_tool_crate() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args([
            "tree",
            // The engine package alone: the workspace's default members also hold the Bevy
            // plugin, whose own tree (Bevy's) is not the engine's.
            "--package",
            "shoal",
            "--no-default-features",
            "--edges",
            "normal",
            "--prefix",
            "none",
            "--offline",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree = String::from_utf8_lossy(&out.stdout);
    let crates: Vec<&str> = tree.lines().filter_map(|l| l.split(' ').next()).collect();
    assert!(
        crates.contains(&"glam") && crates.contains(&"rhai"),
        "{tree}"
    );
    for tool in ["clap", "anyhow", "ctrlc", "notify", "notify-debouncer-full"] {
        assert!(
            !crates.contains(&tool),
            "{tool} in the embedder's tree:\n{tree}"
        );
    }
}
