//! What the page embeds to explain the selected agent: `explain.jsonl` of a run folder (written by
//! `shoal run --explain`, see [`crate::tick::Explain`]) grouped by agent, and every agent's meals,
//! catches and matings from `events.jsonl`. The page reads it as `<script id="shoal-explain">`.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::Path;

use serde_json::{json, Value};

/// Explanations kept per agent at most (frames and decisions each); the rest are dropped and
/// counted, so a long run still opens.
const MAX_PER_AGENT: usize = 4000;

/// Bytes of `explain.jsonl` read at most; past them the page says the rest was left out.
const MAX_BYTES: u64 = 64 << 20;

/// The JSON objects of a JSON Lines file with their line lengths (unreadable lines skipped).
fn lines(path: &Path) -> impl Iterator<Item = (usize, Value)> {
    let file = std::fs::File::open(path).ok();
    file.into_iter().flat_map(|f| {
        BufReader::new(f)
            .lines()
            .map_while(Result::ok)
            .filter_map(|l| Some((l.len(), serde_json::from_str::<Value>(&l).ok()?)))
    })
}

/// The explanation table of `run_dir`: `{frames: {id: [..]}, decisions: {id: [..]}, contacts:
/// {id: [[tick, kind, other]..]}, present, dropped}`; `present` is false when the run did not
/// record `explain.jsonl`.
pub(crate) fn build(run_dir: &Path) -> Value {
    let path = run_dir.join(crate::record::EXPLAIN_FILE);
    let present = path.is_file();
    let mut frames: BTreeMap<u64, Vec<Value>> = BTreeMap::new();
    let mut decisions: BTreeMap<u64, Vec<Value>> = BTreeMap::new();
    let mut dropped = 0u64;
    let mut read = 0u64;
    if present {
        for (len, v) in lines(&path) {
            read += len as u64 + 1;
            if read > MAX_BYTES {
                dropped += 1;
                continue;
            }
            let Some(id) = v["id"].as_u64() else { continue };
            let list = match v["type"].as_str() {
                Some("frame") => frames.entry(id).or_default(),
                Some("decision") => decisions.entry(id).or_default(),
                _ => continue,
            };
            if list.len() < MAX_PER_AGENT {
                list.push(v);
            } else {
                dropped += 1;
            }
        }
    }
    let mut contacts: BTreeMap<u64, Vec<Value>> = BTreeMap::new();
    for (_, e) in lines(&run_dir.join("events.jsonl")) {
        let (kind, other) = match e["kind"].as_str() {
            Some("meal") => ("meal", &e["food"]),
            Some("catch") => ("catch", &e["prey"]),
            Some("mating") => ("mating", &e["mate"]),
            _ => continue,
        };
        if let Some(a) = e["agent"].as_u64() {
            let list = contacts.entry(a).or_default();
            if list.len() < MAX_PER_AGENT {
                list.push(json!([e["tick"], kind, other]));
            }
        }
    }
    let by_id = |m: BTreeMap<u64, Vec<Value>>| -> Value {
        Value::Object(
            m.into_iter()
                .map(|(k, v)| (k.to_string(), Value::Array(v)))
                .collect(),
        )
    };
    json!({
        "present": present,
        "dropped": dropped,
        "frames": by_id(frames),
        "decisions": by_id(decisions),
        "contacts": by_id(contacts),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_explanations_and_contacts_by_agent() {
        let dir = std::env::temp_dir().join(format!("shoal-view-explain-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("explain.jsonl"),
            "{\"type\":\"frame\",\"tick\":2,\"id\":7,\"term\":\"Wander\"}\n\
             {\"type\":\"decision\",\"tick\":1,\"id\":7}\n{\"type\":\"frame\",\"tick\":2,\"id\":3}\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("events.jsonl"),
            "{\"tick\":4,\"kind\":\"meal\",\"agent\":7,\"food\":12}\n\
             {\"tick\":5,\"kind\":\"catch\",\"agent\":3,\"prey\":7}\n",
        )
        .unwrap();
        let v = build(&dir);
        assert_eq!(v["present"], true);
        assert_eq!(v["frames"]["7"][0]["term"], "Wander");
        assert_eq!(v["frames"]["3"].as_array().unwrap().len(), 1);
        assert_eq!(v["decisions"]["7"][0]["tick"], 1);
        assert_eq!(v["contacts"]["7"][0], json!([4, "meal", 12]));
        assert_eq!(v["contacts"]["3"][0], json!([5, "catch", 7]));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
