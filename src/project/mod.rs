//! The load-time analysis of a project's files, shared by `shoal check` and `shoal lsp`: which
//! files a check covers, what kind each one is, the per-file check (species with their scripts
//! and imports, scenarios with their species, scripts, test files' literal names, terrain grids,
//! features and teams) and the check of relations between the species checked together, with
//! problems reported once per place. Reads files only through the loaders, so an editor's unsaved
//! buffers ([`crate::load::overlay`]) are read in place of the disk. Runs nothing.

use crate::diag::{Diagnostic, Diagnostics};
use crate::formation::Team;
use crate::load::overlay::{self, Texts};
use crate::scenario::Scenario;
use crate::script::Script;
use crate::species::{load_species_str, Species, SpeciesSet};
use crate::terrain::{load_pgm, parse_asc, Features};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What a file holds, told by its extension and, for RON, its first word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A species file.
    Species,
    /// A scenario file (`Scenario(...)`).
    Scenario,
    /// A behavior script or shared module (`.rhai` outside a `tests` folder).
    Script,
    /// A designers' test script (`.rhai` in a `tests` folder).
    Test,
    /// Terrain features (`Features(...)`).
    Features,
    /// A formation team (`Team(...)`).
    Team,
    /// An ESRI ASCII grid (`.asc`).
    AsciiGrid,
    /// A PGM height map (`.pgm`).
    HeightMap,
}

/// The kind of `path` (text `text`, when it is text). `.rhai` files in a `tests` folder are test
/// files only with `tests_apart`: `shoal check` compiles every script it is given alike.
pub fn kind_of(path: &Path, text: Option<&str>, tests_apart: bool) -> Kind {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "rhai" if tests_apart && in_tests_folder(path) => Kind::Test,
        "rhai" => Kind::Script,
        "asc" => Kind::AsciiGrid,
        "pgm" => Kind::HeightMap,
        _ => match text.map(crate::load::first_word) {
            Some("Scenario") => Kind::Scenario,
            Some("Features") => Kind::Features,
            Some("Team") => Kind::Team,
            _ => Kind::Species,
        },
    }
}

/// Whether `path` lies in a folder named `tests` (at any depth).
pub fn in_tests_folder(path: &Path) -> bool {
    path.parent()
        .is_some_and(|d| d.components().any(|c| c.as_os_str() == "tests"))
}

