//! Completion on small documents, broken ones too: RON keys and variants, scenarios, the
//! `this.` API, test files.

use super::*;

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
