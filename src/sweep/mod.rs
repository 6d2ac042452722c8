//! Parameter sweeps: a sweep file ([`def`]) names a base scenario, the keys to vary (axes of
//! values, ranges or samples) and seeds per point; a [`Plan`] expands it into numbered runs
//! ([`Entry`]), each a scenario loaded with settings ([`crate::scenario::Setting`]).
//! [`run_entry`] runs one entry into its own folder, atomically ([`exec`]); [`collect`] merges
//! the finished folders into one [`Table`] ([`table`]). Above the core: reads files, steps runs
//! through [`crate::scenario::Run`] like `shoal run`. Not behind the `tools` feature, so an
//! embedding program (the Python package) drives sweeps with the engine alone.

pub mod def;
pub mod exec;
mod expand;
pub mod table;

pub use def::SweepDef;
pub use exec::{prepare, run_entry, EntryStatus, SweepError};
pub use table::{collect, collect_partial, Cell, Table};

use crate::load::{locate, locate_key, ron_diag, ron_options, Diagnostic, Diagnostics};
use crate::scenario::{Scenario, Setting};
use std::path::{Path, PathBuf};

/// One run of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Its number, from 0: `point * seeds + replicate`.
    pub index: usize,
    /// The point (combination of axis values) it runs.
    pub point: usize,
    /// Which of the point's seeds it is, from 0.
    pub replicate: u32,
    /// Its seed.
    pub seed: u64,
    /// The settings it runs with, one per axis.
    pub set: Vec<Setting>,
}

impl Entry {
    /// The axis values, as RON text, in axis order.
    pub fn values(&self) -> impl Iterator<Item = &str> {
        self.set.iter().map(|s| s.value.as_str())
    }
}

/// A sweep file expanded into its runs.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The sweep file.
    pub file: PathBuf,
    /// Its definition.
    pub def: SweepDef,
    /// The base scenario file.
    pub scenario: PathBuf,
    /// The axes' keys, in order.
    pub keys: Vec<String>,
    /// The points: one RON value per axis.
    points: Vec<Vec<String>>,
    /// The reduction script's file and text, when the sweep has one.
    pub reduce: Option<(PathBuf, String)>,
    /// Every input with its SHA-256, by name relative to the sweep file's folder: the sweep
    /// file, the scenario, species, scripts and imports, the reduction, the sample file.
    pub inputs: Vec<(String, String)>,
    entries: Vec<Entry>,
}

