//! Go to definition and find references: what the name under the cursor is (a behavior of which
//! species, a function of which script, a module, a species file), where it is defined, and
//! every place the project writes it. Reads the symbol index only.

use super::index::{FileIndex, Index, Span, SymKind, UseKind};
use crate::load::overlay::normalize;
use crate::project::{script_root, Kind};
use std::path::{Path, PathBuf};

/// What a name under the cursor refers to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// A behavior (`path` such as `hunt/strike` for a composed one's part) of a species file.
    Behavior {
        /// The species file.
        species: PathBuf,
        /// The behavior's path.
        path: String,
    },
    /// A function of a script.
    Function {
        /// The script.
        script: PathBuf,
        /// The function's name.
        name: String,
    },
    /// A whole file (a module, a species, a species' script).
    File(PathBuf),
}

/// The span of segment `k` (0-based) of a `/`-separated literal at `span` with text `value`.
fn segment(value: &str, span: Span, k: usize) -> Option<Span> {
    let mut at = span.0;
    for (i, seg) in value.split('/').enumerate() {
        if i == k {
            return Some((at, at + seg.len()));
        }
        at += seg.len() + 1;
    }
    None
}

/// The species files a file's behavior names belong to: a species file's own; the species
/// whose script a script is; the species a test file adds.
fn owners(index: &Index, file: &Path, f: &FileIndex) -> Vec<PathBuf> {
    match f.kind {
        Kind::Species => vec![file.to_path_buf()],
        Kind::Script => index
            .iter()
            .filter(|(_, x)| x.script.as_deref().map(normalize).as_deref() == Some(file))
            .map(|(p, _)| p.clone())
            .collect(),
        Kind::Test => {
            let root = normalize(&crate::testing::world::behaviors_root(file));
            f.uses
                .iter()
                .filter(|u| u.what == UseKind::Species)
                .map(|u| root.join(format!("{}.ron", u.name)))
                .collect()
        }
        _ => Vec::new(),
    }
}

/// The behavior a literal names in a file owned by `owners`, with the span of its segment under
/// `at`: its path is the literal up to that segment (`"hunt/strike"` on `hunt` is `hunt`); a
/// short name in a species file is the first behavior of that name.
fn behavior_at(
    index: &Index,
    owners: &[PathBuf],
    value: &str,
    span: Span,
    at: usize,
) -> Option<(Target, Span)> {
    let segs: Vec<&str> = value.split('/').collect();
    let k = (0..segs.len()).find(|&k| segment(value, span, k).is_some_and(|s| at <= s.1))?;
    let path = segs[..=k].join("/");
    for o in owners {
        let Some(f) = index.get(o) else { continue };
        let behaviors = f.behaviors();
        let hit = behaviors.iter().find(|(p, _)| *p == path).or_else(|| {
            behaviors
                .iter()
                .find(|(_, s)| segs.len() == 1 && s.name == value)
        });
        if let Some((p, _)) = hit {
            let target = Target::Behavior {
                species: o.clone(),
                path: p.clone(),
            };
            return Some((target, segment(value, span, k)?));
        }
    }
    None
}

/// The behaviors folder a scenario names (`behaviors: Some("..")`, else `../behaviors`).
fn scenario_behaviors(file: &Path, text: &str) -> PathBuf {
    let dir = file.parent().unwrap_or(Path::new("/"));
    let rel = text
        .find("behaviors:")
        .and_then(|i| text[i..].find("Some(\"").map(|j| i + j + 6))
        .and_then(|s| text[s..].find('"').map(|e| &text[s..s + e]))
        .unwrap_or("../behaviors");
    normalize(&dir.join(rel))
}

