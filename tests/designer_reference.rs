//! Keeps `behaviors/README.md` honest: every fenced example in it is run.
//!
//! - ```` ```ron file=NAME.ron ```` / ```` ```rhai file=PATH ````: written to a scratch behaviors
//!   folder; every species file must load (a file tagged `error` must fail, with exactly the
//!   diagnostics of the ```` ```text ```` block that follows it);
//! - ```` ```ron scenario=NAME.ron ````: written to a scratch scenarios folder and run to the end
//!   without script errors;
//! - ```` ```ron body|senses|avoid|attributes|drives|relations|behavior|condition|value|recipe ````:
//!   parsed as that part of the species format;
//! - ```` ```rhai snippet ````: compiled (imports resolved against the scratch folder).
//!
//! Any other fenced block fails the test, so no example can go unchecked.

use serde::de::DeserializeOwned;
use shoal::events::Event;
use shoal::perception::SenseParams;
use shoal::scenario::{script_limits, Overrides, Run, Scenario};
use shoal::script::Script;
use shoal::species::validate::ron_options;
use shoal::species::{
    load_species, AttributesDef, BehaviorDef, BodyDef, Cond, DrivesDef, LookDef, Recipe,
    RelationsDef, Value,
};
use shoal::steering::avoid::AvoidParams;
use std::path::Path;

/// A fenced block: its info string, its text and the README line it starts on.
struct Block {
    info: String,
    text: String,
    line: usize,
}

fn blocks(readme: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in readme.lines().enumerate() {
        match (&mut open, line.strip_prefix("```")) {
            (None, Some(info)) => {
                open = Some(Block {
                    info: info.trim().to_string(),
                    text: String::new(),
                    line: i + 1,
                })
            }
            (Some(_), Some(rest)) if rest.trim().is_empty() => out.push(open.take().unwrap()),
            (Some(b), _) => {
                b.text.push_str(line);
                b.text.push('\n');
            }
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "unclosed code block in README.md");
    out
}

fn parse<T: DeserializeOwned>(b: &Block) {
    if let Err(e) = ron_options().from_str::<T>(&b.text) {
        panic!(
            "README.md:{}: the `{}` example does not parse: {e}\n{}",
            b.line, b.info, b.text
        );
    }
}

#[test]
fn every_example_of_the_designers_reference_works() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors/README.md"))
            .expect("behaviors/README.md");
    let blocks = blocks(&readme);
    let dir = tempfile::tempdir().expect("temp dir");
    let behaviors = dir.path().join("behaviors");
    let scenarios = dir.path().join("scenarios");
    std::fs::create_dir_all(&scenarios).unwrap();

    let mut species = Vec::new(); // (file, README line, expected diagnostics)
    let mut scenario_files = Vec::new();
    let mut snippets = Vec::new();
    let mut checked = 0;
    let mut k = 0;
    while k < blocks.len() {
        let b = &blocks[k];
        let words: Vec<&str> = b.info.split_whitespace().collect();
        let file_of = |w: &str, key: &str| w.strip_prefix(key).map(str::to_string);
        match words.as_slice() {
            [lang @ ("ron" | "rhai"), file, rest @ ..] if file.starts_with("file=") => {
                let rel = file_of(file, "file=").unwrap();
                let path = behaviors.join(&rel);
                std::fs::create_dir_all(path.parent().unwrap()).unwrap();
                std::fs::write(&path, &b.text).unwrap();
                if *lang == "ron" {
                    let expected = if rest == ["error"] {
                        let next = blocks.get(k + 1).filter(|n| n.info == "text");
                        let next = next.unwrap_or_else(|| {
                            panic!(
                                "README.md:{}: an error example needs a ```text block after it",
                                b.line
                            )
                        });
                        k += 1;
                        Some(next.text.trim_end().to_string())
                    } else {
                        assert!(
                            rest.is_empty(),
                            "README.md:{}: unknown tag {rest:?}",
                            b.line
                        );
                        None
                    };
                    species.push((path, b.line, expected));
                }
            }
            ["ron", file] if file.starts_with("scenario=") => {
                let path = scenarios.join(file_of(file, "scenario=").unwrap());
                std::fs::write(&path, &b.text).unwrap();
                scenario_files.push((path, b.line));
            }
            ["ron", "body"] => parse::<BodyDef>(b),
            ["ron", "senses"] => parse::<SenseParams>(b),
            ["ron", "avoid"] => parse::<AvoidParams>(b),
            ["ron", "attributes"] => parse::<AttributesDef>(b),
            ["ron", "drives"] => parse::<DrivesDef>(b),
            ["ron", "relations"] => parse::<RelationsDef>(b),
            ["ron", "look"] => parse::<LookDef>(b),
            ["ron", "behavior"] => parse::<BehaviorDef>(b),
            ["ron", "condition"] => parse::<Cond>(b),
            ["ron", "value"] => parse::<Value>(b),
            ["ron", "recipe"] => parse::<Recipe>(b),
            ["rhai", "snippet"] => snippets.push(b),
            _ => panic!(
                "README.md:{}: code block `{}` is not checked by this test (tag it)",
                b.line, b.info
            ),
        }
        checked += 1;
        k += 1;
    }

    // Species files load, or fail exactly as shown.
    for (path, line, expected) in &species {
        let r = load_species(path, &behaviors, &script_limits());
        match (r, expected) {
            (Ok(_), None) => {}
            (Err(e), None) => panic!("README.md:{line}: the example does not load:\n{e}"),
            (Ok(_), Some(_)) => panic!("README.md:{line}: the error example loads fine"),
            (Err(e), Some(text)) => {
                let shown: Vec<String> =
                    e.0.iter()
                        .map(|d| {
                            let mut d = d.clone();
                            d.file = d.file.strip_prefix(&behaviors).unwrap_or(&d.file).into();
                            d.to_string()
                        })
                        .collect();
                assert_eq!(
                    &shown.join("\n"),
                    text,
                    "README.md:{line}: diagnostics differ"
                );
            }
        }
    }
    // Script snippets compile.
    for b in snippets {
        let file = behaviors.join("snippet.rhai");
        if let Err(e) = Script::compile(&file, &b.text, &behaviors, &script_limits()) {
            panic!("README.md:{}: the script does not compile:\n{e}", b.line);
        }
    }
    // Scenarios run without script errors, and things happen.
    for (path, line) in &scenario_files {
        let sc = Scenario::load(path).unwrap_or_else(|e| panic!("README.md:{line}:\n{e}"));
        let mut run = Run::new(sc, Overrides::default());
        let mut transitions = 0;
        while !run.finished() {
            run.step();
            for e in &run.pipeline.events {
                match e {
                    Event::ScriptError { message, .. } => {
                        panic!("README.md:{line}: script error while running: {message}")
                    }
                    Event::Transition { .. } => transitions += 1,
                    _ => {}
                }
            }
        }
        assert!(transitions > 0, "README.md:{line}: nothing happened");
    }
    assert!(
        checked >= 20 && !species.is_empty() && !scenario_files.is_empty(),
        "{checked} blocks"
    );
}

