//! The files of one version of a scenario: which files it was built from, their contents and
//! hashes, read so that the contents recorded are the ones that were compiled.

use crate::diag::Diagnostics;
use crate::scenario::{normalize, Scenario};
use sha2::{Digest, Sha256};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// One file of a version.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileEntry {
    /// Absolute path.
    pub path: PathBuf,
    /// Hex SHA-256 of the contents.
    pub sha256: String,
    /// The contents.
    pub bytes: Arc<[u8]>,
}

/// Absolute, lexically normalized form of `p`.
pub fn absolute(p: &Path) -> PathBuf {
    normalize(&std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()))
}

/// The form of `p` a file watcher reports: the canonical folder joined with the file name (the
/// file itself may be missing, e.g. deleted or between a delete and a re-create).
pub fn watch_key(p: &Path) -> PathBuf {
    let abs = absolute(p);
    match (abs.parent(), abs.file_name()) {
        (Some(dir), Some(name)) => std::fs::canonicalize(dir)
            .map(|d| d.join(name))
            .unwrap_or(abs),
        _ => abs,
    }
}

/// Hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    let mut s = String::with_capacity(64);
    for b in digest {
        s.push_str(&format!("{b:02x}"));
    }
    s
}

fn read(paths: &[PathBuf]) -> Vec<Option<FileEntry>> {
    paths
        .iter()
        .map(|p| {
            let bytes = std::fs::read(p).ok()?;
            Some(FileEntry {
                path: p.clone(),
                sha256: sha256_hex(&bytes),
                bytes: bytes.into(),
            })
        })
        .collect()
}

/// A loaded version: the scenario and the files it was built from.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The scenario, validated and compiled.
    pub scenario: Scenario,
    /// Its files (scenario, species, scripts, imports), sorted by path.
    pub files: Vec<FileEntry>,
    /// Species files its species name in relations without loading them (they only need to
    /// exist for the scenario to load; a recording copies them).
    pub library: Vec<PathBuf>,
}

/// The result of loading the scenario file.
#[derive(Debug, Clone)]
pub enum Attempt {
    /// It loaded.
    Loaded(Box<Loaded>),
    /// It did not; `watch` lists the files involved (those named by the diagnostics and those of
    /// the previous attempt), so that fixing any of them is noticed.
    Failed {
        /// What is wrong.
        diagnostics: Diagnostics,
        /// Files to watch.
        watch: Vec<PathBuf>,
    },
}

/// Every file `s` was built from, absolute, sorted and without duplicates.
pub fn files_of(s: &Scenario) -> Vec<PathBuf> {
    let set: BTreeSet<PathBuf> = s.files().iter().map(|p| absolute(p)).collect();
    set.into_iter().collect()
}

fn library_of(s: &Scenario) -> Vec<PathBuf> {
    let mut out = BTreeSet::new();
    for sp in &s.species.species {
        let r = &sp.def.relations;
        for name in r.prey.iter().chain(&r.predators).chain(&r.kin) {
            if s.species.index_of(name).is_none() {
                let p = s.behaviors_dir.join(format!("{name}.ron"));
                if p.is_file() {
                    out.insert(absolute(&p));
                }
            }
        }
    }
    out.into_iter().collect()
}

