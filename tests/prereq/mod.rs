//! For the tests that drive something cargo does not install (a browser, node packages, a
//! Python environment): their rule for a missing prerequisite (under CI, `CI` set, the test
//! fails; locally it skips, saying what is missing and which command installs it), and running
//! such a tool with its output shown.

use std::io::Write;
use std::path::PathBuf;
use std::process::Command;

/// The repository root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `cmd` from the repository root, printing what it printed; fails the test with that
/// output when it fails. `what` names it in the failure.
pub fn run_tool(what: &str, cmd: &mut Command) {
    let out = cmd.current_dir(repo()).output().expect(what);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    eprintln!("{stderr}");
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
}

/// Whether `test` may run, given what is `missing`: true when nothing is. `kind` names the
/// prerequisites in the failure ("browser test"), `setup` the command that installs them.
pub fn may_run(test: &str, kind: &str, missing: &[String], setup: &str) -> bool {
    if missing.is_empty() {
        return true;
    }
    let what = missing.join(", ");
    if std::env::var_os("CI").is_some() {
        panic!("{test}: {kind} prerequisites missing under CI: {what}; run `{setup}`");
    }
    // Straight to the process's stderr so that the test harness does not capture it.
    let _ = writeln!(
        std::io::stderr().lock(),
        "SKIPPED: {test}: missing {what}; run `{setup}` to enable it"
    );
    false
}
