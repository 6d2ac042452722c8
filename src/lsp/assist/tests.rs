//! Completion and hover on small documents (broken ones too) and on the shipped project; the
//! format table checked against the real serde types; the API documentation complete; the JSON
//! Schemas checked against the shipped files.

use super::api::{self, Api};
use super::schema::{self, Args, Form, NAME_TYPES, PLAIN_TYPES};
use super::*;
use crate::load::ron_options;
use serde::de::DeserializeOwned;
use std::path::Path;

/// `text` with `|` marking the cursor: the text without it and the offset.
fn at(marked: &str) -> (String, usize) {
    let i = marked.find('|').expect("a cursor mark");
    (marked.replacen('|', "", 1), i)
}

fn labels(items: &[Item]) -> Vec<&str> {
    items.iter().map(|i| i.label.as_str()).collect()
}

fn complete_at(kind: FileKind, marked: &str) -> Vec<Item> {
    let (text, i) = at(marked);
    complete(kind, &text, i, &names())
}

fn hover_at(kind: FileKind, marked: &str) -> Option<Hover> {
    let (text, i) = at(marked);
    hover(kind, &text, i)
}

fn names() -> ProjectNames {
    ProjectNames {
        species: vec!["sardine".into(), "shark".into()],
        behaviors: vec!["wander".into(), "escape".into()],
        functions: vec!["tired".into()],
        modules: vec![],
    }
}

const SPECIES_HEAD: &str =
    "Species(\n    name: \"x\",\n    initial: \"wander\",\n    behaviors: [\n";

