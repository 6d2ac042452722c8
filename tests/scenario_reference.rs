//! Keeps `docs/scenarios.md` honest, as `designer_reference.rs` keeps the species reference:
//!
//! - every field and variant of the scenario format (read from `src/scenario/def.rs`, so a new
//!   one is caught without editing this test) is named in the reference as `` `name` `` and
//!   appears in one of its RON examples;
//! - every fenced example loads: ```` ```ron scenario ```` blocks as whole scenarios through the
//!   loader `shoal check` uses (as if they sat in `scenarios/`, next to the shipped species and
//!   terrain), the others as the part of the format their tag names (```` ```ron groups ````, …).
//!
//! Any other fenced block fails the test, so no example goes unchecked.

use serde::de::DeserializeOwned;
use shoal::formation::PlanningParams;
use shoal::scenario::{
    DrivesOverride, Expectation, FoodDef, HeadingDef, ObstacleDef, RecordDef, Scenario,
    SpawnGroupDef, SquadDef, SquadLeader, TerrainDef, TimedEvent,
};
use shoal::species::validate::ron_options;
use shoal::world::Aabb;
use std::path::Path;

const DOC: &str = "docs/scenarios.md";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Fenced blocks: info string, text, line of the opening fence.
fn blocks(doc: &str) -> Vec<(String, String, usize)> {
    let mut out = Vec::new();
    let mut open: Option<(String, String, usize)> = None;
    for (i, line) in doc.lines().enumerate() {
        match (&mut open, line.strip_prefix("```")) {
            (None, Some(info)) => open = Some((info.trim().to_string(), String::new(), i + 1)),
            (Some(_), Some(rest)) if rest.trim().is_empty() => out.push(open.take().unwrap()),
            (Some((_, text, _)), _) => {
                text.push_str(line);
                text.push('\n');
            }
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "{DOC}: unclosed code block");
    out
}

fn parse<T: DeserializeOwned>(text: &str, line: usize, tag: &str) {
    if let Err(e) = ron_options().from_str::<T>(text) {
        panic!("{DOC}:{line}: the `{tag}` example does not parse: {e}\n{text}");
    }
}

/// Field and variant names of the types of `src/scenario/def.rs`: `pub name:` lines of structs,
/// variants of enums and the fields of struct variants (doc comments and attributes skipped).
fn format_names(source: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut kind = "";
    for line in source.lines() {
        if let Some(rest) = line.strip_prefix("pub struct ") {
            kind = if rest.trim_end().ends_with(';') {
                ""
            } else {
                "struct"
            };
            continue;
        }
        if line.starts_with("pub enum ") {
            kind = "enum";
            continue;
        }
        if line.starts_with('}') || (!line.starts_with(' ') && !line.is_empty()) {
            kind = "";
            continue;
        }
        let t = line.trim_start();
        if t.starts_with("//") || t.starts_with("#[") {
            continue;
        }
        let indent = line.len() - t.len();
        let ident: String = t
            .trim_start_matches("pub ")
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        if ident.is_empty() {
            continue;
        }
        let after = &t.trim_start_matches("pub ")[ident.len()..];
        let named = match (kind, indent) {
            ("struct", 4) => t.starts_with("pub ") && after.starts_with(':'),
            ("enum", 4) => {
                after.is_empty() || [",", "(", " {"].iter().any(|p| after.starts_with(p))
            }
            ("enum", 8) => after.starts_with(':'),
            _ => false,
        };
        if named && !names.contains(&ident) {
            names.push(ident);
        }
    }
    names
}

/// Whether `word` occurs in `text` as a whole identifier.
fn has_word(text: &str, word: &str) -> bool {
    text.match_indices(word).any(|(i, _)| {
        let ok = |c: Option<char>| !c.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
        ok(text[..i].chars().next_back()) && ok(text[i + word.len()..].chars().next())
    })
}

/// Every name of the format that the reference does not cover, with what is missing.
fn uncovered(doc: &str) -> Vec<String> {
    let source = std::fs::read_to_string(root().join("src/scenario/def.rs")).unwrap();
    let mut names = format_names(&source);
    // Types of the format defined elsewhere: boxes, draws, seed 004's planning constants.
    for n in [
        "min",
        "max",
        "Fixed",
        "Uniform",
        "relax_step",
        "fm_broken",
        "keep_share",
        "must_keep",
        "may_change_rarely",
        "shortest_first",
        "k1",
        "k2",
    ] {
        names.push(n.to_string());
    }
    let examples: String = blocks(doc)
        .into_iter()
        .filter(|(info, _, _)| info.starts_with("ron"))
        .map(|(_, text, _)| text)
        .collect();
    names
        .iter()
        .filter_map(|n| {
            let said = doc.contains(&format!("`{n}`")) || doc.contains(&format!("`{n}("));
            let shown = has_word(&examples, n);
            match (said, shown) {
                (true, true) => None,
                (false, true) => Some(format!("`{n}` is not described")),
                (true, false) => Some(format!("`{n}` has no RON example")),
                (false, false) => Some(format!("`{n}` is missing")),
            }
        })
        .collect()
}

#[test]
fn the_reference_names_every_field_and_variant_of_the_format() {
    let source = std::fs::read_to_string(root().join("src/scenario/def.rs")).unwrap();
    let names = format_names(&source);
    // The reader finds the format's names (so an empty list cannot pass).
    for n in [
        "behaviors",
        "duration",
        "Cylinder",
        "respawn_per_second",
        "heading",
        "Toward",
        "fatigue",
        "DropFood",
        "SetCurrent",
        "explain",
        "GroupCatches",
        "MaxObstaclePenetration",
        "height_scale",
        "roles",
        "Random",
        "Role",
    ] {
        assert!(
            names.iter().any(|x| x == n),
            "{n} not read from def.rs: {names:?}"
        );
    }
    assert!(
        !names.iter().any(|x| x == "shape" || x == "resolve"),
        "{names:?}"
    );
    let doc = std::fs::read_to_string(root().join(DOC)).expect(DOC);
    let missing = uncovered(&doc);
    assert!(missing.is_empty(), "{DOC}:\n{}", missing.join("\n"));
}

#[test]
fn a_field_left_out_of_the_reference_is_caught() {
    let doc = std::fs::read_to_string(root().join(DOC)).expect(DOC);
    let without = doc.replace("`respawn_per_second`", "`respawn`");
    assert_eq!(
        uncovered(&without),
        ["`respawn_per_second` is not described"]
    );
    let without = doc.replace("GroupMaxAlive(\"bait\", 0),", "");
    assert_eq!(uncovered(&without), ["`GroupMaxAlive` has no RON example"]);
}

#[test]
fn every_example_of_the_scenario_reference_loads() {
    let doc = std::fs::read_to_string(root().join(DOC)).expect(DOC);
    let mut whole = 0;
    for (k, (info, text, line)) in blocks(&doc).into_iter().enumerate() {
        let tag = info.strip_prefix("ron ").unwrap_or("");
        match tag {
            "scenario" => {
                whole += 1;
                // Where a shipped scenario sits, so `../behaviors` and `../assets` resolve.
                let file = root().join(format!("scenarios/reference_example_{k}.ron"));
                if let Err(d) = Scenario::load_str(&file, &text) {
                    panic!("{DOC}:{line}: the scenario example does not load:\n{d}");
                }
            }
            "bounds" => parse::<Aabb>(&text, line, tag),
            "current" => parse::<glam::Vec3>(&text, line, tag),
            "obstacles" => parse::<Vec<ObstacleDef>>(&text, line, tag),
            "food" => parse::<FoodDef>(&text, line, tag),
            "groups" => parse::<Vec<SpawnGroupDef>>(&text, line, tag),
            "heading" => parse::<HeadingDef>(&text, line, tag),
            "drives" => parse::<DrivesOverride>(&text, line, tag),
            "events" => parse::<Vec<TimedEvent>>(&text, line, tag),
            "record" => parse::<RecordDef>(&text, line, tag),
            "expect" => parse::<Vec<Expectation>>(&text, line, tag),
            "terrain" => parse::<TerrainDef>(&text, line, tag),
            "squads" => parse::<Vec<SquadDef>>(&text, line, tag),
            "leader" => parse::<SquadLeader>(&text, line, tag),
            "planning" => parse::<PlanningParams>(&text, line, tag),
            _ => panic!("{DOC}:{line}: unknown block `{info}`: tag it with what it shows"),
        }
    }
    assert!(whole >= 2, "{DOC}: {whole} whole scenarios");
}
