//! The rule of the tests that need something cargo does not install (a browser, node packages, a
//! Python environment): under CI (`CI` set) a missing prerequisite fails the test; locally the
//! test skips, saying what is missing and which command installs it.

use std::io::Write;

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
