//! `shoal check [PATHS]`: validates species (with their scripts), scenarios, scripts, terrain
//! grids, feature and team files without running anything; exits non-zero on any error. The
//! analysis is the library's ([`shoal::project`]), the one the language server runs as you type.

use shoal::project;
use std::path::PathBuf;
use std::process::ExitCode;

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
        project::collect(r, &mut files);
    }
    // No editor buffers: every file is read from the disk.
    let report = project::check_files(&files, &Default::default());
    if report.diags.0.is_empty() {
        let (n_species, n_scenarios, n_other) = (report.species, report.scenarios, report.other);
        if n_other > 0 {
            println!(
                "ok: {n_species} species, {n_scenarios} scenarios, {n_other} other files, no errors"
            );
        } else {
            println!("ok: {n_species} species, {n_scenarios} scenarios, no errors");
        }
        Ok(ExitCode::SUCCESS)
    } else {
        Ok(super::report(&report.diags))
    }
}
