//! The declared blackboard and the names scripts write: a species declares its memory keys with
//! types and start values; a script that uses an undeclared key, writes a value of another type,
//! or compares `this.behavior` with a name the species does not have is refused at load with
//! file:line:col and a did-you-mean, and a wrong write that only shows at run time is a located
//! script error.

mod common;

use common::{folder, load, Sim};
use glam::Vec3;
use shoal::scenario::script_limits;
use shoal::species::load_species;
use shoal::world::{Aabb, MemValue};

/// A small species; tests put a `memory` block in place of MEMORY and a script beside it.
const MINNOW: &str = r#"Species(
    name: "minnow",
    script: Some("minnow.rhai"),
    MEMORY
    decision_interval: 1,
    initial: "idle",
    behaviors: [
        Behavior(name: "idle", priority: 2, steer: Wander()),
        Behavior(name: "dart", priority: 1, when: Script("startled"), done: TimeIn(1.0), steer: Cruise(speed: 1.0)),
    ],
)
"#;

fn species(memory: &str) -> String {
    MINNOW.replace("MEMORY", memory)
}

/// The diagnostics of loading `minnow.ron` with `memory` and `script`, as (file, line, col,
/// message) with file names relative to the folder.
fn errors(memory: &str, script: &str) -> Vec<(String, usize, usize, String)> {
    let ron = species(memory);
    let dir = folder(&[("minnow.ron", &ron), ("minnow.rhai", script)]);
    let err = load_species(&dir.path().join("minnow.ron"), dir.path(), &script_limits())
        .expect_err("the species is refused");
    err.0
        .iter()
        .map(|d| {
            (
                d.file.file_name().unwrap().to_string_lossy().into_owned(),
                d.line,
                d.col,
                d.message.clone(),
            )
        })
        .collect()
}

fn one(file: &str, line: usize, col: usize, msg: &str) -> Vec<(String, usize, usize, String)> {
    vec![(file.to_string(), line, col, msg.to_string())]
}

