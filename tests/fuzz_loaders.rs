//! The short fuzzing run: a fixed, seeded number of mutated inputs per loader (species, script,
//! scenario, ESRI and PGM terrain, features, HTTP requests), each of which must be accepted or
//! refused with located diagnostics, never panic and never run past 5 s. The long run is
//! `cargo run --release --example fuzz` (docs/testing.md); the approach is described in
//! `tests/fuzz_support/mod.rs`.

mod fuzz_support;

use fuzz_support::{execute, Outcome, Target};
use std::time::{Duration, Instant};

/// Executions per loader: a few seconds in all on two cores. Loaders that load every species
/// of a scenario cost more per input, so they get fewer.
fn budget(t: Target) -> u64 {
    match t {
        Target::Scenario => 300,
        Target::Species | Target::Script => 1_000,
        _ => 3_000,
    }
}

fn fuzz(t: Target) {
    let rep = fuzz_support::run(t, 20_261_125, budget(t), 1, None, |_| {});
    println!("{rep}");
    if let Some(f) = rep.findings.first() {
        let dir = std::env::temp_dir().join("shoal-fuzz-crashes");
        let saved = fuzz_support::save_findings(&rep, &dir);
        panic!(
            "{} on {} input (exec {}): {}; input saved to {}",
            f.kind,
            t.name(),
            f.exec,
            f.message,
            saved[0].display()
        );
    }
    assert_eq!(rep.execs, budget(t));
}

#[test]
fn species_loader_survives_mutated_files() {
    fuzz(Target::Species);
}

#[test]
fn script_loader_survives_mutated_files() {
    fuzz(Target::Script);
}

#[test]
fn scenario_loader_survives_mutated_files() {
    fuzz(Target::Scenario);
}

#[test]
fn asc_terrain_loader_survives_mutated_files() {
    fuzz(Target::Asc);
}

#[test]
fn pgm_terrain_loader_survives_mutated_files() {
    fuzz(Target::Pgm);
}

#[test]
fn feature_loader_survives_mutated_files() {
    fuzz(Target::Features);
}

#[test]
fn http_parser_survives_mutated_requests() {
    fuzz(Target::Http);
}

/// Runs `input` on `t` and returns its outcome, failing if it takes a second or more.
fn quickly(t: Target, input: &str) -> Outcome {
    let start = Instant::now();
    let o = execute(t, input.as_bytes());
    assert!(
        start.elapsed() < Duration::from_secs(1),
        "took {:?}",
        start.elapsed()
    );
    o
}

#[test]
fn a_scenario_listing_forty_thousand_species_is_refused_at_once() {
    // Found by the fuzzer: each missing species was located by scanning the whole line, 5 s.
    let text = |name: &str| {
        let names = vec![format!("\"{name}\""); 40_000].join(", ");
        format!(
            "Scenario(dt: 0.05, duration: 1.0, bounds: (min: (0.0, 0.0, 0.0), max: (1.0, 1.0, 1.0)), species: [{names}])"
        )
    };
    let Outcome::Refused { shape, located } = quickly(Target::Scenario, &text("nowhere")) else {
        panic!("accepted");
    };
    assert!(located && shape.starts_with("species file"), "{shape}");
    // An existing species repeated is loaded once, then refused as listed twice.
    let Outcome::Refused { shape, located } = quickly(Target::Scenario, &text("shark")) else {
        panic!("accepted");
    };
    assert!(
        located && shape.starts_with("species \"\" is listed twice"),
        "{shape}"
    );
}

#[test]
fn a_missing_species_written_with_escapes_is_located_at_the_list() {
    // Found by the fuzzer: the name as parsed is not in the text, so the error had no line.
    let text = "Scenario(\n    dt: 0.05,\n    duration: 1.0,\n    bounds: (min: (0.0, 0.0, 0.0), max: (1.0, 1.0, 1.0)),\n    species: [\"nowh\\u{65}re\"],\n)\n";
    let Outcome::Refused { shape, located } = quickly(Target::Scenario, text) else {
        panic!("accepted");
    };
    assert!(located && shape.starts_with("species file"), "{shape}");
}
