//! A RON text changed by key: the value at a path such as `groups[0].count`,
//! `body.limits.max_speed` or `behaviors[escape].priority` is found in the text (a tree of byte
//! spans over [`super::ron_lex`]'s tokens) and its text replaced, or, for a key its struct omits,
//! `key: value` is inserted before the struct's closing bracket. The patched text is then read by
//! the ordinary loader, so every check and located message applies to it. Not a tick stage.

use super::ron_lex::{tokens, Tok};

/// One step of a key path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    /// A struct's field.
    Field(String),
    /// A list or tuple element by position.
    Index(usize),
    /// A list element whose `name` (or, without one, `species`) is this string, or a map's entry
    /// with this key.
    Named(String),
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Step::Field(s) => write!(f, ".{s}"),
            Step::Index(i) => write!(f, "[{i}]"),
            Step::Named(s) => write!(f, "[{s}]"),
        }
    }
}

/// Splits `groups[0].count` into its steps; the error says what is wrong with the key.
pub fn parse_path(path: &str) -> Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    let b = path.as_bytes();
    let mut i = 0;
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    while i < b.len() {
        if b[i] == b'[' {
            let close = path[i..]
                .find(']')
                .ok_or_else(|| format!("`[` at character {} of `{path}` is not closed", i + 1))?
                + i;
            let inner = path[i + 1..close].trim().trim_matches('"');
            if inner.is_empty() {
                return Err(format!(
                    "empty `[]` in `{path}`: expected an index or a name"
                ));
            }
            steps.push(match inner.parse::<usize>() {
                Ok(n) => Step::Index(n),
                Err(_) => Step::Named(inner.to_string()),
            });
            i = close + 1;
            continue;
        }
        if b[i] == b'.' {
            if i == 0 || i + 1 == b.len() {
                return Err(format!("`{path}`: a `.` must stand between two keys"));
            }
            i += 1;
        }
        let start = i;
        while i < b.len() && ident(b[i]) {
            i += 1;
        }
        if start == i {
            return Err(format!(
                "`{path}`: expected a key name at character {}",
                start + 1
            ));
        }
        steps.push(Step::Field(path[start..i].to_string()));
    }
    if steps.is_empty() {
        return Err("empty key".to_string());
    }
    Ok(steps)
}

/// A value of the text: its byte span and, for brackets, what is inside.
#[derive(Debug, Clone)]
struct Node {
    start: usize,
    end: usize,
    /// The word before a `(` (`Behavior`, `Some`; empty when none).
    name: String,
    kind: Kind,
}

#[derive(Debug, Clone)]
enum Kind {
    Atom,
    /// `(key: value, …)`; the byte of the closing bracket.
    Struct(Vec<(String, usize, Node)>, usize),
    /// `[a, b]` or `(a, b)`.
    Seq(Vec<Node>),
    /// `{ "k": v }`: keys without their quotes.
    Map(Vec<(String, Node)>),
}

struct Parser<'a> {
    text: &'a str,
    toks: Vec<(Tok, usize, usize)>,
    k: usize,
}

impl Parser<'_> {
    fn peek(&self, d: usize) -> Option<(Tok, usize, usize)> {
        self.toks.get(self.k + d).copied()
    }

    fn value(&mut self) -> Option<Node> {
        let (t, s, e) = self.peek(0)?;
        match t {
            Tok::Word if matches!(self.peek(1), Some((Tok::Open(b'('), o, _)) if o == e) => {
                self.k += 1;
                let mut n = self.bracket()?;
                n.start = s;
                n.name = self.text[s..e].to_string();
                Some(n)
            }
            Tok::Word | Tok::Str => {
                self.k += 1;
                Some(Node {
                    start: s,
                    end: e,
                    name: String::new(),
                    kind: Kind::Atom,
                })
            }
            Tok::Open(_) => self.bracket(),
            _ => None,
        }
    }

    /// A bracketed value starting at the current `(`, `[` or `{`.
    fn bracket(&mut self) -> Option<Node> {
        let (Tok::Open(open), start, _) = self.peek(0)? else {
            return None;
        };
        self.k += 1;
        let is_struct = open == b'('
            && (matches!(self.peek(0), Some((Tok::Close, _, _)))
                || (matches!(self.peek(0), Some((Tok::Word, _, _)))
                    && matches!(self.peek(1), Some((Tok::Colon, _, _)))));
        let mut fields = Vec::new();
        let mut items = Vec::new();
        let mut entries = Vec::new();
        loop {
            let (t, s, e) = self.peek(0)?;
            match t {
                Tok::Close => {
                    self.k += 1;
                    let kind = if is_struct {
                        Kind::Struct(fields, s)
                    } else if open == b'{' {
                        Kind::Map(entries)
                    } else {
                        Kind::Seq(items)
                    };
                    return Some(Node {
                        start,
                        end: e,
                        name: String::new(),
                        kind,
                    });
                }
                Tok::Comma => self.k += 1,
                _ if is_struct => {
                    let key = self.text[s..e].to_string();
                    self.k += 2;
                    let v = self.value()?;
                    fields.push((key, s, v));
                }
                _ if open == b'{' => {
                    let key = self.value()?;
                    let key = self.text[key.start..key.end].trim_matches('"').to_string();
                    if !matches!(self.peek(0), Some((Tok::Colon, _, _))) {
                        return None;
                    }
                    self.k += 1;
                    entries.push((key, self.value()?));
                }
                _ => items.push(self.value()?),
            }
        }
    }
}