/// The files a check of `p` covers: `p` itself when it is a file, else the `.ron` files under
/// it in sorted order, `tests` and `fixtures` folders skipped.
pub fn collect(p: &Path, out: &mut Vec<PathBuf>) {
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

/// The behaviors folder a script's imports resolve against: the nearest folder above it named
/// `behaviors`, else its own folder.
pub fn script_root(path: &Path) -> PathBuf {
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
/// one's place (the check of relations lists every species of the folder).
pub fn add_once(diags: &mut Vec<Diagnostic>, d: Diagnostic, replace: bool) {
    let same = |x: &Diagnostic| {
        x.file == d.file && x.line == d.line && x.col == d.col && (d.line > 0 || x == &d)
    };
    match diags.iter_mut().find(|x| same(x)) {
        Some(x) if replace => *x = d,
        Some(_) => {}
        None => diags.push(d),
    }
}

/// What checking one file found.
#[derive(Default)]
pub struct FileCheck {
    /// Its problems, and those of the files it loads (a species' script, a scenario's species).
    pub diags: Vec<Diagnostic>,
    /// The species it defines, when it is a species file that validates.
    pub species: Option<Arc<Species>>,
}

/// Checks one file of kind `kind` with text `text` (`None` for a binary grid, read by its
/// loader). The files it loads are read through the loaders, so an active overlay applies.
pub fn check_file(path: &Path, kind: Kind, text: Option<&str>) -> FileCheck {
    let limits = crate::scenario::script_limits();
    let mut species = None;
    let result = match (kind, text) {
        (Kind::Scenario, Some(t)) => Scenario::load_str(path, t).map(drop),
        (Kind::Species, Some(t)) => {
            let root = path.parent().unwrap_or(Path::new("."));
            load_species_str(path, t, root, &limits).map(|s| species = Some(Arc::new(s)))
        }
        (Kind::Script, Some(t)) => Script::compile(path, t, &script_root(path), &limits).map(drop),
        (Kind::Test, Some(t)) => test_file(path, t),
        (Kind::Features, Some(t)) => Features::parse(t, path).map(drop),
        (Kind::Team, Some(t)) => Team::parse(t, path).map(drop),
        (Kind::AsciiGrid, Some(t)) => parse_asc(t, path).map(drop),
        // The format only; cell size and height scale are the loader's caller's.
        _ => load_pgm(path, 1.0, 1.0).map(drop),
    };
    FileCheck {
        diags: result.err().map(|d| d.0).unwrap_or_default(),
        species,
    }
}

#[cfg(feature = "tools")]
fn test_file(path: &Path, text: &str) -> Result<(), Diagnostics> {
    let d = crate::testing::check_text(path, text);
    if d.is_empty() {
        Ok(())
    } else {
        Err(Diagnostics(d))
    }
}

#[cfg(not(feature = "tools"))]
fn test_file(path: &Path, text: &str) -> Result<(), Diagnostics> {
    // Without the test runner a test file is only parsed.
    let engine = crate::script::new_engine(&crate::scenario::script_limits());
    engine
        .compile(text)
        .map(drop)
        .map_err(|e| crate::script::parse_diag(path, text, &e).into())
}

/// The problems of the relations between `species` (prey, predators, kin named by others):
/// a name may also be a species file in one of their folders that was not checked.
pub fn relations(species: Vec<Arc<Species>>) -> Vec<Diagnostic> {
    if species.is_empty() {
        return Vec::new();
    }
    let dirs: Vec<PathBuf> = species
        .iter()
        .filter_map(|s| s.file.parent().map(Path::to_path_buf))
        .collect();
    SpeciesSet::with_library(species, |n| {
        dirs.iter().any(|d| d.join(format!("{n}.ron")).is_file())
    })
    .err()
    .map(|d| d.0)
    .unwrap_or_default()
}

/// What a check of several files found.
#[derive(Default)]
pub struct Report {
    /// Every problem, each place once.
    pub diags: Diagnostics,
    /// Species files checked.
    pub species: usize,
    /// Scenario files checked.
    pub scenarios: usize,
    /// Other files checked (scripts, grids, features, teams).
    pub other: usize,
}

/// Checks `files` (as [`collect`] lists them) with `texts` read in place of those files: what
/// `shoal check` does, with an empty overlay.
pub fn check_files(files: &[PathBuf], texts: &Texts) -> Report {
    overlay::with(texts, || check_all(files)).0
}

fn check_all(files: &[PathBuf]) -> Report {
    let mut report = Report::default();
    let mut diags = Vec::new();
    let mut species = Vec::new();
    for f in files {
        let binary = f.extension().is_some_and(|x| x.eq_ignore_ascii_case("pgm"));
        // Every file is read once, through the reader that refuses pipes and devices.
        let text = if binary {
            None
        } else {
            match crate::diag::read_text(f, "file") {
                Ok(t) => Some(t),
                Err(d) => {
                    diags.push(d);
                    continue;
                }
            }
        };
        let kind = kind_of(f, text.as_deref(), false);
        match kind {
            Kind::Species => report.species += 1,
            Kind::Scenario => report.scenarios += 1,
            _ => report.other += 1,
        }
        let found = check_file(f, kind, text.as_deref());
        species.extend(found.species);
        // A species shared by several scenarios is reported once.
        for d in found.diags {
            add_once(&mut diags, d, false);
        }
    }
    // Relations between the species checked together (others may live in the same folder).
    for d in relations(species) {
        add_once(&mut diags, d, true);
    }
    report.diags = Diagnostics(diags);
    report
}