/// The seed of replicate `r` of a sweep whose base seed is `base` (SplitMix64 of the pair):
/// the same for every point, so points are compared on common random numbers.
pub fn derive_seed(base: u64, r: u32) -> u64 {
    let mut z = base.wrapping_mul(0x9E37_79B9_7F4A_7C15).wrapping_add(
        u64::from(r)
            .wrapping_add(1)
            .wrapping_mul(0xD1B5_4A32_D192_ED03),
    );
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl Plan {
    /// Reads and expands a sweep file; the base scenario is loaded once with the first point's
    /// settings, so an unknown key or a bad value is reported before anything runs.
    pub fn load(file: &Path) -> Result<Plan, Diagnostics> {
        let text = crate::load::read_text(file, "sweep")?;
        let def: SweepDef = ron_options()
            .from_str(&text)
            .map_err(|e| Diagnostics::from(ron_diag(file, &text, &e)))?;
        let dir = file.parent().unwrap_or(Path::new("."));
        let at = |key: &str, from: usize| {
            let (l, c, _) = locate_key(&text, key, from)
                .or_else(|| locate(&text, key, from))
                .unwrap_or((0, 0, 0));
            (l, c)
        };
        let problem = |key: &str, from: usize, msg: String| {
            let (l, c) = at(key, from);
            Diagnostics::from(Diagnostic::new(file, l, c, msg, Some(&text)))
        };
        if def.seeds == 0 {
            return Err(problem(
                "seeds",
                0,
                "`seeds` must be ≥ 1 (runs per point)".into(),
            ));
        }
        if let Some(d) = def.duration {
            if !(d >= 0.0 && d.is_finite()) {
                return Err(problem(
                    "duration",
                    0,
                    "`duration` must be ≥ 0 seconds".into(),
                ));
            }
        }
        let scenario = crate::scenario::normalize(&dir.join(&def.scenario));
        if let Some(p) = crate::load::diag::file_problem(&scenario) {
            return Err(problem(
                "scenario",
                0,
                format!(
                    "scenario \"{}\" {p} (the path is relative to the sweep file's folder)",
                    scenario.display()
                ),
            ));
        }
        let points = expand::points(file, &text, &def)?;
        let keys: Vec<String> = def.axes.iter().map(|a| a.key.clone()).collect();
        let mut key_at = 0;
        for k in &keys {
            let from = locate(&text, &format!("\"{k}\""), key_at).map_or(key_at, |x| x.2);
            if let Err(e) = Setting::parse(&format!("{k}=0")) {
                return Err(problem(
                    &format!("\"{k}\""),
                    key_at,
                    format!("axis key {e}"),
                ));
            }
            key_at = from + 1;
        }
        let mut entries = Vec::new();
        for (p, values) in points.iter().enumerate() {
            for r in 0..def.seeds {
                entries.push(Entry {
                    index: entries.len(),
                    point: p,
                    replicate: r,
                    seed: derive_seed(def.seed, r),
                    set: keys
                        .iter()
                        .zip(values)
                        .map(|(k, v)| Setting {
                            key: k.clone(),
                            value: v.clone(),
                        })
                        .collect(),
                });
            }
        }
        // Keys and values are checked by loading the first point (the others differ only in
        // values: their problems are each run's own, recorded in its folder).
        let base = match entries.first() {
            Some(e) => Scenario::load_with(&scenario, &e.set)?,
            None => Scenario::load(&scenario)?,
        };
        let reduce = match &def.keep.reduce {
            Some(r) => {
                let path = crate::scenario::normalize(&dir.join(r));
                let t = crate::load::read_text(&path, "reduction script")?;
                exec::check_reduce(&path, &t)?;
                Some((path, t))
            }
            None => None,
        };
        let mut inputs = vec![(name_in(dir, file), hash_file(file))];
        for f in base.files() {
            inputs.push((name_in(dir, &f), hash_file(&f)));
        }
        if let Some((p, t)) = &reduce {
            inputs.push((name_in(dir, p), crate::record::sha256_bytes(t.as_bytes())));
        }
        if let def::SamplerDef::File(f) = &def.sampler {
            let p = dir.join(f);
            inputs.push((name_in(dir, &p), hash_file(&p)));
        }
        inputs.sort();
        inputs.dedup();
        Ok(Plan {
            file: file.to_path_buf(),
            def,
            scenario,
            keys,
            points,
            reduce,
            inputs,
            entries,
        })
    }

    /// How many runs.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the sweep has no runs.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Run `i` (panics past [`Plan::len`]).
    pub fn entry(&self, i: usize) -> &Entry {
        &self.entries[i]
    }

    /// Every run, in index order.
    pub fn entries(&self) -> &[Entry] {
        &self.entries
    }

    /// How many points (runs per point: the sweep's `seeds`).
    pub fn points(&self) -> usize {
        self.points.len()
    }

    /// One SHA-256 over every input's name and hash: what an output folder was made from.
    pub fn inputs_hash(&self) -> String {
        let mut s = String::new();
        for (n, h) in &self.inputs {
            s.push_str(&format!("{n}\t{h}\n"));
        }
        crate::record::sha256_bytes(s.as_bytes())
    }
}

fn hash_file(p: &Path) -> String {
    crate::record::sha256_file(p).unwrap_or_default()
}

/// `to` named relative to the folder `dir` (both made absolute first), with `/` separators, so
/// a sweep's inputs are named the same whatever the working folder.
fn name_in(dir: &Path, to: &Path) -> String {
    let abs = |p: &Path| {
        std::fs::canonicalize(p).unwrap_or_else(|_| {
            crate::scenario::normalize(&std::env::current_dir().unwrap_or_default().join(p))
        })
    };
    let (a, b) = (abs(dir), abs(to));
    let a: Vec<_> = a.components().collect();
    let b: Vec<_> = b.components().collect();
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut parts: Vec<String> = vec!["..".to_string(); a.len() - common];
    parts.extend(
        b[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    parts.join("/")
}