/// What a key path reached.
enum Found<'n> {
    /// The value there.
    Value(&'n Node),
    /// A field the struct omits: insert it at this byte (the struct's closing bracket); `comma`
    /// when a `,` must go before it.
    Missing { at: usize, comma: bool },
}

/// A failed look-up: the message, and the byte it is about (where the key was looked for).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PathError {
    /// What is wrong, with a did-you-mean where a name was misspelt.
    pub message: String,
    /// Byte of the text the message is about.
    pub at: usize,
}

/// `Some(x)` stands for `x` on the way down.
fn unwrap_some(n: &Node) -> &Node {
    match &n.kind {
        Kind::Seq(items) if n.name == "Some" && items.len() == 1 => &items[0],
        _ => n,
    }
}

fn string_field<'n>(n: &'n Node, text: &'n str, key: &str) -> Option<&'n str> {
    match &n.kind {
        Kind::Struct(fields, _) => fields
            .iter()
            .find(|f| f.0 == key)
            .map(|f| text[f.2.start..f.2.end].trim_matches('"')),
        _ => None,
    }
}

/// A list element's name: its `name`, else its `species`.
fn element_name<'n>(it: &'n Node, text: &'n str) -> Option<&'n str> {
    let it = unwrap_some(it);
    string_field(it, text, "name").or_else(|| string_field(it, text, "species"))
}

fn find<'n>(
    root: &'n Node,
    text: &'n str,
    steps: &[Step],
    what: &str,
) -> Result<Found<'n>, PathError> {
    let mut node = root;
    for (i, step) in steps.iter().enumerate() {
        let walked = if i == 0 {
            what.to_string()
        } else {
            format!("`{}`", show(&steps[..i]))
        };
        let last = i + 1 == steps.len();
        let n = unwrap_some(node);
        let err = |message: String| PathError {
            message,
            at: n.start,
        };
        node = match (step, &n.kind) {
            (Step::Field(f), Kind::Struct(fields, close)) => {
                match fields.iter().find(|x| &x.0 == f) {
                    Some(x) => &x.2,
                    None if last => {
                        let before = text[..*close].trim_end();
                        let comma = !(before.ends_with(',') || before.ends_with('('));
                        return Ok(Found::Missing { at: *close, comma });
                    }
                    None => {
                        let keys: Vec<&str> = fields.iter().map(|x| x.0.as_str()).collect();
                        return Err(err(format!(
                            "no key `{f}` in {walked}{}: it has {}",
                            super::did_you_mean(f, keys.iter().copied()),
                            list(&keys)
                        )));
                    }
                }
            }
            (Step::Index(ix), Kind::Seq(items)) => items.get(*ix).ok_or_else(|| {
                err(format!(
                    "{walked} has {} element(s); index {ix} is out of range (indices start at 0)",
                    items.len()
                ))
            })?,
            (Step::Named(name), Kind::Seq(items)) => {
                let of = |it: &'n Node| element_name(it, text);
                let hits: Vec<&Node> = items.iter().filter(|it| of(it) == Some(name)).collect();
                match hits.len() {
                    1 => hits[0],
                    0 => {
                        let names: Vec<&str> = items.iter().filter_map(of).collect();
                        return Err(err(format!(
                            "no element named `{name}` in {walked}{}: its elements are {}",
                            super::did_you_mean(name, names.iter().copied()),
                            if names.is_empty() {
                                "not named (select one by index: `[0]`)".to_string()
                            } else {
                                list(&names)
                            }
                        )));
                    }
                    n => {
                        return Err(err(format!(
                            "{n} elements of {walked} are named `{name}`: select one by index"
                        )))
                    }
                }
            }
            (Step::Named(k) | Step::Field(k), Kind::Map(entries)) => {
                match entries.iter().find(|x| &x.0 == k) {
                    Some(x) => &x.1,
                    None => {
                        let keys: Vec<&str> = entries.iter().map(|x| x.0.as_str()).collect();
                        return Err(err(format!(
                            "no entry `{k}` in {walked}{}: it has {}",
                            super::did_you_mean(k, keys.iter().copied()),
                            list(&keys)
                        )));
                    }
                }
            }
            (Step::Index(_) | Step::Named(_), _) => {
                return Err(err(format!(
                    "{walked} is not a list: `{step}` selects a list element"
                )))
            }
            (Step::Field(f), _) => {
                return Err(err(format!(
                    "{walked} is a single value, not a struct with keys: `.{f}` names nothing"
                )))
            }
        };
    }
    Ok(Found::Value(node))
}