/// Loads the scenario at `file` and reads the files it was built from. The files are hashed
/// before and after loading; if one changed in between (an editor still saving), the load is
/// repeated, so the contents returned are the ones that were compiled. `known` is the file list
/// of a previous attempt (a hint: the first load discovers the list anyway).
pub fn load(file: &Path, known: &[PathBuf]) -> Attempt {
    let mut known: Vec<PathBuf> = known.to_vec();
    let mut last = None;
    for _ in 0..4 {
        let before = read(&known);
        match Scenario::load(file) {
            Err(diagnostics) => {
                let mut watch: BTreeSet<PathBuf> = known.iter().cloned().collect();
                watch.insert(absolute(file));
                watch.extend(diagnostics.0.iter().map(|d| absolute(&d.file)));
                return Attempt::Failed {
                    diagnostics,
                    watch: watch.into_iter().collect(),
                };
            }
            Ok(scenario) => {
                let paths = files_of(&scenario);
                let after = read(&paths);
                let consistent = paths.iter().zip(&after).all(|(p, a)| {
                    let b = known
                        .iter()
                        .position(|k| k == p)
                        .and_then(|i| before[i].as_ref());
                    matches!((a, b), (Some(a), Some(b)) if a.sha256 == b.sha256)
                });
                let files: Option<Vec<FileEntry>> = after.into_iter().collect();
                let library = library_of(&scenario);
                if let (true, Some(files)) = (consistent, &files) {
                    return Attempt::Loaded(Box::new(Loaded {
                        scenario,
                        files: files.clone(),
                        library,
                    }));
                }
                if let Some(files) = files {
                    last = Some(Loaded {
                        scenario,
                        files,
                        library,
                    });
                }
                known = paths;
            }
        }
    }
    match last {
        Some(l) => Attempt::Loaded(Box::new(l)),
        None => Attempt::Failed {
            diagnostics: crate::diag::Diagnostic::file(
                file,
                "the scenario's files kept changing while they were read",
            )
            .into(),
            watch: known,
        },
    }
}

/// Whether two file lists have the same paths and contents.
pub fn same_contents(a: &[FileEntry], b: &[FileEntry]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.path == y.path && x.sha256 == y.sha256)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_of_abc() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn a_load_lists_every_file_used_and_the_species_named_only_in_relations() {
        let tmp = tempfile::tempdir().unwrap();
        let beh = tmp.path().join("behaviors");
        std::fs::create_dir_all(beh.join("common")).unwrap();
        std::fs::create_dir_all(tmp.path().join("scenarios")).unwrap();
        let fish = r#"Species(name: "fish", script: Some("fish.rhai"), relations: (predators: ["eel"]),
            initial: "wander", behaviors: [Behavior(name: "wander", priority: 1, steer: Wander())])"#;
        std::fs::write(beh.join("fish.ron"), fish).unwrap();
        std::fs::write(beh.join("eel.ron"), fish.replace("\"fish\"", "\"eel\"")).unwrap();
        std::fs::write(
            beh.join("fish.rhai"),
            "import \"common/util\" as util;\nfn f() { util::one() }\n",
        )
        .unwrap();
        std::fs::write(beh.join("common/util.rhai"), "fn one() { 1 }\n").unwrap();
        let scen = tmp.path().join("scenarios/s.ron");
        std::fs::write(&scen, r#"Scenario(duration: 1.0, bounds: (min: (0.0, 0.0, 0.0), max: (9.0, 9.0, 9.0)), species: ["fish"])"#).unwrap();
        let Attempt::Loaded(l) = load(&scen, &[]) else {
            panic!("does not load");
        };
        let names: Vec<String> = l
            .files
            .iter()
            .map(|f| {
                f.path
                    .strip_prefix(tmp.path())
                    .unwrap()
                    .display()
                    .to_string()
            })
            .collect();
        assert_eq!(
            names,
            [
                "behaviors/common/util.rhai",
                "behaviors/fish.rhai",
                "behaviors/fish.ron",
                "scenarios/s.ron"
            ]
        );
        assert_eq!(l.library, vec![absolute(&beh.join("eel.ron"))]);
        let util = &l.files[0];
        assert_eq!(util.sha256, sha256_hex(b"fn one() { 1 }\n"));
        // A broken import: the failure names the script, which is to be watched.
        std::fs::write(beh.join("fish.rhai"), "import \"common/nope\" as util;\n").unwrap();
        let Attempt::Failed { diagnostics, watch } = load(&scen, &[]) else {
            panic!("loads with a missing import");
        };
        assert_eq!(diagnostics.0[0].file, beh.join("fish.rhai"));
        assert_eq!((diagnostics.0[0].line, diagnostics.0[0].col), (1, 1));
        assert!(watch.contains(&absolute(&beh.join("fish.rhai"))));
    }
}
