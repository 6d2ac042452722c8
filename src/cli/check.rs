//! `shoal check [PATHS]`: validates species (with their scripts), scenarios, scripts, terrain
//! grids, feature and team files without running anything; exits non-zero on any error. A
//! file's kind comes from its extension (`.rhai`, `.asc`, `.pgm`) or, for RON, its first word.

use shoal::diag::Diagnostics;
use shoal::scenario::Scenario;
use shoal::script::Script;
use shoal::species::{load_species_str, SpeciesSet};
use shoal::terrain::{load_pgm, parse_asc, Features};
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

/// What a file given to `check` holds, told by its extension and, for RON, its first word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Species,
    Scenario,
    Script,
    Features,
    Team,
    AsciiGrid,
    HeightMap,
}

fn kind_of(path: &Path, text: Option<&str>) -> Kind {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "rhai" => Kind::Script,
        "asc" => Kind::AsciiGrid,
        "pgm" => Kind::HeightMap,
        _ => match text.map(shoal::load::first_word) {
            Some("Scenario") => Kind::Scenario,
            Some("Features") => Kind::Features,
            Some("Team") => Kind::Team,
            _ => Kind::Species,
        },
    }
}

/// The behaviors folder a script's imports resolve against: the nearest folder above it named
/// `behaviors`, else its own folder.
fn script_root(path: &Path) -> PathBuf {
    path.ancestors()
        .skip(1)
        .find(|a| a.file_name().is_some_and(|n| n == "behaviors"))
        .or(path.parent())
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf()
}

/// Adds `d` unless a problem at the same place of the same file is already reported: a species
/// file that several scenarios load is checked once per scenario, and a message that lists the
/// loaded species differs from one scenario to the next. With `replace`, `d` takes the earlier
/// one's place (the library's check lists every species of the folder).
fn add_once(diags: &mut Diagnostics, d: shoal::diag::Diagnostic, replace: bool) {
    let same = |x: &shoal::diag::Diagnostic| {
        x.file == d.file && x.line == d.line && x.col == d.col && (d.line > 0 || x == &d)
    };
    match diags.0.iter_mut().find(|x| same(x)) {
        Some(x) if replace => *x = d,
        Some(_) => {}
        None => diags.0.push(d),
    }
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
    let (mut n_species, mut n_scenarios, mut n_other) = (0, 0, 0);
    let limits = shoal::scenario::script_limits();
    for f in &files {
        let binary = f.extension().is_some_and(|x| x.eq_ignore_ascii_case("pgm"));
        // Every file is read once, through the reader that refuses pipes and devices.
        let text = if binary {
            None
        } else {
            match shoal::diag::read_text(f, "file") {
                Ok(t) => Some(t),
                Err(d) => {
                    diags.0.push(d);
                    continue;
                }
            }
        };
        let result = match (kind_of(f, text.as_deref()), text.as_deref()) {
            (Kind::Scenario, Some(t)) => {
                n_scenarios += 1;
                Scenario::load_str(f, t).map(drop)
            }
            (Kind::Species, Some(t)) => {
                n_species += 1;
                let root = f.parent().unwrap_or(Path::new("."));
                load_species_str(f, t, root, &limits).map(|s| species.push(Arc::new(s)))
            }
            (Kind::Script, Some(t)) => {
                n_other += 1;
                Script::compile(f, t, &script_root(f), &limits).map(drop)
            }
            (Kind::Features, Some(t)) => {
                n_other += 1;
                Features::parse(t, f).map(drop)
            }
            (Kind::Team, Some(t)) => {
                n_other += 1;
                shoal::formation::Team::parse(t, f).map(drop)
            }
            (Kind::AsciiGrid, Some(t)) => {
                n_other += 1;
                parse_asc(t, f).map(drop)
            }
            _ => {
                n_other += 1;
                // The format only; cell size and height scale are the loader's caller's.
                load_pgm(f, 1.0, 1.0).map(drop)
            }
        };
        // A species shared by several scenarios is reported once.
        for d in result.err().map(|d| d.0).unwrap_or_default() {
            add_once(&mut diags, d, false);
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
                add_once(&mut diags, x, true);
            }
        }
    }
    if diags.0.is_empty() {
        if n_other > 0 {
            println!(
                "ok: {n_species} species, {n_scenarios} scenarios, {n_other} other files, no errors"
            );
        } else {
            println!("ok: {n_species} species, {n_scenarios} scenarios, no errors");
        }
        Ok(ExitCode::SUCCESS)
    } else {
        Ok(super::report(&diags))
    }
}
