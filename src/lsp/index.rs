//! The symbol index of a project: per file, what it defines (behaviors with their nesting,
//! script and test functions, scenario groups) and the names it uses (behavior names, script
//! functions named in species slots and called in scripts, imports, species), each with its byte
//! range. Built from the text by the forgiving scanner ([`super::lex`]), except behavior names
//! in scripts and tests, which come from the compiled AST (the checks' own walk), so a string
//! that only looks like a behavior name is never renamed. Navigation and rename read it.

use super::lex::{is_punct, text_of, tokens, Tok};
use crate::project::{kind_of, Kind};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A byte range in a document.
pub type Span = (usize, usize);

/// What a symbol is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SymKind {
    /// A behavior of a species (composed ones hold their parts as children).
    Behavior,
    /// A function of a script.
    Function,
    /// A `test_*` function of a test file.
    Test,
    /// A named group of a scenario.
    Group,
}

/// A definition: its name, where the name is written and the item's whole extent.
#[derive(Debug, Clone, PartialEq)]
pub struct Sym {
    /// The name as written.
    pub name: String,
    /// What it is.
    pub kind: SymKind,
    /// The name's bytes.
    pub name_span: Span,
    /// The whole item's bytes.
    pub full: Span,
    /// Parts of a composed behavior.
    pub children: Vec<Sym>,
}

/// A name used somewhere, with where it is written.
#[derive(Debug, Clone, PartialEq)]
pub struct Use {
    /// The literal or identifier as written (a behavior path such as `hunt/strike` whole).
    pub name: String,
    /// Its bytes (for a string, its content without the quotes).
    pub span: Span,
    /// What it names.
    pub what: UseKind,
}

/// What a used name refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UseKind {
    /// A behavior (RON string, `this.behavior` comparison, test assertion).
    Behavior,
    /// A script function: a species slot (`Script("f")`, `Call("f")`) or a call in a script.
    Function,
    /// A shared module (`import "x"`).
    Module,
    /// A species (a scenario's list, a test's `add_agent`).
    Species,
    /// The species' script file (`script: Some("x.rhai")`).
    ScriptFile,
}

/// What the index knows of one file.
#[derive(Debug, Clone)]
pub struct FileIndex {
    /// Its kind.
    pub kind: Kind,
    /// Its definitions, in text order (behaviors nested).
    pub defs: Vec<Sym>,
    /// The names it uses.
    pub uses: Vec<Use>,
    /// A species file's script (resolved against its folder).
    pub script: Option<PathBuf>,
}

impl FileIndex {
    /// The behaviors, flattened with their paths (`hunt/strike`).
    pub fn behaviors(&self) -> Vec<(String, &Sym)> {
        fn walk<'a>(prefix: &str, syms: &'a [Sym], out: &mut Vec<(String, &'a Sym)>) {
            for s in syms.iter().filter(|s| s.kind == SymKind::Behavior) {
                let path = if prefix.is_empty() {
                    s.name.clone()
                } else {
                    format!("{prefix}/{}", s.name)
                };
                walk(&path, &s.children, out);
                out.push((path, s));
            }
        }
        let mut out = Vec::new();
        walk("", &self.defs, &mut out);
        out
    }

    /// The function named `name`, if the file defines one.
    pub fn function(&self, name: &str) -> Option<&Sym> {
        self.defs
            .iter()
            .find(|s| matches!(s.kind, SymKind::Function | SymKind::Test) && s.name == name)
    }
}

/// Indexes `text`, the file `path`. `engine` compiles scripts and tests for their behavior names.
pub fn index(path: &Path, text: &str, engine: &rhai::Engine) -> FileIndex {
    let kind = kind_of(path, Some(text), true);
    let toks = tokens(text);
    let mut f = FileIndex {
        kind,
        defs: Vec::new(),
        uses: Vec::new(),
        script: None,
    };
    match kind {
        Kind::Species => species(path, text, &toks, &mut f),
        Kind::Scenario => scenario(text, &toks, &mut f),
        Kind::Script | Kind::Test => rhai_file(text, &toks, engine, &mut f),
        _ => {}
    }
    f
}

/// The string token right after `i` inside `(`: `Name("x")`.
fn call_arg(toks: &[Tok], i: usize) -> Option<(usize, usize)> {
    if !is_punct(toks.get(i + 1), '(') {
        return None;
    }
    match toks.get(i + 2) {
        Some(Tok::Str(s, e)) => Some((*s, *e)),
        _ => None,
    }
}

