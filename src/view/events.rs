//! `events.jsonl` of a run folder: per-agent decision histories, deaths, script errors, reloads.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

use serde::Serialize;
use serde_json::Value;

use super::csv::{located, NameTable};
use super::ViewError;

/// At most this many script errors and reloads are kept for the page; the rest are counted.
const MAX_LISTED: usize = 500;

/// One decision of one agent, its strings interned in [`Events::strings`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Transition {
    pub agent: u32,
    pub tick: u32,
    pub from: u32,
    pub to: u32,
    pub cause: u32,
    pub condition: u32,
    /// The stack after the transition, joined with " > ".
    pub stack: u32,
}

/// An event listed as it was, for the page's event log.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct ListedEvent {
    pub tick: u64,
    pub text: String,
}

/// What the page needs from `events.jsonl`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Events {
    /// Transitions sorted by agent, then tick (file order within a tick).
    pub transitions: Vec<Transition>,
    /// Strings referred to by transitions.
    pub strings: NameTable,
    /// Agent id → (tick, cause) of its death.
    pub deaths: BTreeMap<u32, (u64, String)>,
    /// Script errors, at most [`MAX_LISTED`].
    pub script_errors: Vec<ListedEvent>,
    /// Reloads, at most [`MAX_LISTED`].
    pub reloads: Vec<ListedEvent>,
    /// Declared (named) events sent, with their payload, at most [`MAX_LISTED`].
    pub named: Vec<ListedEvent>,
    /// How many events of each kind the file holds.
    pub counts: BTreeMap<String, u64>,
    /// Line number of a truncated last line that was skipped, if any.
    pub truncated_line: Option<usize>,
    /// Every transition of the run counted by (species, from, to), for the state-machine graph.
    pub edges: BTreeMap<(String, String, String), u64>,
}

fn field<'v>(
    v: &'v Value,
    name: &str,
    path: &Path,
    line: usize,
    text: &str,
) -> Result<&'v Value, ViewError> {
    v.get(name)
        .ok_or_else(|| located(path, line, 1, format!("event has no `{name}` field"), text))
}

fn uint(v: &Value, name: &str, path: &Path, line: usize, text: &str) -> Result<u64, ViewError> {
    field(v, name, path, line, text)?.as_u64().ok_or_else(|| {
        located(
            path,
            line,
            1,
            format!("`{name}` must be a whole number"),
            text,
        )
    })
}

fn string(v: &Value, name: &str) -> String {
    match v.get(name) {
        Some(Value::String(s)) => s.clone(),
        Some(Value::Null) | None => String::new(),
        Some(other) => other.to_string(),
    }
}

/// One line for a `script_error` event: its message (which starts with `file:line:col:`), then
/// the agent and species. Older records that kept the place in `file`, `line` and `col` fields
/// get it put in front.
fn script_error_text(v: &Value) -> String {
    let mut text = String::new();
    let file = string(v, "file");
    if !file.is_empty() {
        text = format!("{file}:{}:{}: ", string(v, "line"), string(v, "col"));
    }
    // The message's first line; the rest quotes the offending line of the script.
    text.push_str(string(v, "message").lines().next().unwrap_or(""));
    let (agent, species) = (string(v, "agent"), string(v, "species"));
    match (agent.is_empty(), species.is_empty()) {
        (false, false) => text.push_str(&format!(" (agent {agent}, {species})")),
        (false, true) => text.push_str(&format!(" (agent {agent})")),
        (true, false) => text.push_str(&format!(" ({species})")),
        (true, true) => {}
    }
    text
}

impl Events {
    /// The transition counts as `[species, from, to, count]` rows, for the page.
    pub(crate) fn edge_list(&self) -> Vec<(&str, &str, &str, u64)> {
        self.edges
            .iter()
            .map(|((s, f, t), n)| (s.as_str(), f.as_str(), t.as_str(), *n))
            .collect()
    }

    /// Reads `events.jsonl`; a missing file means no events were recorded.
    pub(crate) fn read(path: &Path, allow_truncated_tail: bool) -> Result<Events, ViewError> {
        let mut ev = Events::default();
        if !path.exists() {
            return Ok(ev);
        }
        let file = File::open(path).map_err(|e| ViewError::io(path, e))?;
        let mut reader = BufReader::new(file);
        let mut line = String::new();
        let mut number = 0;
        loop {
            line.clear();
            if reader
                .read_line(&mut line)
                .map_err(|e| ViewError::io(path, e))?
                == 0
            {
                break;
            }
            number += 1;
            if !line.ends_with('\n') && allow_truncated_tail {
                ev.truncated_line = Some(number);
                break;
            }
            let text = line.trim();
            if text.is_empty() {
                continue;
            }
            ev.add(path, number, text)?;
        }
        ev.transitions.sort_by_key(|t| (t.agent, t.tick));
        Ok(ev)
    }