/// Steps written as a key (`groups[0].count`).
pub fn show(steps: &[Step]) -> String {
    let s: String = steps.iter().map(|x| x.to_string()).collect();
    s.strip_prefix('.').map(str::to_string).unwrap_or(s)
}

fn list(v: &[&str]) -> String {
    if v.is_empty() {
        return "none".to_string();
    }
    v.iter()
        .map(|x| format!("`{x}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// What one patch did: the lines (1-based, inclusive) of the patched text it wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Patched {
    /// First line written.
    pub first_line: usize,
    /// Last line written.
    pub last_line: usize,
}

/// `text` with the value at `steps` replaced by `value` (inserted as `key: value` when the last
/// key is omitted by its struct). `what` names the document in messages (`the scenario`). A
/// replaced value that spanned more lines than `value` keeps its line count (padding newlines),
/// so a later message's line numbers match the file on disk outside the setting's lines.
pub fn patch(
    text: &str,
    steps: &[Step],
    value: &str,
    what: &str,
) -> Result<(String, Patched), PathError> {
    let mut p = Parser {
        text,
        toks: tokens(text),
        k: 0,
    };
    let root = p.value().ok_or_else(|| PathError {
        message: format!("{what} is not a RON value this key can be found in"),
        at: 0,
    })?;
    let line_of = |at: usize| text[..at].matches('\n').count() + 1;
    let (start, end, insert) = match find(&root, text, steps, what)? {
        Found::Value(n) => (n.start, n.end, value.to_string()),
        Found::Missing { at, comma } => {
            let Some(Step::Field(key)) = steps.last() else {
                unreachable!("only a field can be missing")
            };
            let sep = if comma { ", " } else { "" };
            (at, at, format!("{sep}{key}: {value} "))
        }
    };
    let removed = text[start..end].matches('\n').count();
    let added = insert.matches('\n').count();
    let mut out = String::with_capacity(text.len() + insert.len());
    out.push_str(&text[..start]);
    out.push_str(&insert);
    out.push_str(&"\n".repeat(removed.saturating_sub(added)));
    out.push_str(&text[end..]);
    let first_line = line_of(start);
    Ok((
        out,
        Patched {
            first_line,
            last_line: first_line + removed.max(added),
        },
    ))
}

/// The text of the value at `steps` (`None` when the path does not reach one).
pub fn value_text<'t>(text: &'t str, steps: &[Step]) -> Option<&'t str> {
    let mut p = Parser {
        text,
        toks: tokens(text),
        k: 0,
    };
    let root = p.value()?;
    match find(&root, text, steps, "the file").ok()? {
        Found::Value(n) => Some(&text[n.start..n.end]),
        Found::Missing { .. } => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "Scenario(\n  duration: 10.0,\n  groups: [\n    (species: \"a\", count: 4),\n    (species: \"b\", name: \"x\", count: 1),\n  ],\n  limits: (speed: Some(0.2)),\n)";

    fn set(path: &str, v: &str) -> Result<String, PathError> {
        patch(TEXT, &parse_path(path).unwrap(), v, "the scenario").map(|x| x.0)
    }

    #[test]
    fn values_are_replaced_by_field_index_and_name() {
        assert!(set("duration", "3").unwrap().contains("duration: 3,"));
        assert!(set("groups[0].count", "50").unwrap().contains("count: 50)"));
        assert!(set("groups[x].count", "7")
            .unwrap()
            .contains("name: \"x\", count: 7)"));
        assert!(set("groups[a].count", "8")
            .unwrap()
            .contains("\"a\", count: 8)"));
        assert!(set("limits.speed", "0.5").unwrap().contains("speed: 0.5)"));
    }

    #[test]
    fn an_omitted_key_is_inserted() {
        let t = set("groups[1].heading", "Yaw(90)").unwrap();
        assert!(t.contains("count: 1, heading: Yaw(90) )"), "{t}");
        let t = set("seed", "4").unwrap();
        assert!(
            t.contains("],\n  limits: (speed: Some(0.2)),\nseed: 4 )"),
            "{t}"
        );
    }

    #[test]
    fn unknown_keys_say_what_exists() {
        let e = set("grups[0].count", "1").unwrap_err();
        assert!(
            e.message
                .starts_with("no key `grups` in the scenario (did you mean `groups`?)"),
            "{}",
            e.message
        );
        let e = set("groups[5].count", "1").unwrap_err();
        assert_eq!(
            e.message,
            "`groups` has 2 element(s); index 5 is out of range (indices start at 0)"
        );
        let e = set("groups[c].count", "1").unwrap_err();
        assert!(
            e.message.contains("its elements are `a`, `x`"),
            "{}",
            e.message
        );
        assert!(parse_path("a..b").is_err());
    }
}
