//! Shared by the browser tests: whether headless Chromium, node and playwright-core are there.
//! Under CI (`CI` set) a missing prerequisite fails the test; locally it skips with a visible
//! message.
// Each test crate uses its own part of this module.
#![allow(dead_code)]

#[path = "../prereq/mod.rs"]
mod prereq;

use std::ffi::OsStr;
use std::path::Path;
use std::process::Command;

/// Debian's Chromium.
pub const CHROMIUM: &str = "/usr/bin/chromium";

pub use prereq::repo;

/// What is missing for a browser test, if anything.
pub fn missing_prerequisites() -> Vec<String> {
    let mut missing = Vec::new();
    if !Path::new(CHROMIUM).exists() {
        missing.push(format!("{CHROMIUM} (apt-get install -y chromium)"));
    }
    let node = Command::new("node").arg("--version").output();
    if !matches!(node, Ok(ref o) if o.status.success()) {
        missing.push("node (apt-get install -y nodejs npm)".to_string());
    }
    if !repo()
        .join("tests/browser/node_modules/playwright-core")
        .exists()
    {
        missing.push(
            "tests/browser/node_modules/playwright-core (npm ci --prefix tests/browser)".into(),
        );
    }
    missing
}

/// True when the test may run; under CI a missing prerequisite fails instead of skipping.
pub fn browser_available(test: &str) -> bool {
    prereq::may_run(
        test,
        "browser test",
        &missing_prerequisites(),
        "bash tests/browser/setup.sh",
    )
}

/// Runs `node tests/browser/<script> <args…>`, prints its output, and fails with it when the
/// script fails.
pub fn run_node<A: AsRef<OsStr>>(script: &str, args: &[A]) {
    prereq::run_tool(
        script,
        Command::new("node")
            .arg(repo().join("tests/browser").join(script))
            .args(args),
    );
}
