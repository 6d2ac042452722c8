//! `shoal lsp` driven by a real LSP client over stdio: VS Code's own client-side protocol library
//! (`vscode-languageserver-protocol` + `vscode-jsonrpc`, pinned in `tests/lsp/package-lock.json`)
//! runs the node:test files `tests/lsp/*.test.mjs` against the binary cargo built, each on a
//! temporary copy of the shipped project. Under CI (`CI` set) a missing node or
//! `npm ci --prefix tests/lsp` is a failure; locally the test skips with a visible message.

mod prereq;

use prereq::repo;

use std::process::Command;

/// What is missing for the client tests, if anything.
fn missing_prerequisites() -> Vec<String> {
    let mut missing = Vec::new();
    let node = Command::new("node").arg("--version").output();
    if !matches!(node, Ok(ref o) if o.status.success()) {
        missing.push("node (apt-get install -y nodejs npm)".to_string());
    }
    for package in ["vscode-languageserver-protocol", "vscode-jsonrpc"] {
        if !repo().join("tests/lsp/node_modules").join(package).exists() {
            missing.push(format!(
                "tests/lsp/node_modules/{package} (bash tests/lsp/setup.sh)"
            ));
        }
    }
    missing
}

/// True when the test may run; under CI a missing prerequisite fails instead of skipping.
fn client_available(test: &str) -> bool {
    prereq::may_run(
        test,
        "LSP client test",
        &missing_prerequisites(),
        "bash tests/lsp/setup.sh",
    )
}

/// Runs `node --test tests/lsp/<file>` against this build's `shoal`, prints its report, and
/// fails with it when a test in the file fails.
fn run_client_tests(file: &str) {
    if !client_available(file) {
        return;
    }
    prereq::run_tool(
        file,
        Command::new("node")
            .arg("--test")
            .arg("--test-reporter=spec")
            .arg(repo().join("tests/lsp").join(file))
            .env("SHOAL_BIN", env!("CARGO_BIN_EXE_shoal")),
    );
}

#[test]
fn lsp_handshake_and_shutdown() {
    run_client_tests("handshake.test.mjs");
}

#[test]
fn lsp_diagnostics_as_you_type() {
    run_client_tests("diagnostics.test.mjs");
}

#[test]
fn lsp_completion_of_primitives_and_the_script_api() {
    run_client_tests("completion.test.mjs");
}

#[test]
fn lsp_hover_shows_the_reference() {
    run_client_tests("hover.test.mjs");
}

#[test]
fn lsp_definition_references_and_outline() {
    run_client_tests("navigation.test.mjs");
}

#[test]
fn lsp_rename_across_ron_rhai_and_tests() {
    run_client_tests("rename.test.mjs");
}

/// Prints median and p95 response times per request kind (20 of each; the release figures in
/// BENCHMARKS.md: see `tests/lsp/latency.test.mjs`).
#[test]
fn lsp_response_times() {
    run_client_tests("latency.test.mjs");
}