/// The first number in a table cell (`0.3927 (π/8)` → 0.3927); `None` for `—`.
fn cell_number(cell: &str) -> Option<f32> {
    let t = cell.trim();
    if t == "—" {
        return None;
    }
    let end = t
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | 'e')))
        .unwrap_or(t.len());
    Some(
        t[..end]
            .parse()
            .unwrap_or_else(|_| panic!("not a number: {cell:?}")),
    )
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-4 * a.abs().max(b.abs()).max(1e-3)
}

/// The dotted path `key` in the serialized default of the species part it names, if it is one.
fn species_default(key: &str) -> Option<serde_json::Value> {
    let (part, path) = key.split_once('.')?;
    let root = match part {
        "senses" => serde_json::to_value(SenseParams::default()),
        "avoid" => serde_json::to_value(AvoidParams::default()),
        "drives" => serde_json::to_value(DrivesDef::default()),
        "body" => serde_json::to_value(BodyDef::default()),
        _ => return None,
    }
    .unwrap();
    let mut v = &root;
    for field in path.split('.') {
        v = v
            .get(field)
            .unwrap_or_else(|| panic!("{key}: no field {field:?} in the species format"));
    }
    Some(v.clone())
}

#[test]
fn the_seed_constants_table_matches_the_engine() {
    let readme = std::fs::read_to_string("behaviors/README.md").unwrap();
    let start = readme
        .find("\n## Seed constants")
        .expect("a Seed constants section");
    let section = &readme[start + 1..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    let mut rows = Vec::new();
    for line in section.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | `key` | default | paper | seed | meaning |
        if cells.len() < 6 || !cells[1].starts_with('`') {
            continue;
        }
        let key = cells[1].trim_matches('`').to_string();
        let default = cell_number(cells[2]).unwrap_or_else(|| panic!("{key}: no default"));
        rows.push((key, default, cell_number(cells[3]), cells[4].to_string()));
    }
    let engine = shoal::species::seeds::seed_constants();
    for c in &engine {
        let Some(row) = rows.iter().find(|r| r.0 == c.key) else {
            panic!("{} is missing from the reference's seed constants", c.key);
        };
        assert!(
            close(row.1, c.default),
            "{}: the reference says default {}, the engine {}",
            c.key,
            row.1,
            c.default
        );
        match (row.2, c.paper) {
            (None, None) => {}
            (Some(a), Some(b)) if close(a, b) => {}
            (a, b) => panic!(
                "{}: paper value {a:?} in the reference, {b:?} in the engine",
                c.key
            ),
        }
        assert_eq!(row.3, c.seed, "{}: seed section", c.key);
        if let Some(v) = species_default(c.key) {
            let v = v
                .as_f64()
                .or_else(|| v.get("Some").and_then(|x| x.as_f64()));
            let v = v.unwrap_or_else(|| panic!("{}: not a number in the format", c.key)) as f32;
            assert!(
                close(v, c.default),
                "{}: format default {v}, registry {}",
                c.key,
                c.default
            );
        }
    }
    for r in &rows {
        assert!(
            engine.iter().any(|c| c.key == r.0),
            "{} is in the reference but not in the engine's seed constants",
            r.0
        );
    }
    assert!(rows.len() >= 6);
}