/// What the name at byte `at` of `file` (text `text`) refers to, and the span of that name.
pub fn target_at(index: &Index, file: &Path, text: &str, at: usize) -> Option<(Target, Span)> {
    let f = index.get(file)?;
    let inside = |s: Span| s.0 <= at && at <= s.1;
    for (path, s) in f.behaviors() {
        if inside(s.name_span) {
            let target = Target::Behavior {
                species: file.to_path_buf(),
                path,
            };
            return Some((target, s.name_span));
        }
    }
    for s in &f.defs {
        if s.kind == SymKind::Function && inside(s.name_span) {
            let target = Target::Function {
                script: file.to_path_buf(),
                name: s.name.clone(),
            };
            return Some((target, s.name_span));
        }
    }
    let u = f.uses.iter().find(|u| inside(u.span))?;
    let dir = file.parent().unwrap_or(Path::new("/"));
    match u.what {
        UseKind::Behavior => behavior_at(index, &owners(index, file, f), &u.name, u.span, at),
        UseKind::Function if f.kind == Kind::Species => {
            let script = normalize(f.script.as_deref()?);
            Some((
                Target::Function {
                    script,
                    name: u.name.clone(),
                },
                u.span,
            ))
        }
        UseKind::Function if u.name.contains("::") => {
            // `alias::f`: the module its `import "m" as alias` names, then `f` in it.
            let (alias, name) = u.name.split_once("::")?;
            let module = import_of(text, alias)?;
            let rel = format!("{module}.rhai");
            let script = [script_root(file).join(&rel), dir.join(&rel)]
                .into_iter()
                .map(|p| normalize(&p))
                .find(|p| index.contains_key(p))?;
            index.get(&script)?.function(name)?;
            let target = Target::Function {
                script,
                name: name.to_string(),
            };
            Some((target, u.span))
        }
        UseKind::Function => {
            f.function(&u.name)?;
            let target = Target::Function {
                script: file.to_path_buf(),
                name: u.name.clone(),
            };
            Some((target, u.span))
        }
        UseKind::Module => {
            let rel = format!("{}.rhai", u.name);
            let found = [script_root(file).join(&rel), dir.join(&rel)]
                .into_iter()
                .map(|p| normalize(&p))
                .find(|p| index.contains_key(p) || p.is_file())?;
            Some((Target::File(found), u.span))
        }
        UseKind::Species => {
            let root = if f.kind == Kind::Scenario {
                scenario_behaviors(file, text)
            } else {
                normalize(&crate::testing::world::behaviors_root(file))
            };
            let p = root.join(format!("{}.ron", u.name));
            (index.contains_key(&p) || p.is_file()).then_some((Target::File(p), u.span))
        }
        UseKind::ScriptFile => Some((Target::File(normalize(&dir.join(&u.name))), u.span)),
    }
}

/// Where `target` is defined: a file and the span of the name (a whole file: its start).
pub fn definition(index: &Index, target: &Target) -> Option<(PathBuf, Span)> {
    match target {
        Target::Behavior { species, path } => {
            let f = index.get(species)?;
            let (_, s) = f.behaviors().into_iter().find(|(p, _)| p == path)?;
            Some((species.clone(), s.name_span))
        }
        Target::Function { script, name } => {
            let s = index.get(script)?.function(name)?;
            Some((script.clone(), s.name_span))
        }
        Target::File(p) => Some((p.clone(), (0, 0))),
    }
}

/// Every place `target` is written (its definition first when `with_def`), by file.
pub fn references(index: &Index, target: &Target, with_def: bool) -> Vec<(PathBuf, Span)> {
    let mut out = Vec::new();
    if with_def {
        out.extend(definition(index, target));
    }
    match target {
        Target::Behavior { species, path } => {
            let depth = path.split('/').count();
            let leaf = path.rsplit('/').next().unwrap_or(path);
            for (file, f) in index {
                if !owners(index, file, f).contains(species) {
                    continue;
                }
                for u in f.uses.iter().filter(|u| u.what == UseKind::Behavior) {
                    let segs: Vec<&str> = u.name.split('/').collect();
                    let prefix = segs.len() >= depth && segs[..depth].join("/") == *path;
                    // A species file names siblings by their own name (`on_success: "b"`).
                    let short = f.kind == Kind::Species && depth > 1 && u.name == leaf;
                    if prefix {
                        out.extend(segment(&u.name, u.span, depth - 1).map(|s| (file.clone(), s)));
                    } else if short {
                        out.push((file.clone(), u.span));
                    }
                }
            }
        }
        Target::Function { script, name } => {
            for (file, f) in index {
                let slot_of = f.kind == Kind::Species
                    && f.script.as_deref().map(normalize).as_deref() == Some(script.as_path());
                if file != script && !slot_of {
                    continue;
                }
                for u in &f.uses {
                    if u.what == UseKind::Function && u.name == *name {
                        out.push((file.clone(), u.span));
                    }
                }
            }
        }
        Target::File(_) => {
            for (file, f) in index {
                for u in &f.uses {
                    if matches!(
                        u.what,
                        UseKind::Species | UseKind::Module | UseKind::ScriptFile
                    ) && target_at(index, file, "", u.span.0).is_some_and(|t| t.0 == *target)
                    {
                        out.push((file.clone(), u.span));
                    }
                }
            }
        }
    }
    out.sort();
    out.dedup();
    out
}

/// The module path of `import "path" as alias;` in a script's text.
fn import_of<'a>(text: &'a str, alias: &str) -> Option<&'a str> {
    text.lines().find_map(|l| {
        let rest = l.trim_start().strip_prefix("import")?.trim_start();
        let rest = rest.strip_prefix('"')?;
        let (path, after) = rest.split_once('"')?;
        let after = after.trim_start().strip_prefix("as")?.trim_start();
        let name = after.trim_end_matches(|c: char| c == ';' || c.is_whitespace());
        (name == alias).then_some(path)
    })
}
