//! Diagnostics as you type: the project's files checked by [`crate::project::check_file`] (the
//! check `shoal check` runs) with the open buffers overlaid, each check's result cached with
//! the files it read, so that an edit re-checks only the checks that read the edited file (a
//! species' scenarios and tests, a script's species). Problems are grouped by the file they are
//! in and published per file; a file whose problems went away gets an empty list.

use super::docs::{diag_range, Documents};
use crate::diag::Diagnostic;
use crate::load::overlay::{self, normalize};
use crate::project::{self, in_tests_folder, kind_of};
use crate::species::Species;
use lsp_types::{DiagnosticSeverity, NumberOrString};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// One cached check: of a species, scenario, test file, or a script no species loads.
struct Unit {
    diags: Vec<Diagnostic>,
    /// Every file the check read (normalized), itself included.
    deps: BTreeSet<PathBuf>,
    species: Option<Arc<Species>>,
}

/// The cached checks and what was last published.
#[derive(Default)]
pub struct Analysis {
    units: BTreeMap<PathBuf, Unit>,
    published: BTreeMap<PathBuf, Vec<Diagnostic>>,
}

/// Whether `path` is checked on its own: species, scenarios, test files, features and teams.
/// Scripts are checked through the species that load them.
fn is_unit(path: &Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    match ext {
        "rhai" => in_tests_folder(path),
        "ron" => true,
        _ => false,
    }
}

impl Analysis {
    /// Checks every file of `files` that is checked on its own.
    pub fn load_all(&mut self, files: &[PathBuf], docs: &Documents) {
        for f in files {
            let f = normalize(f);
            if is_unit(&f) {
                if let Some(text) = docs.text(&f) {
                    self.run(&f, &text, docs);
                }
            }
        }
    }

    fn run(&mut self, path: &Path, text: &str, docs: &Documents) {
        let kind = kind_of(path, Some(text), true);
        let (found, mut deps) =
            overlay::with(&docs.open, || project::check_file(path, kind, Some(text)));
        deps.insert(path.to_path_buf());
        self.units.insert(
            path.to_path_buf(),
            Unit {
                diags: found.diags,
                deps,
                species: found.species,
            },
        );
    }

    /// Re-checks after `path` changed (opened, edited, saved or closed): its own check, and
    /// every check that read it. A script that no check reads is checked alone while open.
    pub fn changed(&mut self, path: &Path, docs: &Documents) {
        let mut again: Vec<PathBuf> = self
            .units
            .iter()
            .filter(|(p, u)| p.as_path() != path && u.deps.contains(path))
            .map(|(p, _)| p.clone())
            .collect();
        let own =
            is_unit(path) || (docs.open.contains_key(path) && again.is_empty() && is_script(path));
        if own {
            again.push(path.to_path_buf());
        } else {
            self.units.remove(path);
        }
        for p in again {
            match docs.text(&p) {
                Some(t) => self.run(&p, &t, docs),
                None => {
                    self.units.remove(&p);
                }
            }
        }
    }

    /// The problems of every file, grouped by file (each place once, as `shoal check` does).
    fn by_file(&self) -> BTreeMap<PathBuf, Vec<Diagnostic>> {
        let mut all: BTreeMap<PathBuf, Vec<Diagnostic>> = BTreeMap::new();
        let mut species = Vec::new();
        for u in self.units.values() {
            species.extend(u.species.clone());
            for d in &u.diags {
                project::add_once(all.entry(normalize(&d.file)).or_default(), d.clone(), false);
            }
        }
        for d in project::relations(species) {
            project::add_once(all.entry(normalize(&d.file)).or_default(), d, true);
        }
        all
    }

    /// What to publish now: every file whose problems changed since the last call, and the
    /// file `edited` (its ranges move with its text; an empty list when it is clean), each with
    /// its whole list (empty when its problems went away).
    pub fn publish(
        &mut self,
        docs: &Documents,
        edited: Option<&Path>,
    ) -> Vec<(PathBuf, Vec<lsp_types::Diagnostic>)> {
        let now = self.by_file();
        let mut out = Vec::new();
        for (p, old) in &self.published {
            if !now.contains_key(p) && !old.is_empty() {
                out.push((p.clone(), Vec::new()));
            }
        }
        for (p, ds) in &now {
            if self.published.get(p) != Some(ds) || edited == Some(p.as_path()) {
                let text = docs.text(p);
                let lsp = ds.iter().map(|d| to_lsp(d, text.as_deref())).collect();
                out.push((p.clone(), lsp));
            }
        }
        // The edited file always gets an answer, an empty list when it is clean: an editor then
        // knows its text was checked.
        if let Some(e) = edited {
            if !out.iter().any(|(p, _)| p == e) {
                out.push((e.to_path_buf(), Vec::new()));
            }
        }
        self.published = now;
        out
    }

    /// The species of the cached checks (those that validate), for completion's names.
    pub fn species(&self) -> impl Iterator<Item = &Arc<Species>> {
        self.units.values().filter_map(|u| u.species.as_ref())
    }
}

fn is_script(path: &Path) -> bool {
    path.extension().is_some_and(|x| x == "rhai") && !in_tests_folder(path)
}

/// `d` as the protocol's diagnostic, ranged in `text` (the file's current text) when known.
pub fn to_lsp(d: &Diagnostic, text: Option<&str>) -> lsp_types::Diagnostic {
    let range = match text {
        Some(t) => diag_range(t, d.line, d.col),
        None => Default::default(),
    };
    lsp_types::Diagnostic {
        range,
        severity: Some(DiagnosticSeverity::ERROR),
        code: None::<NumberOrString>,
        source: Some("shoal".into()),
        message: d.message.clone(),
        ..Default::default()
    }
}
