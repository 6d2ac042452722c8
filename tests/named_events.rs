//! Named events declared by species: unknown names and payload fields are load-time errors with
//! file, line, column and a suggestion (in the species file and in the script's `send`
//! literals), a payload built at run time is checked when sent, and a scenario run records the
//! events in `events.jsonl` with their name and payload.

mod common;

use common::{folder, load, shoal, Sim};
use glam::Vec3;
use shoal::scenario::script_limits;
use shoal::species::load_species;
use shoal::world::Aabb;
use std::path::Path;

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            copy_dir(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

/// A species with one declared event; tests put names into `Heard(…)`, `Send(…)`, the
/// declarations and the script.
const BASE: &str = r#"Species(
    name: "minnow",
    script: Some("minnow.rhai"),
    decision_interval: 1,
    initial: "idle",
    behaviors: [
        Behavior(name: "idle", priority: 2, steer: Stop),
        Behavior(name: "dart", priority: 1, when: Heard(HEARD), done: TimeIn(1.0), steer: Stop, on_enter: [Send(SEND, 5.0)]),
    ],
    events: [EVENTS],
)
"#;

const ALARM: &str = r#"(name: "alarm_call", priority: 25, fields: {"strength": Float})"#;

fn species(heard: &str, send: &str, events: &str) -> String {
    BASE.replace("HEARD", heard)
        .replace("SEND", send)
        .replace("EVENTS", events)
}

/// The diagnostics of loading `minnow.ron` with this script, as `file:line:col: message`
/// (file relative to the folder), first lines only.
fn errors(ron: &str, rhai: &str) -> Vec<String> {
    let dir = folder(&[("minnow.ron", ron), ("minnow.rhai", rhai)]);
    match load_species(&dir.path().join("minnow.ron"), dir.path(), &script_limits()) {
        Ok(_) => Vec::new(),
        Err(e) => {
            e.0.iter()
                .map(|d| {
                    let file = d.file.strip_prefix(dir.path()).unwrap_or(&d.file);
                    format!("{}:{}:{}: {}", file.display(), d.line, d.col, d.message)
                })
                .collect()
        }
    }
}

