//! The editor's outline (document symbols: behaviors nested as composed, script and test
//! functions, scenario groups) and the project's names offered by completion
//! ([`super::assist::ProjectNames`]), both read from the symbol index.

use super::assist::ProjectNames;
use super::docs::LineIndex;
use super::index::{FileIndex, Index, Sym, SymKind};
use crate::load::overlay::normalize;
use crate::project::{script_root, Kind};
use lsp_types::{DocumentSymbol, SymbolKind};
use std::path::Path;

/// The outline of a file indexed as `f`, with text `text`.
pub fn outline(f: &FileIndex, text: &str) -> Vec<DocumentSymbol> {
    let lines = LineIndex::new(text);
    f.defs.iter().map(|s| symbol(s, &lines)).collect()
}

#[allow(deprecated)] // `deprecated` is a required field of the protocol's type.
fn symbol(s: &Sym, lines: &LineIndex) -> DocumentSymbol {
    let (kind, detail) = match s.kind {
        SymKind::Behavior => (SymbolKind::CLASS, "behavior"),
        SymKind::Function => (SymbolKind::FUNCTION, "function"),
        SymKind::Test => (SymbolKind::METHOD, "test"),
        SymKind::Group => (SymbolKind::NAMESPACE, "group"),
    };
    let full = (s.full.0.min(s.name_span.0), s.full.1.max(s.name_span.1));
    let children: Vec<DocumentSymbol> = s.children.iter().map(|c| symbol(c, lines)).collect();
    DocumentSymbol {
        name: s.name.clone(),
        detail: Some(detail.into()),
        kind,
        tags: None,
        deprecated: None,
        range: lines.range(full),
        selection_range: lines.range(s.name_span),
        children: (!children.is_empty()).then_some(children),
    }
}

/// The names completion offers in `file` (indexed as `f`): the project's species and shared
/// modules, and the behaviors and script functions of the species the file belongs to.
pub fn names(index: &Index, file: &Path, f: Option<&FileIndex>) -> ProjectNames {
    let root = normalize(&script_root(file));
    let mut n = ProjectNames::default();
    let scripts: Vec<_> = index
        .values()
        .filter_map(|x| x.script.as_deref().map(normalize))
        .collect();
    for (p, x) in index {
        match x.kind {
            Kind::Species if p.parent() == Some(root.as_path()) => {
                n.species
                    .extend(p.file_stem().map(|s| s.to_string_lossy().into_owned()));
            }
            Kind::Script if !scripts.contains(p) => {
                if let Ok(rel) = p.with_extension("").strip_prefix(&root) {
                    n.modules.push(rel.to_string_lossy().into_owned());
                }
            }
            _ => {}
        }
    }
    let Some(f) = f else { return n };
    // The species this file belongs to.
    let owners: Vec<&FileIndex> = match f.kind {
        Kind::Species => vec![f],
        Kind::Script => index
            .values()
            .filter(|x| x.script.as_deref().map(normalize).as_deref() == Some(file))
            .collect(),
        Kind::Test => f
            .uses
            .iter()
            .filter(|u| u.what == super::index::UseKind::Species)
            .filter_map(|u| index.get(&root.join(format!("{}.ron", u.name))))
            .collect(),
        _ => Vec::new(),
    };
    for o in &owners {
        n.behaviors
            .extend(o.behaviors().into_iter().map(|(p, _)| p));
        let script = o.script.as_deref().map(normalize);
        if let Some(s) = script.as_ref().and_then(|s| index.get(s)) {
            n.functions.extend(s.defs.iter().map(|d| d.name.clone()));
        }
    }
    if f.kind == Kind::Script {
        n.functions.extend(f.defs.iter().map(|d| d.name.clone()));
    }
    for v in [
        &mut n.species,
        &mut n.behaviors,
        &mut n.functions,
        &mut n.modules,
    ] {
        v.sort();
        v.dedup();
    }
    n
}
