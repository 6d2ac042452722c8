//! Tests of completion and hover: on small documents (broken ones too) and on the shipped
//! project (`complete`, `hover`, `speed`); the format table checked against the real serde types
//! and the API documentation complete (`table`); the JSON Schemas checked against the shipped
//! files (`schema`). This file holds what they share.

mod complete;
mod hover;
mod schema;
mod speed;
mod table;

use super::*;
use std::path::Path;

/// `text` with `|` marking the cursor: the text without it and the offset.
pub(super) fn at(marked: &str) -> (String, usize) {
    let i = marked.find('|').expect("a cursor mark");
    (marked.replacen('|', "", 1), i)
}

pub(super) fn labels(items: &[Item]) -> Vec<&str> {
    items.iter().map(|i| i.label.as_str()).collect()
}

pub(super) fn complete_at(kind: FileKind, marked: &str) -> Vec<Item> {
    let (text, i) = at(marked);
    complete(kind, &text, i, &names())
}

pub(super) fn hover_at(kind: FileKind, marked: &str) -> Option<Hover> {
    let (text, i) = at(marked);
    hover(kind, &text, i)
}

pub(super) fn names() -> ProjectNames {
    ProjectNames {
        species: vec!["sardine".into(), "shark".into()],
        behaviors: vec!["wander".into(), "escape".into()],
        functions: vec!["tired".into()],
        modules: vec![],
    }
}

pub(super) const SPECIES_HEAD: &str =
    "Species(\n    name: \"x\",\n    initial: \"wander\",\n    behaviors: [\n";

/// A script with a cursor mark inside `station`.
pub(super) const SCRIPT: &str = "// How tired the fish is.\nfn tired() {\n    this.fatigue > 0.8\n}\n\nfn station() {\n    |\n}\n";

/// The shipped `.ron` files of `dir`, with their texts, in path order.
pub(super) fn shipped(dir: &str) -> Vec<(std::path::PathBuf, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut out: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|p| {
            let t = std::fs::read_to_string(&p).unwrap();
            (p, t)
        })
        .collect();
    out.sort();
    out
}