fn species(path: &Path, text: &str, toks: &[Tok], f: &mut FileIndex) {
    // Open `Behavior(` items: the depth inside their parenthesis and what is known so far.
    let mut open: Vec<(usize, Sym)> = Vec::new();
    let mut roots: Vec<Sym> = Vec::new();
    let mut depth = 0usize;
    for (i, t) in toks.iter().enumerate() {
        match t {
            Tok::Punct('(' | '[' | '{', _) => depth += 1,
            Tok::Punct(')' | ']' | '}', at) => {
                if open.last().is_some_and(|o| o.0 == depth) {
                    let (_, mut s) = open.pop().unwrap_or((0, placeholder()));
                    s.full.1 = at + 1;
                    match open.last_mut() {
                        Some(p) => p.1.children.push(s),
                        None => roots.push(s),
                    }
                }
                depth = depth.saturating_sub(1);
            }
            Tok::Ident(s, _) => match text_of(text, t) {
                "Behavior" if is_punct(toks.get(i + 1), '(') => {
                    let mut sym = placeholder();
                    sym.full = (*s, *s);
                    open.push((depth + 1, sym));
                }
                "name" if is_punct(toks.get(i + 1), ':') => {
                    if let (Some(o), Some(Tok::Str(a, b))) = (open.last_mut(), toks.get(i + 2)) {
                        if o.0 == depth && o.1.name.is_empty() {
                            o.1.name = text[*a..*b].to_string();
                            o.1.name_span = (*a, *b);
                        }
                    }
                }
                "Script" | "Call" => {
                    if let Some((a, b)) = call_arg(toks, i) {
                        f.uses.push(Use {
                            name: text[a..b].to_string(),
                            span: (a, b),
                            what: UseKind::Function,
                        });
                    }
                }
                "script" if is_punct(toks.get(i + 1), ':') => {
                    let arg = match toks.get(i + 2) {
                        Some(Tok::Ident(..)) => call_arg(toks, i + 2),
                        Some(Tok::Str(a, b)) => Some((*a, *b)),
                        _ => None,
                    };
                    if let Some((a, b)) = arg {
                        let rel = &text[a..b];
                        f.script = Some(path.parent().unwrap_or(Path::new(".")).join(rel));
                        f.uses.push(Use {
                            name: rel.to_string(),
                            span: (a, b),
                            what: UseKind::ScriptFile,
                        });
                    }
                }
                _ => {}
            },
            Tok::Str(..) | Tok::Punct(..) => {}
        }
    }
    // Items left open by a half-typed file still count.
    while let Some((_, s)) = open.pop() {
        match open.last_mut() {
            Some(p) => p.1.children.push(s),
            None => roots.push(s),
        }
    }
    roots.retain(|s| !s.name.is_empty());
    f.defs = roots;
    // Behavior names in strings: every literal naming one (not a slot or the script path).
    let names: Vec<String> = f.behaviors().into_iter().map(|(p, _)| p).collect();
    let leaves: Vec<String> = f.behaviors().iter().map(|(_, s)| s.name.clone()).collect();
    let taken: Vec<Span> = f.uses.iter().map(|u| u.span).collect();
    let defs: Vec<Span> = f.behaviors().iter().map(|(_, s)| s.name_span).collect();
    for t in toks {
        if let Tok::Str(a, b) = *t {
            let v = &text[a..b];
            if (names.iter().any(|n| n == v) || leaves.iter().any(|n| n == v))
                && !taken.contains(&(a, b))
                && !defs.contains(&(a, b))
            {
                f.uses.push(Use {
                    name: v.to_string(),
                    span: (a, b),
                    what: UseKind::Behavior,
                });
            }
        }
    }
}

fn placeholder() -> Sym {
    Sym {
        name: String::new(),
        kind: SymKind::Behavior,
        name_span: (0, 0),
        full: (0, 0),
        children: Vec::new(),
    }
}

fn scenario(text: &str, toks: &[Tok], f: &mut FileIndex) {
    let mut depth = 0usize;
    // The `species: [...]` list and named groups (`name: "x"` inside it or `groups`).
    let mut in_species: Option<usize> = None;
    for (i, t) in toks.iter().enumerate() {
        match t {
            Tok::Punct('(' | '[' | '{', _) => depth += 1,
            Tok::Punct(')' | ']' | '}', _) => {
                if in_species == Some(depth) {
                    in_species = None;
                }
                depth = depth.saturating_sub(1);
            }
            Tok::Ident(..) => match text_of(text, t) {
                "species" if is_punct(toks.get(i + 1), ':') => match toks.get(i + 2) {
                    Some(Tok::Punct('[', _)) => in_species = Some(depth + 1),
                    Some(Tok::Str(a, b)) => f.uses.push(Use {
                        name: text[*a..*b].to_string(),
                        span: (*a, *b),
                        what: UseKind::Species,
                    }),
                    _ => {}
                },
                "name" if is_punct(toks.get(i + 1), ':') => {
                    if let Some(Tok::Str(a, b)) = toks.get(i + 2) {
                        f.defs.push(Sym {
                            name: text[*a..*b].to_string(),
                            kind: SymKind::Group,
                            name_span: (*a, *b),
                            full: (*a, *b),
                            children: Vec::new(),
                        });
                    }
                }
                _ => {}
            },
            Tok::Str(a, b) if in_species == Some(depth) => f.uses.push(Use {
                name: text[*a..*b].to_string(),
                span: (*a, *b),
                what: UseKind::Species,
            }),
            _ => {}
        }
    }
}