    fn add(&mut self, path: &Path, line: usize, text: &str) -> Result<(), ViewError> {
        let v: Value = serde_json::from_str(text)
            .map_err(|e| located(path, line, e.column(), e.to_string(), text))?;
        if !v.is_object() {
            return Err(located(path, line, 1, "expected a JSON object", text));
        }
        let tick = uint(&v, "tick", path, line, text)?;
        let kind = match field(&v, "kind", path, line, text)? {
            Value::String(s) => s.clone(),
            _ => return Err(located(path, line, 1, "`kind` must be a string", text)),
        };
        *self.counts.entry(kind.clone()).or_default() += 1;
        match kind.as_str() {
            "transition" => {
                let agent = uint(&v, "agent", path, line, text)?;
                let stack = match v.get("stack") {
                    Some(Value::Array(items)) => items
                        .iter()
                        .map(|s| {
                            s.as_str()
                                .map(str::to_string)
                                .unwrap_or_else(|| s.to_string())
                        })
                        .collect::<Vec<_>>()
                        .join(" > "),
                    _ => String::new(),
                };
                let t = Transition {
                    agent: agent as u32,
                    tick: tick as u32,
                    from: self.strings.intern(&string(&v, "from")) as u32,
                    to: self.strings.intern(&string(&v, "to")) as u32,
                    cause: self.strings.intern(&string(&v, "cause")) as u32,
                    condition: self.strings.intern(&string(&v, "condition")) as u32,
                    stack: self.strings.intern(&stack) as u32,
                };
                self.transitions.push(t);
                *self
                    .edges
                    .entry((string(&v, "species"), string(&v, "from"), string(&v, "to")))
                    .or_default() += 1;
            }
            "death" => {
                let agent = uint(&v, "agent", path, line, text)?;
                self.deaths
                    .insert(agent as u32, (tick, string(&v, "cause")));
            }
            "script_error" if self.script_errors.len() < MAX_LISTED => {
                let text = script_error_text(&v);
                self.script_errors.push(ListedEvent { tick, text });
            }
            // A declared event carries a payload; the built-in kinds are only counted.
            "message" if v.get("payload").is_some() && self.named.len() < MAX_LISTED => {
                let fields: Vec<String> = v["payload"]
                    .as_object()
                    .map(|m| m.iter().map(|(k, x)| format!("{k} {x}")).collect())
                    .unwrap_or_default();
                let text = format!(
                    "{} from #{} ({})",
                    string(&v, "message"),
                    string(&v, "from"),
                    fields.join(", ")
                );
                self.named.push(ListedEvent { tick, text });
            }
            "reload" if self.reloads.len() < MAX_LISTED => {
                let accepted = v.get("accepted").and_then(Value::as_bool).unwrap_or(false);
                let text = format!(
                    "version {} {}",
                    string(&v, "version"),
                    if accepted { "accepted" } else { "rejected" }
                );
                self.reloads.push(ListedEvent { tick, text });
            }
            _ => {}
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn script_errors_read_as_one_line_without_empty_places() {
        let v: Value = serde_json::from_str(
            r#"{"tick":3,"kind":"script_error","agent":2,"species":"shark","message":"b/s.rhai:4:9: boom\n4 | x\n"}"#,
        )
        .unwrap();
        assert_eq!(script_error_text(&v), "b/s.rhai:4:9: boom (agent 2, shark)");
        let old: Value = serde_json::from_str(
            r#"{"agent":2,"species":"shark","file":"h.rhai","line":4,"col":9,"message":"bad"}"#,
        )
        .unwrap();
        assert_eq!(script_error_text(&old), "h.rhai:4:9: bad (agent 2, shark)");
    }

    #[test]
    fn transitions_are_counted_per_species_and_edge() {
        let mut ev = Events::default();
        let p = Path::new("events.jsonl");
        for (i, line) in [
            r#"{"tick":1,"kind":"transition","agent":1,"species":"fish","from":"a","to":"b"}"#,
            r#"{"tick":2,"kind":"transition","agent":2,"species":"fish","from":"a","to":"b"}"#,
            r#"{"tick":3,"kind":"transition","agent":1,"species":"fish","from":"b","to":"a"}"#,
        ]
        .iter()
        .enumerate()
        {
            ev.add(p, i + 1, line).unwrap();
        }
        assert_eq!(
            ev.edge_list(),
            [("fish", "a", "b", 2), ("fish", "b", "a", 1)]
        );
    }
}
