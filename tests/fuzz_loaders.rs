//! The short fuzzing run: a fixed, seeded number of mutated inputs per loader (species, script,
//! scenario, ESRI and PGM terrain, features, HTTP requests), each of which must be accepted or
//! refused with located diagnostics, never panic and never run past 5 s. The long run is
//! `cargo run --release --example fuzz` (docs/testing.md); the approach is described in
//! `tests/fuzz_support/mod.rs`.

mod fuzz_support;

use fuzz_support::Target;

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
