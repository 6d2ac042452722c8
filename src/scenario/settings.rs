//! Settings: `KEY=VALUE` overrides of any key of a scenario file or of a species file it loads
//! (`scenario.duration=30`, `scenario.groups[sardine].count=50`,
//! `sardine.senses.vision_radius=6`). Each is a text patch of the file's RON
//! ([`crate::load::ron_patch`]); the patched texts are then read in place of the files
//! ([`crate::load::overlay`]) by the ordinary loaders, so every check and located message
//! applies. Reads files only while loading, like the rest of this layer.

use super::Scenario;
use crate::load::overlay::{self, Texts};
use crate::load::ron_patch::{self, parse_path, Patched, Step};
use crate::load::{locate, Diagnostic, Diagnostics};
use std::path::Path;
use std::sync::Arc;

/// One override: a key (`scenario.<path>` or `<species>.<path>`) and a value in RON.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Setting {
    /// The key: which file (`scenario` or a species name), then the path in it.
    pub key: String,
    /// The value, as RON text.
    pub value: String,
}

impl Setting {
    /// Reads `KEY=VALUE` (the first `=` splits; the value may hold more).
    pub fn parse(s: &str) -> Result<Setting, String> {
        let Some((k, v)) = s.split_once('=') else {
            return Err(format!(
                "`{s}`: expected KEY=VALUE (e.g. `scenario.duration=30` or \
                 `sardine.senses.vision_radius=6`)"
            ));
        };
        let (key, value) = (k.trim(), v.trim());
        if value.is_empty() {
            return Err(format!("`{s}`: no value after `=`"));
        }
        let steps = parse_path(key).map_err(|e| format!("`{s}`: {e}"))?;
        if steps.len() < 2 || !matches!(steps[0], Step::Field(_)) {
            return Err(format!(
                "`{s}`: a key names its file, then a key in it: `scenario.<key>` or \
                 `<species>.<key>`"
            ));
        }
        Ok(Setting {
            key: key.to_string(),
            value: value.to_string(),
        })
    }

    /// The file part of the key: `scenario` or a species name.
    pub fn root(&self) -> &str {
        self.key.split(['.', '[']).next().unwrap_or_default()
    }
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}={}", self.key, self.value)
    }
}

/// Where one setting wrote: the patched file (normalized) and its lines there.
struct Written {
    setting: usize,
    file: std::path::PathBuf,
    lines: Patched,
}

/// Applies the settings of `root` in order to `text` (the file `file`).
fn apply(
    text: &str,
    file: &Path,
    set: &[Setting],
    root: &str,
    what: &str,
    written: &mut Vec<Written>,
) -> Result<String, Diagnostics> {
    let mut text = text.to_string();
    for (i, s) in set.iter().enumerate().filter(|(_, s)| s.root() == root) {
        let steps = parse_path(&s.key).map_err(|e| Diagnostic::file(file, e))?;
        match ron_patch::patch(&text, &steps[1..], &s.value, what) {
            Ok((t, lines)) => {
                text = t;
                written.push(Written {
                    setting: i,
                    file: overlay::normalize(file),
                    lines,
                });
            }
            Err(e) => {
                let (l, c) = line_col(&text, e.at);
                return Err(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!("setting `{s}`: {}", e.message),
                    Some(&text),
                )
                .into());
            }
        }
    }
    Ok(text)
}

fn line_col(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let line = text[..at].matches('\n').count() + 1;
    let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    (line, text[start..at].chars().count() + 1)
}

impl Scenario {
    /// Reads a scenario with `set` applied to it and its species files (see the module); with
    /// no settings, [`Scenario::load`]. A problem a setting's value causes is the loader's own
    /// message, prefixed with the setting.
    pub fn load_with(file: &Path, set: &[Setting]) -> Result<Scenario, Diagnostics> {
        if set.is_empty() {
            return Scenario::load(file);
        }
        let text = crate::load::read_text(file, "scenario")?;
        let mut written = Vec::new();
        let stext = apply(&text, file, set, "scenario", "the scenario", &mut written)?;
        // The species and their folder as patched (a setting may change them).
        let def: Result<super::ScenarioDef, _> = crate::load::ron_options().from_str(&stext);
        let mut texts = Texts::new();
        texts.insert(overlay::normalize(file), Arc::from(stext.as_str()));
        if let Ok(def) = &def {
            let dir = file.parent().unwrap_or(Path::new("."));
            let behaviors = dir.join(def.behaviors.as_deref().unwrap_or("../behaviors"));
            let mut roots: Vec<&str> = set.iter().map(Setting::root).collect();
            roots.dedup();
            let mut seen = std::collections::BTreeSet::new();
            for root in roots {
                if root == "scenario" || !seen.insert(root) {
                    continue;
                }
                if !def.species.iter().any(|s| s == root) {
                    let (l, c, _) = locate(&stext, "species", 0).unwrap_or((0, 0, 0));
                    let first = set
                        .iter()
                        .find(|s| s.root() == root)
                        .expect("a root's setting");
                    let known =
                        std::iter::once("scenario").chain(def.species.iter().map(String::as_str));
                    return Err(Diagnostic::new(
                        file,
                        l,
                        c,
                        format!(
                            "setting `{first}`: `{root}` is neither `scenario` nor a species the \
                             scenario loads{}; a key starts with `scenario` or one of {}",
                            crate::load::did_you_mean(root, known),
                            def.species.join(", ")
                        ),
                        Some(&stext),
                    )
                    .into());
                }
                let path = behaviors.join(format!("{root}.ron"));
                let t = crate::load::read_text(&path, "species")?;
                let what = format!("the species file of `{root}`");
                let t = apply(&t, &path, set, root, &what, &mut written)?;
                texts.insert(overlay::normalize(&path), Arc::from(t.as_str()));
            }
        }
        let (loaded, _) = overlay::with(&texts, || Scenario::load_str(file, &stext));
        match loaded {
            Ok(mut s) => {
                s.settings = set.to_vec();
                s.patched = texts;
                Ok(s)
            }
            Err(mut d) => {
                for diag in &mut d.0 {
                    let here = overlay::normalize(&diag.file);
                    let by: Vec<String> = written
                        .iter()
                        .filter(|w| {
                            w.file == here
                                && (w.lines.first_line..=w.lines.last_line).contains(&diag.line)
                        })
                        .map(|w| format!("setting `{}`", set[w.setting]))
                        .collect();
                    let of_file: Vec<String> = written
                        .iter()
                        .filter(|w| w.file == here)
                        .map(|w| format!("`{}`", set[w.setting]))
                        .collect();
                    if !by.is_empty() {
                        diag.message = format!("{}: {}", by.join(", "), diag.message);
                    } else if !of_file.is_empty() {
                        diag.message = format!(
                            "with setting(s) {} applied to this file: {}",
                            of_file.join(", "),
                            diag.message
                        );
                    }
                }
                Err(d)
            }
        }
    }
}