#[test]
fn completion_at_steer_lists_the_primitives() {
    let doc = format!("{SPECIES_HEAD}        Behavior(name: \"wander\", priority: 3, steer: |\n");
    let items = complete_at(FileKind::Species, &doc);
    let l = labels(&items);
    for p in [
        "Chase",
        "Escape",
        "Wander",
        "AvoidStatic",
        "Priority",
        "Blend",
        "Zones",
    ] {
        assert!(l.contains(&p), "{p} missing: {l:?}");
    }
    assert!(!l.contains(&"Sees"), "a condition offered as a primitive");
    let chase = items.iter().find(|i| i.label == "Chase").unwrap();
    assert!(
        chase.detail.starts_with("Chase(target: Category, d0: f32"),
        "{}",
        chase.detail
    );
    assert!(chase.doc.contains("smell mode by sectors"), "{}", chase.doc);
    assert_eq!(chase.insert.as_deref(), Some("Chase()"));
    // A half-typed primitive, and parameters inside one.
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(steer: Cha|"),
    );
    assert!(labels(&l).contains(&"Chase"));
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(steer: Chase(d0: 0.5, |"),
    );
    let l = labels(&l);
    assert!(
        l.contains(&"target") && l.contains(&"vision") && !l.contains(&"d0"),
        "{l:?}"
    );
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(steer: Chase(target: |"),
    );
    assert_eq!(
        labels(&l),
        ["Food", "Predator", "Kin", "Mate", "Obstacle", "Other"]
    );
    // Inside a combination.
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(steer: Priority([AvoidStatic(), |"),
    );
    assert!(labels(&l).contains(&"Escape"));
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(steer: Blend([(w: 0.5, steer: Cohesion(), |"),
    );
    assert_eq!(labels(&l), ["by"]);
}

#[test]
fn completion_in_conditions_lists_conditions_and_their_arguments() {
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(when: |"),
    );
    let l = labels(&l);
    for c in ["Sees", "Within", "Latch", "All", "Script", "EscapeDone"] {
        assert!(l.contains(&c), "{c} missing: {l:?}");
    }
    assert!(!l.contains(&"Chase"));
    // done:, nested lists and arguments.
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(done: Any([Sees(Food), |"),
    );
    assert!(labels(&l).contains(&"TimeIn"));
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(when: Above(|"),
    );
    assert!(labels(&l).contains(&"Drive"), "{:?}", labels(&l));
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(when: Above(Drive(|"),
    );
    assert_eq!(labels(&l), ["Hunger", "Libido", "Fear", "Fatigue", "State"]);
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(when: Latch(on: Sees(Food), |"),
    );
    assert_eq!(labels(&l), ["off"]);
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(when: InSector(Predator, [|"),
    );
    assert!(labels(&l).contains(&"LeftRear"));
    // Script slots offer the script's functions, quoted or inside the quotes.
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(when: Script(|"),
    );
    assert_eq!(
        l.iter().map(|i| i.insert.as_deref()).collect::<Vec<_>>(),
        [Some("\"tired\"")]
    );
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(when: Script(\"ti|"),
    );
    assert_eq!(labels(&l), ["tired"]);
    assert_eq!(l[0].insert, None);
    // Names of behaviors, and messages.
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(on_success: |"),
    );
    assert_eq!(labels(&l), ["wander", "escape"]);
    let l = complete_at(
        FileKind::Species,
        &format!("{SPECIES_HEAD}Behavior(on_enter: [Send(|"),
    );
    assert_eq!(labels(&l), ["Danger", "Obstacle", "Mate"]);
}

#[test]
fn completion_of_keys_offers_those_not_yet_written() {
    let doc = format!("{SPECIES_HEAD}        Behavior(\n            name: \"eat\",\n            |\n            steer: Stop,\n        ),\n    ],\n)\n");
    let items = complete_at(FileKind::Species, &doc);
    let l = labels(&items);
    for k in ["priority", "when", "done", "min_time", "on_enter", "focus"] {
        assert!(l.contains(&k), "{k} missing: {l:?}");
    }
    assert!(!l.contains(&"name") && !l.contains(&"steer"), "{l:?}");
    let min_time = items.iter().find(|i| i.label == "min_time").unwrap();
    assert_eq!(min_time.detail, "min_time: f32");
    assert_eq!(min_time.insert.as_deref(), Some("min_time: "));
    assert!(min_time.doc.contains("Minimum time"), "{}", min_time.doc);
    // The species' own keys, with defaults from the engine.
    let items = complete_at(FileKind::Species, "Species(\n    name: \"x\",\n    |");
    let l = labels(&items);
    assert!(l.contains(&"senses") && l.contains(&"behaviors") && !l.contains(&"name"));
    let d = items
        .iter()
        .find(|i| i.label == "decision_interval")
        .unwrap();
    assert_eq!(d.detail, "decision_interval: u32");
    let items = complete_at(FileKind::Species, "Species(\n    body: (limits: (|");
    let ms = items
        .iter()
        .find(|i| i.label == "max_speed")
        .expect("max_speed");
    assert_eq!(ms.detail, "max_speed: f32 = 2.0");
    let items = complete_at(FileKind::Species, "Species(\n    body: (locomotion: |");
    assert_eq!(labels(&items), ["Kinematic", "RigidBody"]);
    let items = complete_at(FileKind::Species, "Species(\n    body: (on_ground: |");
    assert_eq!(labels(&items), ["true", "false"]);
}

#[test]
fn completion_in_scenarios() {
    let l = complete_at(FileKind::Scenario, "Scenario(\n    duration: 10.0,\n    |");
    let l = labels(&l);
    assert!(l.contains(&"groups") && l.contains(&"expect") && !l.contains(&"duration"));
    let l = complete_at(FileKind::Scenario, "Scenario(\n    species: [|");
    assert_eq!(
        l.iter().map(|i| i.insert.as_deref()).collect::<Vec<_>>(),
        [Some("\"sardine\""), Some("\"shark\"")]
    );
    let l = complete_at(
        FileKind::Scenario,
        "Scenario(\n    obstacles: [Sphere(center: (0.0, 1.0, 2.0), radius: 1.0), |",
    );
    assert_eq!(labels(&l), ["Sphere", "Box", "Cylinder"]);
    let l = complete_at(FileKind::Scenario, "Scenario(\n    expect: [|");
    assert!(labels(&l).contains(&"MinCatches"));
    let l = complete_at(
        FileKind::Scenario,
        "Scenario(\n    events: [(at: 3.0, action: |",
    );
    assert!(labels(&l).contains(&"DropFood"));
    let l = complete_at(FileKind::Scenario, "Scenario(\n    groups: [(species: \"|");
    assert_eq!(labels(&l), ["sardine", "shark"]);
}

#[test]
fn broken_documents_still_complete() {
    // Unclosed brackets everywhere, a stray close, comments and strings with brackets.
    let doc = "Species(\n  name: \"a(b[\", // steer: (\n  behaviors: [\n    Behavior(name: \"x\", when: All([Sees(Food)),\n    Behavior(steer: |";
    assert!(labels(&complete_at(FileKind::Species, doc)).contains(&"Wander"));
    let doc = "Species(\n  /* ( [ */ behaviors: [ Behavior( min_time: 0.5, pri|";
    let l = complete_at(FileKind::Species, doc);
    assert!(labels(&l).contains(&"priority"));
    // Nothing sensible: nothing offered, no panic.
    assert!(complete_at(FileKind::Species, "|").is_empty());
    assert!(complete_at(FileKind::Species, ")))]]|").is_empty());
    assert!(complete_at(
        FileKind::Species,
        "Species(behaviors: [Behavior(steer: Chase(target: Foo(bar: |"
    )
    .is_empty());
    let text = "Species(name: \"é\", |";
    for i in 0..=text.len() {
        let _ = complete(FileKind::Species, text, i, &names());
        let _ = hover(FileKind::Species, text, i);
    }
}

const SCRIPT: &str = "// How tired the fish is.\nfn tired() {\n    this.fatigue > 0.8\n}\n\nfn station() {\n    |\n}\n";

#[test]
fn completion_after_this_lists_the_api() {
    let doc = SCRIPT.replace('|', "this.");
    let i = doc.find("this.\n").unwrap() + 5;
    let items = complete(FileKind::Script, &doc, i, &names());
    let l = labels(&items);
    for f in [
        "pos",
        "kin",
        "seek",
        "arrive",
        "recipe",
        "send",
        "has",
        "hunger",
        "plan_path",
    ] {
        assert!(l.contains(&f), "{f} missing: {l:?}");
    }
    assert!(!l.contains(&"vec3") && !l.contains(&"length"), "{l:?}");
    let seek = items.iter().find(|i| i.label == "seek").unwrap();
    assert_eq!(seek.detail, "Agent.seek(Vec3) -> Steer");
    assert!(seek.doc.contains("steering toward"), "{}", seek.doc);
    let send = items.iter().find(|i| i.label == "send").unwrap();
    assert!(
        send.detail.lines().count() == 2,
        "both overloads: {}",
        send.detail
    );
    let hunger = items.iter().find(|i| i.label == "hunger").unwrap();
    assert!(hunger.detail.ends_with("(settable)"), "{}", hunger.detail);
    let pos = items.iter().find(|i| i.label == "pos").unwrap();
    assert_eq!(pos.detail, "Agent.pos: Vec3");
    // A category's percepts, a half word, and global functions.
    let l = complete(
        FileKind::Script,
        &SCRIPT.replace('|', "this.kin.nea"),
        SCRIPT.find('|').unwrap() + 12,
        &names(),
    );
    assert!(labels(&l).contains(&"nearest_pos") && !labels(&l).contains(&"seek"));
    let items = complete_at(FileKind::Script, SCRIPT);
    let l = labels(&items);
    assert!(
        l.contains(&"vec3") && l.contains(&"tired") && l.contains(&"station"),
        "{l:?}"
    );
    assert!(!l.contains(&"assert"), "test API in a species script");
}

#[test]
fn completion_in_test_files() {
    let t = "fn test_escape() {\n    let w = world();\n    let a = w.add_agent(\"sardine\", vec3(0.0, 1.0, 0.0));\n    |\n}\n";
    let items = complete_at(FileKind::Test, t);
    let l = labels(&items);
    for f in [
        "world",
        "assert",
        "assert_behavior",
        "fail",
        "vec3",
        "test_escape",
    ] {
        assert!(l.contains(&f), "{f} missing: {l:?}");
    }
    let l = complete_at(FileKind::Test, &t.replace('|', "w.|"));
    let l = labels(&l);
    for f in ["step", "add_food", "events", "behavior", "length"] {
        assert!(l.contains(&f), "{f} missing: {l:?}");
    }
    let l = complete_at(FileKind::Test, &t.replace('|', "assert_behavior(a, \"|"));
    assert_eq!(labels(&l), ["wander", "escape"]);
    let l = complete_at(FileKind::Test, &t.replace('|', "w.add_agent(\"sh|"));
    assert_eq!(labels(&l), ["sardine", "shark"]);
}

#[test]
fn hover_shows_reference_entries() {
    let doc =
        format!("{SPECIES_HEAD}Behavior(name: \"eat\", min_ti|me: 0.5, steer: Cha|se(d0: 0.5)),\n");
    let (text, _) = at(&doc);
    let text = text.replacen('|', "", 1);
    let i = doc.find("min_ti").unwrap() + 2;
    let h = hover(FileKind::Species, &text, i).expect("hover on a key");
    assert!(h.markdown.contains("min_time: f32"), "{}", h.markdown);
    assert!(h.markdown.contains("anti-dithering"), "{}", h.markdown);
    assert_eq!(&text[h.start..h.end], "min_time");
    let i = text.find("Chase").unwrap() + 2;
    let h = hover(FileKind::Species, &text, i).expect("hover on a primitive");
    assert!(
        h.markdown.contains("| `Chase(target: Food"),
        "{}",
        h.markdown
    );
    assert!(
        h.markdown.starts_with("`Chase(target: Category"),
        "{}",
        h.markdown
    );
    // A condition, and a scenario key.
    let h = hover_at(
        FileKind::Species,
        "Species(behaviors: [Behavior(when: Esc|apeDone)])",
    )
    .unwrap();
    assert!(h.markdown.contains("seed 000 §4.4"), "{}", h.markdown);
    let h = hover_at(FileKind::Scenario, "Scenario(\n    respawn|: 1.0)");
    assert!(h.is_none());
    let h = hover_at(
        FileKind::Scenario,
        "Scenario(\n    food: (respawn_per|_second: 1.0))",
    )
    .unwrap();
    assert!(h.markdown.contains("respawn_per_second"), "{}", h.markdown);
    // Nothing to say about a number.
    assert!(hover_at(FileKind::Species, "Species(decision_interval: 4|)").is_none());
}

#[test]
fn hover_on_a_seed_constant_gives_its_paper_default() {
    let h = hover_at(
        FileKind::Species,
        "Species(\n    senses: (vision_half|_angle: 2.0),\n",
    )
    .unwrap();
    assert!(
        h.markdown
            .contains("**Seed constant** `senses.vision_half_angle` (seed 000 §1)"),
        "{}",
        h.markdown
    );
    assert!(
        h.markdown.contains("default 2.618 · paper 2.618\n"),
        "{}",
        h.markdown
    );
    let h = hover_at(
        FileKind::Species,
        "Species(behaviors: [Behavior(steer: Chase(max_tu|rn: 0.5))])",
    )
    .unwrap();
    assert!(
        h.markdown.contains("`Chase(max_turn)` (seed 000 §4.3)"),
        "{}",
        h.markdown
    );
    let h = hover_at(
        FileKind::Scenario,
        "Scenario(squads: [(species: \"a\", planning: (must_keep: (k|1: 0.1)))])",
    )
    .unwrap();
    assert!(
        h.markdown
            .contains("`squads[].planning.must_keep.k1` (seed 004)"),
        "{}",
        h.markdown
    );
    // A key of the same name elsewhere is no seed constant.
    let h = hover_at(
        FileKind::Species,
        "Species(behaviors: [Behavior(steer: Escape(max_tu|rn: 0.5))])",
    );
    assert!(h.is_none_or(|h| !h.markdown.contains("Seed constant")));
}

#[test]
fn hover_on_api_functions_and_own_functions() {
    let doc = SCRIPT.replace('|', "this.se|ek(this.kin.nearest_p|os)");
    let (text, i) = at(&doc);
    let text = text.replacen('|', "", 1);
    let h = hover(FileKind::Script, &text, i).expect("hover on seek");
    assert!(
        h.markdown.contains("Agent.seek(Vec3) -> Steer"),
        "{}",
        h.markdown
    );
    assert!(h.markdown.contains("steering toward"), "{}", h.markdown);
    let j = text.find("nearest_p").unwrap() + 3;
    let h = hover(FileKind::Script, &text, j).expect("hover on a Percepts property");
    assert!(
        h.markdown.contains("Percepts.nearest_pos: Vec3"),
        "{}",
        h.markdown
    );
    let k = text.find("tired").unwrap() + 1;
    let h = hover(FileKind::Script, &text, k).expect("hover on an own function");
    assert!(
        h.markdown.contains("fn tired()") && h.markdown.contains("How tired the fish is."),
        "{}",
        h.markdown
    );
    let h = hover_at(FileKind::Test, "fn t() { assert_beh|avior(a, \"x\"); }").unwrap();
    assert!(
        h.markdown.contains("the agent is in another behavior"),
        "{}",
        h.markdown
    );
}

/// Problems of the table's type `name` against the real type `T`: the field or variant lists
/// differ, or a variant's template does not parse.
fn check_type<T: DeserializeOwned + serde::Serialize>(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    let Some(t) = schema::get(name) else {
        return vec![format!("{name} is not in the table")];
    };
    let (probe, listed): (&str, Vec<&str>) = match &t.form {
        Form::Struct(f) => ("(zz_not_a_key: 0)", f.iter().map(|f| f.name).collect()),
        Form::Enum(v) => ("ZzNotAVariant", v.iter().map(|v| v.name).collect()),
        Form::Either(alts) => {
            for alt in alts {
                let s = schema::sample(alt);
                if let Err(e) = ron_options().from_str::<T>(&s) {
                    out.push(format!("{name}: {s} does not parse: {e}"));
                }
            }
            return out;
        }
    };
    let mut real: Vec<&str> = match ron_options().from_str::<T>(probe).map_err(|e| e.code) {
        Err(::ron::Error::NoSuchStructField { expected, .. })
        | Err(::ron::Error::NoSuchEnumVariant { expected, .. }) => expected.to_vec(),
        Err(::ron::Error::MissingStructField { .. }) => {
            // Unknown keys are ignored by this type: write every listed key and read back
            // the keys the type keeps.
            let all: Vec<String> = match &t.form {
                Form::Struct(f) => f
                    .iter()
                    .map(|f| format!("{}: {}", f.name, schema::sample(f.ty)))
                    .collect(),
                _ => Vec::new(),
            };
            let text = format!("({})", all.join(", "));
            match ron_options().from_str::<T>(&text) {
                Ok(v) => match serde_json::to_value(&v) {
                    Ok(serde_json::Value::Object(m)) => {
                        m.keys().map(|k| &*k.clone().leak()).collect()
                    }
                    other => return vec![format!("{name}: serialized as {other:?}")],
                },
                Err(e) => return vec![format!("{name}: `{text}` does not parse: {e}")],
            }
        }
        other => return vec![format!("{name}: {probe} gave {:?}", other.err())],
    };
    let mut listed_sorted = listed.clone();
    listed_sorted.sort_unstable();
    real.sort_unstable();
    if listed_sorted != real {
        out.push(format!(
            "{name}: the table has {listed_sorted:?}, the type {real:?}"
        ));
    }
    if let Form::Enum(vs) = &t.form {
        for v in vs {
            let s = schema::template(v);
            if let Err(e) = ron_options().from_str::<T>(&s) {
                out.push(format!("{name}: `{s}` does not parse: {e}"));
            }
        }
    }
    if let Form::Struct(_) = &t.form {
        let s = schema::sample(name);
        if let Err(e) = ron_options().from_str::<T>(&s) {
            out.push(format!(
                "{name}: `{s}` (the required fields) does not parse: {e}"
            ));
        }
    }
    out
}

#[test]
fn the_table_matches_the_serde_types() {
    use crate::drives::{DriveParams, HungerModel};
    use crate::events::MessageKind;
    use crate::formation::astar::{ClassFactors, PlanningParams};
    use crate::params::locomotion::{AnimParams, BodyLimits, Mode, RigidParams};
    use crate::params::steering::{AvoidParams, Prediction, VisionTurn, WanderParams, Zones};
    use crate::perception::{
        Category, Extent, Level, Occluders, Sector, Sectors, SenseParams, Strength, Volume,
    };
    use crate::scenario::def::*;
    use crate::species::def::*;
    use crate::terrain::Mobility;
    use crate::world::Aabb;
    let mut problems = Vec::new();
    let mut checked = Vec::new();
    macro_rules! check {
        ($($t:ident),* $(,)?) => {$(
            problems.extend(check_type::<$t>(stringify!($t)));
            checked.push(stringify!($t));
        )*};
    }
    check!(
        SpeciesDef,
        BodyDef,
        SenseParams,
        AvoidParams,
        AttributesDef,
        DrivesDef,
        RelationsDef,
        BehaviorDef,
        Recipe,
        LookDef,
        EventDef,
        MemDecl,
        BodyLimits,
        Mode,
        AnimParams,
        Mobility,
        Volume,
        Occluders,
        Extent,
        Strength,
        Sectors,
        SexDef,
        Draw,
        DriveParams,
        Cond,
        Contact,
        Action,
        Category,
        Weighted,
        LookAheadDef,
        ChaseDef,
        EscapeDef,
        PursueDef,
        SeekDef,
        GroupRuleDef,
        Zones,
        VicsekDef,
        DisperseDef,
        WanderParams,
        CruiseDef,
        HoldDef,
        ShapeDef,
        FieldType,
        RigidParams,
        HungerModel,
        Value,
        Sector,
        Level,
        MessageRef,
        VisionTurn,
        Prediction,
        Target,
        DriveKind,
        AttrKind,
        MessageKind,
        ScenarioDef,
        Aabb,
        ObstacleDef,
        FoodDef,
        SpawnGroupDef,
        TimedEvent,
        RecordDef,
        Expectation,
        TerrainDef,
        SquadDef,
        HeadingDef,
        DrivesOverride,
        EventAction,
        PlanningParams,
        SquadLeader,
        ClassFactors,
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    // Every type of the table is checked, and every type a field names is in the table.
    for t in schema::types() {
        assert!(
            checked.contains(&t.name),
            "{} is not checked against its type",
            t.name
        );
    }
    let mut named: Vec<&str> = Vec::new();
    for t in schema::types() {
        match &t.form {
            Form::Struct(f) => named.extend(f.iter().map(|f| f.ty)),
            Form::Enum(v) => {
                for v in v {
                    match &v.args {
                        Args::Tuple(a) => named.extend(a.iter().copied()),
                        Args::Named(f) => named.extend(f.iter().map(|f| f.ty)),
                        Args::Unit => {}
                    }
                }
            }
            Form::Either(a) => named.extend(a.iter().copied()),
        }
    }
    for ty in named {
        let mut t = schema::bare(ty);
        t = schema::element(t)
            .or_else(|| schema::map_value(t))
            .map_or(t, schema::bare);
        let known = schema::get(t).is_some()
            || PLAIN_TYPES.contains(&t)
            || NAME_TYPES.contains(&t)
            || t == "(f32, f32)";
        assert!(known, "type {ty} of the table is unknown");
    }
}

#[test]
fn a_variant_missing_from_the_table_is_caught() {
    // `Level` checked as if it were `Sector`: the lists differ and it is said.
    let p = check_type::<crate::perception::Level>("Sector");
    assert!(p.iter().any(|p| p.contains("the table has")), "{p:?}");
    let p = check_type::<crate::species::def::ChaseDef>("SeekDef");
    assert!(p.iter().any(|p| p.contains("the table has")), "{p:?}");
}

#[test]
fn every_registered_api_function_has_documentation() {
    let mut missing = Vec::new();
    for api in [Api::Script, Api::Test] {
        let fns = api::functions(api);
        assert!(fns.len() > 20, "{api:?}: {} functions", fns.len());
        for f in fns {
            if f.doc.is_none() {
                missing.push(format!("{api:?}: {}", f.signature()));
            }
        }
    }
    assert!(missing.is_empty(), "undocumented:\n{}", missing.join("\n"));
    // Rhai's own library is not part of the API.
    let script = api::functions(Api::Script);
    assert!(!script.iter().any(|f| f.name == "sin" || f.name == "len"));
    assert!(script
        .iter()
        .any(|f| f.name == "vec3" && f.receiver.is_empty()));
    let test = api::functions(Api::Test);
    assert!(test.iter().any(|f| f.name == "assert_behavior"));
    assert!(
        !test.iter().any(|f| f.name == "seek"),
        "script API listed as test API"
    );
}

#[test]
fn rhai_definitions_list_the_this_api() {
    let d = api::definitions(Api::Script);
    for f in ["fn seek(", "fn arrive(", "get pos(", "fn vec3("] {
        assert!(d.contains(f), "{f} missing from the definitions:\n{d}");
    }
    let t = api::definitions(Api::Test);
    assert!(
        t.contains("fn assert_behavior(") && t.contains("fn seek("),
        "{t}"
    );
}

/// A tiny JSON Schema checker: `$ref`, `type`, `const`, `properties`, `required`,
/// `additionalProperties`, `items`, `prefixItems`, `oneOf`, `anyOf` (what the generated schemas
/// use). JSON has no infinity: serde writes it as `null`, taken for a number.
fn validate(
    v: &serde_json::Value,
    s: &serde_json::Value,
    root: &serde_json::Value,
    path: &str,
) -> Vec<String> {
    use serde_json::Value as J;
    if let Some(r) = s.get("$ref").and_then(J::as_str) {
        let name = r.trim_start_matches("#/$defs/");
        return validate(v, &root["$defs"][name], root, path);
    }
    if let Some(c) = s.get("const") {
        return if v == c {
            vec![]
        } else {
            vec![format!("{path}: {v} is not {c}")]
        };
    }
    for (key, need_one) in [("oneOf", true), ("anyOf", false)] {
        if let Some(alts) = s.get(key).and_then(J::as_array) {
            let ok = alts
                .iter()
                .filter(|a| validate(v, a, root, path).is_empty())
                .count();
            return if ok == 1 || (!need_one && ok > 0) {
                vec![]
            } else {
                vec![format!("{path}: {v} matches {ok} of {key}")]
            };
        }
    }
    let mut out = Vec::new();
    match (s.get("type").and_then(J::as_str), v) {
        (Some("null"), J::Null)
        | (Some("number"), J::Number(_) | J::Null)
        | (Some("boolean"), J::Bool(_))
        | (Some("string"), J::String(_)) => {}
        (Some("integer"), J::Number(n)) if n.is_i64() || n.is_u64() => {}
        (Some("array"), J::Array(a)) => {
            for (i, x) in a.iter().enumerate() {
                let item = s
                    .get("prefixItems")
                    .and_then(|p| p.get(i))
                    .or(s.get("items"));
                if let Some(item) = item {
                    out.extend(validate(x, item, root, &format!("{path}[{i}]")));
                }
            }
        }
        (Some("object"), J::Object(m)) => {
            for (k, x) in m {
                match s.get("properties").and_then(|p| p.get(k)) {
                    Some(p) => out.extend(validate(x, p, root, &format!("{path}.{k}"))),
                    None => match s.get("additionalProperties") {
                        Some(J::Bool(false)) => {
                            out.push(format!("{path}: key `{k}` is not in the schema"))
                        }
                        Some(a) => out.extend(validate(x, a, root, &format!("{path}.{k}"))),
                        None => {}
                    },
                }
            }
            for r in s
                .get("required")
                .and_then(J::as_array)
                .into_iter()
                .flatten()
            {
                if !m.contains_key(r.as_str().unwrap_or("")) {
                    out.push(format!("{path}: required `{r}` missing"));
                }
            }
        }
        (t, v) => out.push(format!("{path}: {v} is not of type {t:?}")),
    }
    out
}

fn shipped(dir: &str) -> Vec<(std::path::PathBuf, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut out: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|p| {
            let t = std::fs::read_to_string(&p).unwrap();
            (p, t)
        })
        .collect();
    out.sort();
    out
}

#[test]
fn the_json_schemas_validate_the_shipped_files() {
    let species = json_schema::species();
    let scenario = json_schema::scenario();
    let mut n = 0;
    for (p, text) in shipped("behaviors") {
        let def: crate::species::SpeciesDef = ron_options().from_str(&text).unwrap();
        let v = serde_json::to_value(&def).unwrap();
        let e = validate(&v, &species, &species, "");
        assert!(e.is_empty(), "{}:\n{}", p.display(), e.join("\n"));
        n += 1;
    }
    for (p, text) in shipped("scenarios") {
        let def: crate::scenario::ScenarioDef = ron_options().from_str(&text).unwrap();
        let v = serde_json::to_value(&def).unwrap();
        let e = validate(&v, &scenario, &scenario, "");
        assert!(e.is_empty(), "{}:\n{}", p.display(), e.join("\n"));
        n += 1;
    }
    assert!(n >= 10, "{n} files");
    // The checker can fail: an unknown key, a wrong variant.
    let mut v = serde_json::to_value(
        ron_options()
            .from_str::<crate::species::SpeciesDef>(&shipped("behaviors")[0].1)
            .unwrap(),
    )
    .unwrap();
    v["bogus"] = serde_json::json!(1);
    v["body"]["locomotion"] = serde_json::json!("Hovering");
    let e = validate(&v, &species, &species, "");
    assert!(
        e.iter().any(|e| e.contains("`bogus` is not in the schema")),
        "{e:?}"
    );
    assert!(e.iter().any(|e| e.contains(".body.locomotion")), "{e:?}");
    assert_eq!(
        species["$schema"],
        "https://json-schema.org/draft/2020-12/schema"
    );
}

#[test]
fn every_key_of_the_shipped_files_completes_and_hovers_quickly() {
    // At each key of each shipped species and scenario, completion offers that key and hover
    // has something to say; the slowest call is reported (and bounded loosely: debug builds on
    // a busy machine).
    let mut slowest = std::time::Duration::ZERO;
    let mut calls = 0;
    for (dir, kind) in [
        ("behaviors", FileKind::Species),
        ("scenarios", FileKind::Scenario),
    ] {
        for (p, text) in shipped(dir) {
            let toks = cursor::tokens(&text);
            for w in toks.windows(2) {
                if !(w[0].0 == cursor::Tok::Word && w[1].0 == cursor::Tok::Colon) {
                    continue;
                }
                let (s, e) = (w[0].1, w[0].2);
                let key = &text[s..e];
                let t0 = std::time::Instant::now();
                let items = complete(kind, &text, e, &names());
                let h = hover(kind, &text, s);
                slowest = slowest.max(t0.elapsed() / 2);
                calls += 2;
                let line = text[..s].matches('\n').count() + 1;
                assert!(
                    labels(&items).contains(&key),
                    "{}:{line}: `{key}` not offered",
                    p.display()
                );
                assert!(h.is_some(), "{}:{line}: no hover on `{key}`", p.display());
            }
        }
    }
    eprintln!("{calls} calls on the shipped files, slowest {slowest:?}");
    assert!(calls > 200, "{calls}");
    assert!(
        slowest < std::time::Duration::from_millis(50),
        "slowest call {slowest:?}"
    );
}

#[test]
fn rhai_completion_on_the_shipped_scripts_is_quick() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors");
    let _ = api::functions(Api::Script);
    let _ = api::functions(Api::Test);
    let mut slowest = std::time::Duration::ZERO;
    for (dir, kind) in [
        (root.clone(), FileKind::Script),
        (root.join("tests"), FileKind::Test),
    ] {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_none_or(|x| x != "rhai") {
                continue;
            }
            let text = std::fs::read_to_string(&p).unwrap();
            for (i, _) in text.match_indices("this.").take(50) {
                let t0 = std::time::Instant::now();
                let items = complete(kind, &text, i + 5, &names());
                let _ = hover(kind, &text, i + 6);
                slowest = slowest.max(t0.elapsed());
                assert!(labels(&items).contains(&"pos"), "{}", p.display());
            }
        }
    }
    eprintln!("slowest Rhai completion + hover {slowest:?}");
    assert!(
        slowest < std::time::Duration::from_millis(50),
        "{slowest:?}"
    );
}