/// Words followed by `(` that are not calls.
const KEYWORDS: &[&str] = &[
    "if", "while", "for", "switch", "return", "loop", "in", "throw",
];

fn rhai_file(text: &str, toks: &[Tok], engine: &rhai::Engine, f: &mut FileIndex) {
    let test = f.kind == Kind::Test;
    let mut depth = 0usize;
    let mut open_fn: Option<(usize, Sym)> = None;
    for (i, t) in toks.iter().enumerate() {
        match t {
            Tok::Punct('{', _) => depth += 1,
            Tok::Punct('}', at) => {
                if open_fn.as_ref().is_some_and(|o| o.0 == depth) {
                    if let Some((_, mut s)) = open_fn.take() {
                        s.full.1 = at + 1;
                        f.defs.push(s);
                    }
                }
                depth = depth.saturating_sub(1);
            }
            Tok::Ident(s, e) => {
                let word = &text[*s..*e];
                let prev = i.checked_sub(1).and_then(|p| toks.get(p));
                if word == "fn" {
                    if let Some(Tok::Ident(a, b)) = toks.get(i + 1) {
                        let name = text[*a..*b].to_string();
                        let kind = if test && name.starts_with("test_") {
                            SymKind::Test
                        } else {
                            SymKind::Function
                        };
                        if let Some((_, s)) = open_fn.take() {
                            f.defs.push(s);
                        }
                        open_fn = Some((
                            depth + 1,
                            Sym {
                                name,
                                kind,
                                name_span: (*a, *b),
                                full: (*s, *b),
                                children: Vec::new(),
                            },
                        ));
                    }
                } else if word == "import" {
                    if let Some(Tok::Str(a, b)) = toks.get(i + 1) {
                        f.uses.push(Use {
                            name: text[*a..*b].to_string(),
                            span: (*a, *b),
                            what: UseKind::Module,
                        });
                    }
                } else if is_punct(toks.get(i + 1), '(')
                    && is_punct(prev, ':')
                    && i >= 3
                    && is_punct(toks.get(i - 2), ':')
                {
                    // `alias::f(…)`: a call into an imported module, named with its alias.
                    if let Some(Tok::Ident(a, b)) = toks.get(i - 3) {
                        f.uses.push(Use {
                            name: format!("{}::{word}", &text[*a..*b]),
                            span: (*s, *e),
                            what: UseKind::Function,
                        });
                    }
                } else if is_punct(toks.get(i + 1), '(')
                    && !KEYWORDS.contains(&word)
                    && !is_punct(prev, '.')
                    && !is_punct(prev, ':')
                    && !matches!(prev, Some(p) if text_of(text, p) == "fn")
                {
                    f.uses.push(Use {
                        name: word.to_string(),
                        span: (*s, *e),
                        what: UseKind::Function,
                    });
                }
                // `w.add_agent("goby", ..)`: the species a test uses (a method call).
                if test && matches!(word, "add_agent" | "add_squad") {
                    if let Some((a, b)) = call_arg(toks, i) {
                        f.uses.push(Use {
                            name: text[a..b].to_string(),
                            span: (a, b),
                            what: UseKind::Species,
                        });
                    }
                }
            }
            _ => {}
        }
    }
    if let Some((_, s)) = open_fn {
        f.defs.push(s);
    }
    // Behavior names: the checks' own AST walk, when the file compiles.
    let Ok(ast) = engine.compile(text) else {
        return;
    };
    let named = if test {
        crate::script::names::test_names(&ast).behaviors
    } else {
        crate::script::names::behavior_uses(&ast)
    };
    let starts = line_starts(text);
    for n in named {
        if let Some(span) = literal_at(text, &starts, n.line, n.col, &n.name) {
            f.uses.push(Use {
                name: n.name,
                span,
                what: UseKind::Behavior,
            });
        }
    }
}

/// Byte offsets where each line starts.
pub fn line_starts(text: &str) -> Vec<usize> {
    std::iter::once(0)
        .chain(text.match_indices('\n').map(|(i, _)| i + 1))
        .collect()
}

