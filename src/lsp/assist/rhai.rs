//! Completion and hover in Rhai files: after `this.` the agent's API, after `this.kin.` (any
//! category) a `Percepts` value's, after another value's `.` the members of the types it may be
//! (vectors; in tests worlds and agents); elsewhere the global API functions and the file's own
//! functions; in a test's string argument of a call that names a behavior or a species, those
//! names.

use super::api::{self, Api, ApiFn};
use super::cursor::{floor_char, is_ident, word_at};
use super::{FileKind, Hover, Item, ItemKind, ProjectNames};
use crate::perception::Category;

/// Calls whose string argument names a behavior.
const BEHAVIOR_CALLS: [&str; 5] = [
    "assert_behavior",
    "assert_behavior_within",
    "assert_transition",
    "assert_stack",
    "force_behavior",
];
/// Calls whose string argument names a species.
const SPECIES_CALLS: [&str; 3] = ["add_agent", "add_squad", "count"];

/// The expression before the `.` that ends at `dot` (`this`, `this.kin`, `w`), if any.
fn receiver(text: &str, dot: usize) -> &str {
    let b = text.as_bytes();
    let mut s = dot;
    while s > 0 && (is_ident(b[s - 1]) || b[s - 1] == b'.') {
        s -= 1;
    }
    &text[s..dot]
}

/// The APIs and receiver types whose members follow `recv.`.
fn member_sources(kind: FileKind, recv: &str) -> Vec<(Api, &'static str)> {
    if recv == "this" {
        return vec![(Api::Script, "Agent")];
    }
    if let Some(cat) = recv.strip_prefix("this.") {
        if Category::ALL.iter().any(|c| c.name() == cat) {
            return vec![(Api::Script, "Percepts")];
        }
    }
    let mut out = vec![(Api::Script, "Vec3"), (Api::Script, "Percepts")];
    if kind == FileKind::Test {
        out.splice(0..0, [(Api::Test, "World"), (Api::Test, "Agent")]);
    }
    out
}

fn api_item(f: &ApiFn) -> Item {
    let insert = if f.property {
        None
    } else if f.params.is_empty() {
        Some(format!("{}()", f.name))
    } else {
        Some(format!("{}(", f.name))
    };
    Item {
        label: f.name.clone(),
        kind: if f.property {
            ItemKind::Key
        } else {
            ItemKind::Function
        },
        detail: f.signature(),
        doc: f.doc.clone().unwrap_or_default(),
        insert,
    }
}

/// Items of `fns`, one per name (overloads' signatures joined).
fn items<'a>(fns: impl Iterator<Item = (Api, &'a ApiFn)>) -> Vec<Item> {
    let mut out: Vec<Item> = Vec::new();
    for (_, f) in fns {
        match out.iter_mut().find(|i| i.label == f.name) {
            Some(i) if !i.detail.contains(&f.signature()) => {
                i.detail = format!("{}\n{}", i.detail, f.signature());
            }
            Some(_) => {}
            None => out.push(api_item(f)),
        }
    }
    out
}

/// Functions the file defines: name and the text of its `fn` line.
pub fn own_functions(text: &str) -> Vec<(&str, &str)> {
    text.lines()
        .filter_map(|l| {
            let t = l.trim_start();
            let t = t.strip_prefix("private ").unwrap_or(t);
            let rest = t.strip_prefix("fn ")?;
            let name = rest.split('(').next()?.trim();
            is_ident(name.as_bytes().first().copied().unwrap_or(b' '))
                .then_some((name, l.trim().trim_end_matches('{').trim_end()))
        })
        .collect()
}

/// The name of the call whose string argument the cursor is in, if it is in one.
fn string_call(text: &str, offset: usize) -> Option<&str> {
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line = &text[line_start..offset];
    if line.matches('"').count().is_multiple_of(2) {
        return None;
    }
    let quote = line.rfind('"')?;
    let before = line[..quote].trim_end().trim_end_matches(',');
    let open = before.rfind('(')?;
    let b = before.as_bytes();
    let mut s = open;
    while s > 0 && is_ident(b[s - 1]) {
        s -= 1;
    }
    Some(&before[s..open])
}

