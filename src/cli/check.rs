//! `shoal check [PATHS]`: validates species (with their scripts) and scenarios without running
//! anything; exits non-zero on any error.

use shoal::diag::Diagnostics;
use shoal::scenario::Scenario;
use shoal::species::{load_species, SpeciesSet};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

fn collect(p: &Path, out: &mut Vec<PathBuf>) {
    if p.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(p)
            .map(|r| r.flatten().map(|e| e.path()).collect())
            .unwrap_or_default();
        entries.sort();
        for e in entries {
            if e.is_dir() {
                if e.file_name()
                    .is_some_and(|n| n != "tests" && n != "fixtures")
                {
                    collect(&e, out);
                }
            } else if e.extension().is_some_and(|x| x == "ron") {
                out.push(e);
            }
        }
    } else {
        out.push(p.to_path_buf());
    }
}

/// Is this RON file a scenario (rather than a species)?
fn is_scenario(path: &Path) -> bool {
    std::fs::read_to_string(path).is_ok_and(|t| {
        t.lines()
            .map(str::trim)
            .find(|l| !l.is_empty() && !l.starts_with("//"))
            .is_some_and(|l| l.starts_with("Scenario"))
    })
}

/// Runs `shoal check`.
pub fn check(paths: &[PathBuf]) -> anyhow::Result<ExitCode> {
    let roots: Vec<PathBuf> = if paths.is_empty() {
        vec![PathBuf::from("behaviors"), PathBuf::from("scenarios")]
    } else {
        paths.to_vec()
    };
    let mut files = Vec::new();
    for r in &roots {
        if !r.exists() {
            eprintln!("{}: no such file or folder", r.display());
            return Ok(ExitCode::from(super::BAD_INPUT));
        }
        collect(r, &mut files);
    }
    let mut diags = Diagnostics::default();
    let mut species = Vec::new();
    let (mut n_species, mut n_scenarios) = (0, 0);
    for f in &files {
        if is_scenario(f) {
            n_scenarios += 1;
            if let Err(d) = Scenario::load(f) {
                diags.0.extend(d.0);
            }
        } else {
            n_species += 1;
            let root = f.parent().unwrap_or(Path::new("."));
            match load_species(f, root, &shoal::scenario::script_limits()) {
                Ok(s) => species.push(Arc::new(s)),
                Err(d) => diags.0.extend(d.0),
            }
        }
    }
    // Relations between the species checked together (others may live in the same folder).
    if !species.is_empty() {
        let dirs: Vec<PathBuf> = species
            .iter()
            .filter_map(|s| s.file.parent().map(Path::to_path_buf))
            .collect();
        if let Err(d) = SpeciesSet::with_library(species, |n| {
            dirs.iter().any(|d| d.join(format!("{n}.ron")).is_file())
        }) {
            for x in d.0 {
                if !diags.0.contains(&x) {
                    diags.0.push(x);
                }
            }
        }
    }
    if diags.0.is_empty() {
        println!("ok: {n_species} species, {n_scenarios} scenarios, no errors");
        Ok(ExitCode::SUCCESS)
    } else {
        Ok(super::report(&diags))
    }
}