/// The content span of the string literal `value` that Rhai places at 1-based `line`:`col`
/// (columns in characters); searched on that line when the column is off.
fn literal_at(text: &str, starts: &[usize], line: usize, col: usize, value: &str) -> Option<Span> {
    let ls = *starts.get(line.checked_sub(1)?)?;
    let le = starts.get(line).copied().unwrap_or(text.len());
    let row = text.get(ls..le)?;
    let at = row
        .char_indices()
        .nth(col.saturating_sub(1))
        .map_or(row.len(), |(b, _)| b);
    let quoted = format!("\"{value}\"");
    let found = row
        .get(at..)
        .and_then(|r| r.find(&quoted).map(|x| x + at))
        .or_else(|| row.find(&quoted))?;
    let a = ls + found + 1;
    Some((a, a + value.len()))
}

/// Every file of the project under `root`: species and scripts under `behaviors/` (its
/// `tests` folder's test files too, fixtures not), scenarios under `scenarios/`.
pub fn project_files(root: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, depth: usize, out: &mut Vec<PathBuf>) {
        if depth > 8 {
            return;
        }
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .map(|r| r.flatten().map(|e| e.path()).collect())
            .unwrap_or_default();
        entries.sort();
        for e in entries {
            let name = e.file_name().map(|n| n.to_string_lossy().into_owned());
            if e.is_dir() {
                if name.is_some_and(|n| {
                    !matches!(n.as_str(), "fixtures" | "target" | "runs") && !n.starts_with('.')
                }) {
                    walk(&e, depth + 1, out);
                }
            } else if e.extension().is_some_and(|x| x == "ron" || x == "rhai") {
                out.push(e);
            }
        }
    }
    let mut out = Vec::new();
    walk(&root.join("behaviors"), 0, &mut out);
    walk(&root.join("scenarios"), 0, &mut out);
    out
}

/// The index of every file the server knows, by normalized path.
pub type Index = BTreeMap<PathBuf, FileIndex>;

#[cfg(test)]
mod tests {
    use super::*;

    fn engine() -> rhai::Engine {
        crate::script::new_engine(&crate::scenario::script_limits())
    }

    #[test]
    fn species_behaviors_nest_and_slots_are_found() {
        let t = r#"Species(name: "s", script: Some("s.rhai"), initial: "a", behaviors: [
            Behavior(name: "a", when: Script("go")),
            Behavior(name: "hunt", sequence: [Behavior(name: "strike", on_enter: [Call("hit")])]),
        ])"#;
        let f = index(Path::new("/p/behaviors/s.ron"), t, &engine());
        let b: Vec<String> = f.behaviors().into_iter().map(|(p, _)| p).collect();
        assert_eq!(b, ["a", "hunt/strike", "hunt"]);
        assert_eq!(f.script, Some(PathBuf::from("/p/behaviors/s.rhai")));
        let fns: Vec<&str> = f
            .uses
            .iter()
            .filter(|u| u.what == UseKind::Function)
            .map(|u| u.name.as_str())
            .collect();
        assert_eq!(fns, ["go", "hit"]);
        // `initial: "a"` is a use of behavior `a`.
        assert!(f.uses.iter().any(|u| u.what == UseKind::Behavior
            && u.name == "a"
            && &t[u.span.0..u.span.1] == "a"));
    }

    #[test]
    fn script_functions_calls_and_behavior_literals() {
        let t = "import \"common/x\" as x;\nfn go() { this.behavior == \"a\" && helper(1) }\nfn helper(n) { x::f(n) }\n";
        let f = index(Path::new("/p/behaviors/s.rhai"), t, &engine());
        let names: Vec<&str> = f.defs.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["go", "helper"]);
        let uses: Vec<(&str, UseKind)> = f.uses.iter().map(|u| (u.name.as_str(), u.what)).collect();
        assert_eq!(
            uses,
            [
                ("common/x", UseKind::Module),
                ("helper", UseKind::Function),
                // A call into an imported module, named with its alias.
                ("x::f", UseKind::Function)
            ]
        );
        // Behavior names come from the compiled AST: only comparisons with `this.behavior`.
        let t = "fn ready() {\n    if this.behavior == \"a\" && this.speed < 2.0 {\n        this.say(\"b\");\n    }\n}\n";
        let f = index(Path::new("/p/behaviors/s.rhai"), t, &engine());
        let b: Vec<(&str, &str)> = f
            .uses
            .iter()
            .filter(|u| u.what == UseKind::Behavior)
            .map(|u| (u.name.as_str(), &t[u.span.0..u.span.1]))
            .collect();
        assert_eq!(b, [("a", "a")]);
    }
}