#[test]
fn declared_keys_start_at_their_values_and_keys_without_one_start_unset() {
    let memory = r#"memory: {
        "meals": Int(2), "home": Vec3(1.0, 2.0, 3.0), "mood": String("calm"),
        "shy": Bool(true), "depth": Float(None), "gain": Float(0.5),
    },"#;
    let script = "fn startled() {\n    this.has(\"depth\") || this[\"meals\"] > 5\n}\n";
    let ron = species(memory);
    let dir = folder(&[("minnow.ron", &ron), ("minnow.rhai", script)]);
    let sp = load(&dir.path().join("minnow.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)));
    let id = sim.spawn("minnow", Vec3::ZERO, 0.0);
    assert_eq!(
        sim.agent(id).memory,
        vec![
            ("gain".into(), MemValue::Float(0.5)),
            ("home".into(), MemValue::Vec3(Vec3::new(1.0, 2.0, 3.0))),
            ("meals".into(), MemValue::Int(2)),
            ("mood".into(), MemValue::Str("calm".into())),
            ("shy".into(), MemValue::Bool(true)),
        ]
    );
    sim.run(5);
    assert!(sim.script_errors().is_empty(), "{:?}", sim.script_errors());
    assert_eq!(
        sim.behavior(id),
        "idle",
        "`depth` is unset and 2 meals are not 5"
    );
}

#[test]
fn an_undeclared_key_is_refused_at_load_with_a_did_you_mean() {
    assert_eq!(
        errors(
            r#"memory: { "meals": Int(0) },"#,
            "fn startled() {\n    this[\"meal\"] > 1\n}\n"
        ),
        one(
            "minnow.rhai",
            2,
            10,
            "memory key \"meal\" is not declared in the species' `memory` (did you mean `meals`?): it declares \"meals\" (Int)"
        )
    );
    // `has` and `forget` name keys too; a key in a comment does not count.
    assert_eq!(
        errors(
            r#"memory: { "meals": Int(0) },"#,
            "// this[\"nope\"]\nfn startled() {\n    this.forget(\"meals\");\n    this.has(\"mels\")\n}\n"
        ),
        one(
            "minnow.rhai",
            4,
            14,
            "memory key \"mels\" is not declared in the species' `memory` (did you mean `meals`?): it declares \"meals\" (Int)"
        )
    );
}

#[test]
fn a_species_without_memory_is_told_the_declaration_to_add() {
    assert_eq!(
        errors(
            "",
            "fn startled() {\n    if !this.has(\"home_y\") { this[\"home_y\"] = this.pos.y; }\n    this[\"seen\"] = true;\n    false\n}\n"
        ),
        one(
            "minnow.rhai",
            2,
            18,
            "memory key \"home_y\" is not declared: the species declares no memory; add `memory: { \"home_y\": Float(None), \"seen\": Bool(None) }` to the species file (each key with its type and a start value, or `None` for unset)"
        )
    );
}

#[test]
fn a_write_of_an_evidently_wrong_type_is_refused_at_load() {
    assert_eq!(
        errors(
            r#"memory: { "meals": Int(0) },"#,
            "fn startled() {\n    this[\"meals\"] = \"many\";\n    true\n}\n"
        ),
        one(
            "minnow.rhai",
            2,
            10,
            "memory key \"meals\" is declared an int (`Int`), but a string is written to it here"
        )
    );
}

#[test]
fn a_write_of_the_wrong_type_at_run_time_is_a_located_script_error() {
    let script =
        "fn startled() {\n    let v = this.speed;\n    this[\"meals\"] = v;\n    false\n}\n";
    let ron = species(r#"memory: { "meals": Int(0) },"#);
    let dir = folder(&[("minnow.ron", &ron), ("minnow.rhai", script)]);
    let sp = load(&dir.path().join("minnow.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)));
    let id = sim.spawn("minnow", Vec3::ZERO, 0.0);
    sim.run(3);
    let errors = sim.script_errors();
    assert_eq!(errors.len(), 1, "{errors:?}");
    let file = dir.path().join("minnow.rhai");
    assert!(
        errors[0].starts_with(&format!("{}:3:", file.display()))
            && errors[0].contains(
                "memory key \"meals\" is declared an int (`Int`), but a float was written"
            ),
        "{}",
        errors[0]
    );
    assert_eq!(
        sim.agent(id).memory,
        vec![("meals".into(), MemValue::Int(0))]
    );
}

#[test]
fn a_behavior_name_the_species_does_not_have_is_refused_at_load() {
    assert_eq!(
        errors("", "fn startled() {\n    this.behavior != \"dsrt\"\n}\n"),
        one(
            "minnow.rhai",
            2,
            22,
            "\"dsrt\" is not a behavior of species \"minnow\" (did you mean `dart`?): it has \"idle\", \"dart\""
        )
    );
}

#[test]
fn memory_declarations_are_checked() {
    let long = "x".repeat(300);
    let memory =
        format!("memory: {{ \"gain\": Float(0.5),\n        \"mood\": String(\"{long}\") }},");
    assert_eq!(
        errors(&memory, "fn startled() { false }\n"),
        one(
            "minnow.ron",
            5,
            9,
            "memory key \"mood\": memory strings are limited to 256 bytes"
        )
    );
}

#[test]
fn a_syntax_error_points_at_the_bracket_never_closed() {
    let e = errors("", "fn startled() {\n    max(this.speed, 1.0;\n}\n");
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].3
            .ends_with("; the `(` at line 2, column 8 is never closed"),
        "{}",
        e[0].3
    );
}

#[test]
fn a_misspelt_script_function_gets_a_did_you_mean() {
    let ron = species("").replace("Script(\"startled\")", "Script(\"startld\")");
    let dir = folder(&[
        ("minnow.ron", &ron),
        ("minnow.rhai", "fn startled() { false }\n"),
    ]);
    let err = load_species(&dir.path().join("minnow.ron"), dir.path(), &script_limits())
        .expect_err("refused");
    assert!(
        err.0[0].message.contains("(did you mean `startled`?)"),
        "{}",
        err.0[0].message
    );
}

#[test]
fn a_reload_carries_memory_to_the_new_declaration() {
    let script = "fn startled() {\n    this[\"meals\"] = this[\"meals\"] + 1;\n    false\n}\n";
    let v1 = r#"memory: { "meals": Int(0), "mood": String("calm"), "old": Bool(true) },"#;
    let dir = folder(&[("minnow.ron", &species(v1)), ("minnow.rhai", script)]);
    let sp = load(&dir.path().join("minnow.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)));
    let id = sim.spawn("minnow", Vec3::ZERO, 0.0);
    sim.run(3);
    let meals = sim.agent(id).memory[0].clone();
    assert!(
        matches!(meals, (ref k, MemValue::Int(n)) if &**k == "meals" && n > 0),
        "{meals:?}"
    );
    // The new version adds "naps", makes "mood" a number and drops "old"; the script uses "naps".
    let v2 = r#"memory: { "meals": Int(0), "mood": Float(0.5), "naps": Int(7) },"#;
    let script2 = "fn startled() {\n    this[\"naps\"] = this[\"naps\"] + 1;\n    false\n}\n";
    std::fs::write(dir.path().join("minnow.ron"), species(v2)).unwrap();
    std::fs::write(dir.path().join("minnow.rhai"), script2).unwrap();
    let sp2 = load(&dir.path().join("minnow.ron"), dir.path());
    let set =
        shoal::species::SpeciesSet::with_library(vec![std::sync::Arc::new(sp2)], |_| true).unwrap();
    sim.set_species(set);
    assert_eq!(
        sim.agent(id).memory,
        vec![
            meals,
            ("mood".into(), MemValue::Float(0.5)),
            ("naps".into(), MemValue::Int(7)),
        ],
        "kept where the type holds, new and retyped keys at their start values, dropped keys gone"
    );
    sim.run(3);
    assert!(sim.script_errors().is_empty(), "{:?}", sim.script_errors());
    assert!(matches!(sim.agent(id).memory[2].1, MemValue::Int(n) if n > 7));
}

#[test]
fn conditions_read_each_agents_own_blackboard_when_every_slot_is_native() {
    // `startled` reads only the blackboard: evaluated natively, with no `on_tick`, so the
    // pass fills the view with the agent's scalars and its blackboard alone. Agents take
    // turns in one worker's view: one that remembers the key must not lend it to the next.
    let memory = r#"memory: { "spooked": Bool(None), "level": Int(0) },"#;
    let script = "fn startled() { this.has(\"spooked\") && this[\"level\"] > 1 }\n";
    let ron = species(memory);
    let dir = folder(&[("minnow.ron", &ron), ("minnow.rhai", script)]);
    let sp = load(&dir.path().join("minnow.ron"), dir.path());
    assert!(sp.scripts_native && sp.natives_read_memory);
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)));
    let ids: Vec<_> = (0..6)
        .map(|k| sim.spawn("minnow", Vec3::new(k as f32 * 20.0 - 50.0, 0.0, 0.0), 0.0))
        .collect();
    // Every other minnow is spooked at level 2; the others remember nothing or level 1 only.
    for (k, &id) in ids.iter().enumerate() {
        let m = &mut sim.agent_mut(id).memory;
        m.clear();
        if k % 2 == 0 {
            m.push(("level".into(), MemValue::Int(2)));
            m.push(("spooked".into(), MemValue::Bool(true)));
        } else if k % 4 == 1 {
            m.push(("level".into(), MemValue::Int(1)));
        }
    }
    sim.run(2);
    assert!(sim.script_errors().is_empty(), "{:?}", sim.script_errors());
    let darting: Vec<bool> = ids.iter().map(|&id| sim.behavior(id) == "dart").collect();
    assert_eq!(darting, [true, false, true, false, true, false]);
}