/// Completion items at `offset` of a script or test file.
pub fn complete(kind: FileKind, text: &str, offset: usize, names: &ProjectNames) -> Vec<Item> {
    let offset = floor_char(text, offset.min(text.len()));
    let b = text.as_bytes();
    let mut start = offset;
    while start > 0 && is_ident(b[start - 1]) {
        start -= 1;
    }
    if let Some(call) = string_call(text, offset) {
        let (list, kind) = if BEHAVIOR_CALLS.contains(&call) {
            (&names.behaviors, ItemKind::Behavior)
        } else if SPECIES_CALLS.contains(&call) {
            (&names.species, ItemKind::Species)
        } else {
            return Vec::new();
        };
        return list
            .iter()
            .map(|n| Item {
                label: n.clone(),
                kind,
                detail: String::new(),
                doc: String::new(),
                insert: None,
            })
            .collect();
    }
    if start > 0 && b[start - 1] == b'.' {
        let recv = receiver(text, start - 1);
        let sources = member_sources(kind, recv);
        return items(
            sources
                .iter()
                .flat_map(|(a, r)| api::members(*a, r).map(move |f| (*a, f))),
        );
    }
    let mut apis = vec![Api::Script];
    if kind == FileKind::Test {
        apis.push(Api::Test);
    }
    let mut out = items(apis.iter().flat_map(|a| {
        api::functions(*a)
            .iter()
            .filter(|f| f.receiver.is_empty())
            .map(move |f| (*a, f))
    }));
    let own = own_functions(text);
    for (name, line) in &own {
        out.push(Item {
            label: name.to_string(),
            kind: ItemKind::Function,
            detail: line.to_string(),
            doc: String::new(),
            insert: Some(format!("{name}(")),
        });
    }
    for n in &names.functions {
        if !own.iter().any(|(o, _)| o == n) {
            out.push(Item {
                label: n.clone(),
                kind: ItemKind::Function,
                detail: "script function".into(),
                doc: String::new(),
                insert: Some(format!("{n}(")),
            });
        }
    }
    out
}

/// Hover for the word at `offset`: an API function's signature and reference entry, or the
/// `fn` line (and comments above it) of the file's own function.
pub fn hover(kind: FileKind, text: &str, offset: usize) -> Option<Hover> {
    let (word, start, end) = word_at(text, offset)?;
    let b = text.as_bytes();
    let found: Vec<(Api, &ApiFn)> = if start > 0 && b[start - 1] == b'.' {
        let recv = receiver(text, start - 1);
        member_sources(kind, recv)
            .into_iter()
            .flat_map(|(a, r)| api::members(a, r).map(move |f| (a, f)))
            .filter(|(_, f)| f.name == word)
            .collect()
    } else {
        let mut apis = vec![Api::Script];
        if kind == FileKind::Test {
            apis.push(Api::Test);
        }
        apis.into_iter()
            .flat_map(|a| api::functions(a).iter().map(move |f| (a, f)))
            .filter(|(_, f)| f.name == word && f.receiver.is_empty())
            .collect()
    };
    let markdown = if let Some((_, first)) = found.first() {
        let sigs: Vec<String> = found.iter().map(|(_, f)| f.signature()).collect();
        let mut md = format!("```rhai\n{}\n```", sigs.join("\n"));
        if let Some(doc) = &first.doc {
            md.push_str("\n\n");
            md.push_str(doc);
        }
        md
    } else {
        let (_, line) = own_functions(text).into_iter().find(|(n, _)| *n == word)?;
        let at = text.find(line).unwrap_or(0);
        let comments: Vec<&str> = text[..at]
            .lines()
            .rev()
            .skip(usize::from(!text[..at].ends_with('\n')))
            .take_while(|l| l.trim_start().starts_with("//"))
            .collect();
        let comments: Vec<&str> = comments
            .into_iter()
            .rev()
            .map(|l| l.trim_start().trim_start_matches('/').trim())
            .collect();
        format!("```rhai\n{line}\n```\n\n{}", comments.join("\n"))
            .trim_end()
            .to_string()
    };
    Some(Hover {
        markdown,
        start,
        end,
    })
}
