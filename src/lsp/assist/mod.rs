//! What the editor is offered at a cursor: completion items and hover text for species, scenario,
//! script and test files. Pure functions of a document's text and the project's names; the
//! server ([`super::server`]) converts protocol positions to byte offsets before calling them.
//!
//! One file per concept: where a RON cursor stands (`cursor.rs`), the formats' vocabulary
//! (`schema.rs` with `species.table` and `scenario.table`), completion and hover in RON
//! (`ron.rs`), the designers' references and their entries (`reference.rs`), the Rhai APIs
//! (`api.rs`) and completion and hover in Rhai (`rhai.rs`), seed constants (`seeds.rs`), and the
//! JSON Schemas of the formats (`json_schema.rs`, written by `shoal defs`).

pub mod api;
pub mod cursor;
pub mod json_schema;
pub mod reference;
pub mod rhai;
pub mod ron;
pub mod schema;
pub mod seeds;
#[cfg(test)]
mod tests;

use std::path::Path;

/// What a document holds, told by its path and, for RON, its first word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A species file (`behaviors/*.ron`).
    Species,
    /// A scenario file (`Scenario(...)`).
    Scenario,
    /// A behavior script (`*.rhai` outside a `tests` folder).
    Script,
    /// A designers' test script (`*.rhai` in a `tests` folder).
    Test,
    /// Anything else (features, teams, grids).
    Other,
}

impl FileKind {
    /// The kind of `path` holding `text`.
    pub fn of(path: &Path, text: &str) -> FileKind {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("rhai") {
            let in_tests = path
                .parent()
                .and_then(|p| p.file_name())
                .is_some_and(|n| n == "tests");
            return if in_tests {
                FileKind::Test
            } else {
                FileKind::Script
            };
        }
        if !ext.eq_ignore_ascii_case("ron") {
            return FileKind::Other;
        }
        match crate::load::first_word(text) {
            "Scenario" => FileKind::Scenario,
            "Features" | "Team" => FileKind::Other,
            _ => FileKind::Species,
        }
    }
}

/// The names a project defines, offered where a name is expected.
#[derive(Debug, Clone, Default)]
pub struct ProjectNames {
    /// Species names (file stems under `behaviors/`).
    pub species: Vec<String>,
    /// Behavior names (paths like `eat/chase` for composed ones) of the species in question.
    pub behaviors: Vec<String>,
    /// Functions the species' script (and its imports) define.
    pub functions: Vec<String>,
    /// Shared script modules (`behaviors/shared/*.rhai` stems).
    pub modules: Vec<String>,
}

/// What a completion item names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemKind {
    /// A RON field name.
    Key,
    /// A RON enum variant (condition, primitive, drive, category, locomotion model, …).
    Variant,
    /// A script or API function.
    Function,
    /// A behavior name.
    Behavior,
    /// A species name.
    Species,
    /// A shared script module.
    Module,
    /// A constant (a seed default, an enum value).
    Constant,
}

/// One completion item.
#[derive(Debug, Clone, PartialEq)]
pub struct Item {
    /// The text shown and, without `insert`, inserted.
    pub label: String,
    /// What it names.
    pub kind: ItemKind,
    /// One line: a signature, a type or a default.
    pub detail: String,
    /// The reference entry, Markdown.
    pub doc: String,
    /// Text inserted instead of the label (a snippet-free template such as `Chase(Prey)`).
    pub insert: Option<String>,
}

/// Hover text and the byte range of the word it describes.
#[derive(Debug, Clone, PartialEq)]
pub struct Hover {
    /// The reference entry, Markdown.
    pub markdown: String,
    /// Byte offset where the word starts.
    pub start: usize,
    /// Byte offset just past the word.
    pub end: usize,
}

/// Completion items at byte `offset` of `text`, a document of kind `kind`.
pub fn complete(kind: FileKind, text: &str, offset: usize, names: &ProjectNames) -> Vec<Item> {
    match kind {
        FileKind::Species | FileKind::Scenario => ron::complete(kind, text, offset, names),
        FileKind::Script | FileKind::Test => rhai::complete(kind, text, offset, names),
        FileKind::Other => Vec::new(),
    }
}

/// Hover text for the word at byte `offset` of `text`, if shoal documents it.
pub fn hover(kind: FileKind, text: &str, offset: usize) -> Option<Hover> {
    match kind {
        FileKind::Species | FileKind::Scenario => ron::hover(kind, text, offset),
        FileKind::Script | FileKind::Test => rhai::hover(kind, text, offset),
        FileKind::Other => None,
    }
}