#[test]
fn declared_events_and_the_built_in_kinds_load() {
    let rhai = "fn on_tick() {\n    this.send(\"alarm_call\", #{ strength: 0.8 }, 8.0);\n    this.send(\"danger\", 2.0);\n}\n";
    let ok = errors(&species(r#""alarm_call""#, r#""alarm_call""#, ALARM), rhai);
    assert_eq!(ok, Vec::<String>::new());
    // The built-in form stays valid beside declarations.
    let ok = errors(&species("Danger", "Danger", ALARM), "fn on_tick() {}\n");
    assert_eq!(ok, Vec::<String>::new());
}

#[test]
fn an_unknown_name_in_heard_or_send_is_located_with_a_suggestion() {
    let e = errors(&species("Dangr", r#""alarm_call""#, ALARM), "");
    assert_eq!(
        e,
        [
            "minnow.ron:8:57: unknown event \"Dangr\" in `Heard`: declared events are alarm_call; \
          built-in kinds are Danger, Obstacle, Mate (did you mean `Danger`?)"
        ]
    );
    let e = errors(&species(r#""alarm_call""#, r#""alarmcall""#, ALARM), "");
    assert_eq!(
        e,
        ["minnow.ron:8:120: unknown event \"alarmcall\" in `Send`: declared events are alarm_call; \
          built-in kinds are Danger, Obstacle, Mate (did you mean `alarm_call`?)"]
    );
    let e = errors(&species(r#""alarm_call""#, "Danger", ""), "");
    assert_eq!(
        e,
        [
            "minnow.ron:8:57: unknown event \"alarm_call\" in `Heard`: the species declares no \
          `events`; built-in kinds are Danger, Obstacle, Mate"
        ]
    );
}

#[test]
fn script_send_literals_are_checked_at_load() {
    let ron = species("Danger", "Danger", ALARM);
    let e = errors(
        &ron,
        "fn on_tick() {\n    this.send(\"alarm_cal\", 8.0);\n}\n",
    );
    assert_eq!(
        e,
        ["minnow.rhai:2:15: unknown event \"alarm_cal\" in `send`: declared events are alarm_call; \
          built-in kinds are danger, obstacle, mate (did you mean `alarm_call`?)"]
    );
    let e = errors(
        &ron,
        "fn on_tick() {\n    this.send(\"alarm_call\", #{ strenght: 0.8 }, 8.0);\n}\n",
    );
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].starts_with("minnow.rhai:2:")
            && e[0].ends_with(
                "event \"alarm_call\" has no field `strenght`: its fields are strength (did you mean `strength`?)"
            ),
        "{e:?}"
    );
    let e = errors(
        &ron,
        "fn on_tick() {\n    this.send(\"alarm_call\", #{ strength: true }, 8.0);\n}\n",
    );
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].starts_with("minnow.rhai:2:")
            && e[0].ends_with("field `strength` of event \"alarm_call\" is a float, not a bool"),
        "{e:?}"
    );
}

#[test]
fn declarations_are_checked() {
    let e = errors(
        &species(
            "Danger",
            "Danger",
            r#"(name: "alarm_call", priority: 20), (name: "alarm_call", priority: 5), (name: "danger", priority: 1)"#,
        ),
        "",
    );
    assert_eq!(
        e,
        [
            "minnow.ron:10:21: event \"alarm_call\": `priority: 20` is the rank of Obstacle; choose \
             another number (Danger 30, Obstacle 20, Mate 10; higher is heard first)",
            "minnow.ron:10:57: event \"alarm_call\" is declared twice in `events`",
            "minnow.ron:10:92: event \"danger\" has the name of a built-in message kind: write \
             `Danger` without quotes to use it, or name the event otherwise",
        ]
    );
}

#[test]
fn a_payload_built_at_run_time_is_checked_when_sent() {
    let ron = species("Danger", "Danger", ALARM);
    let rhai = "fn on_tick() {\n    let m = #{};\n    m[\"strenght\"] = this.speed;\n    this.send(\"alarm_call\", m, 8.0);\n}\n";
    let dir = folder(&[("minnow.ron", &ron), ("minnow.rhai", rhai)]);
    let sp = load(&dir.path().join("minnow.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)));
    sim.spawn("minnow", Vec3::new(0.0, 10.0, 0.0), 0.0);
    sim.run(2);
    let errors = sim.script_errors();
    assert_eq!(errors.len(), 1, "{errors:?}");
    let file = dir.path().join("minnow.rhai");
    assert!(
        errors[0].starts_with(&format!("{}:4:", file.display()))
            && errors[0].contains(
                "event \"alarm_call\" has no field `strenght`: its fields are strength (did you mean `strength`?)"
            ),
        "{errors:?}"
    );
}

#[test]
fn a_scenario_run_records_named_events_with_their_payload() {
    let root = env!("CARGO_MANIFEST_DIR");
    let scenario = r#"Scenario(
    seed: 1,
    dt: 0.05,
    duration: 6.0,
    bounds: (min: (-15.0, 0.0, -15.0), max: (15.0, 10.0, 15.0)),
    species: ["goby", "shark"],
    groups: [
        (species: "goby", count: 8, region: (min: (-2.0, 4.0, -2.0), max: (2.0, 6.0, 2.0))),
        (species: "shark", count: 1, region: (min: (-1.0, 4.0, 6.0), max: (1.0, 6.0, 7.0)), heading: Toward(0.0, 5.0, 0.0)),
    ],
)
"#;
    // The shipped behaviors folder (the shark's prey are defined there), beside the scenario.
    let dir = folder(&[("scenarios/gobies.ron", scenario)]);
    copy_dir(
        &Path::new(root).join("behaviors"),
        &dir.path().join("behaviors"),
    );
    let out = dir.path().join("run");
    let (code, stdout, stderr) = shoal(&[
        "run",
        dir.path().join("scenarios/gobies.ron").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let events: Vec<serde_json::Value> = std::fs::read_to_string(out.join("events.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let flicks: Vec<_> = events
        .iter()
        .filter(|e| e["kind"] == "message" && e["message"] == "tail_flick")
        .collect();
    assert!(!flicks.is_empty(), "no tail_flick in events.jsonl");
    for f in &flicks {
        assert!(f["payload"]["urgency"].is_number(), "{f}");
        assert!(f["from"].is_u64() && f["radius"] == 4.0, "{f}");
    }
    assert!(
        events.iter().any(|e| e["kind"] == "transition"
            && e["to"] == "hide"
            && e["condition"] == "heard tail_flick"),
        "no goby hid on hearing a flick"
    );
}
