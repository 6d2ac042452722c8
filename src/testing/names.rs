//! The names a test file writes as string literals, checked when it is compiled, before any test
//! runs: species given to `add_agent` / `add_squad` must have a species file in the behaviors
//! folder, and behavior names (compared with `.behavior`, given to `assert_behavior`,
//! `assert_stack`, `force_behavior`, or to `add_agent`'s `behavior` and `stack`) must be
//! behaviors of a species the file uses. Each miss is located, with a did-you-mean. The AST walk
//! is [`crate::script::names::test_names`].

use super::world::Library;
use crate::diag::Diagnostic;
use crate::load::did_you_mean;
use crate::script::names::{is_behavior, test_names, unknown_behavior};
use rhai::AST;
use std::path::Path;

/// What is wrong with the literal names of the test file `path` (text `text`, compiled `ast`).
pub(super) fn check(ast: &AST, library: &Library, path: &Path, text: &str) -> Vec<Diagnostic> {
    let found = test_names(ast);
    let mut out = Vec::new();
    let mut used: Vec<String> = Vec::new();
    for s in &found.species {
        if library.exists(&s.name) {
            if !used.contains(&s.name) {
                used.push(s.name.clone());
            }
            continue;
        }
        let names = library.names();
        out.push(Diagnostic::new(
            path,
            s.line,
            s.col,
            format!(
                "unknown species \"{}\"{}: {} has {}",
                s.name,
                did_you_mean(&s.name, names.iter().map(String::as_str)),
                library.root.display(),
                if names.is_empty() {
                    "no species files".to_string()
                } else {
                    names.join(", ")
                }
            ),
            Some(text),
        ));
    }
    // Species that do not load are reported by the tests that use them.
    let species: Vec<_> = used.iter().filter_map(|n| library.get(n).ok()).collect();
    if species.is_empty() {
        return out;
    }
    // Each name once: several species share names such as "avoid_static".
    let mut known: Vec<&str> = Vec::new();
    for name in species
        .iter()
        .flat_map(|s| s.behaviors.iter().map(|b| &*b.name))
    {
        if !known.contains(&name) {
            known.push(name);
        }
    }
    let owner = if species.len() == 1 {
        format!("species \"{}\"", species[0].name)
    } else {
        format!("the species this file uses ({})", used.join(", "))
    };
    for b in &found.behaviors {
        if !is_behavior(&b.name, &known) {
            out.push(Diagnostic::new(
                path,
                b.line,
                b.col,
                unknown_behavior(&b.name, &owner, &known),
                Some(text),
            ));
        }
    }
    out
}
