//! A species the engine has never seen, written as RON + Rhai files (with a shared module) in a
//! temporary folder, loaded by a scenario and run: no Rust change is needed for a new species.

mod common;

use common::folder;
use shoal::events::{Cause, Event};
use shoal::scenario::{Overrides, Run, Scenario};
use shoal::world::MemValue;

const EEL: &str = r##"// A moray eel: lurks at its den, strikes at food passing close, goes back home.
Species(
    name: "eel",
    color: "#556b2f",
    body: (size: (0.15, 0.15, 1.5), limits: (max_speed: 3.0, max_turn: 0.6)),
    senses: (vision_radius: 4.0, smell_radius: 6.0),
    drives: (params: (p0: 0.02), hunger: Fixed(0.8), meal_size: 0.3),
    relations: (eats_items: true),
    script: Some("eel.rhai"),
    memory: { "den": Vec3(None), "meals": Int(None) },
    decision_interval: 2,
    initial: "lurk",
    behaviors: [
        Behavior(
            name: "strike",
            priority: 1,
            when: All([Above(Drive(Hunger), 0.4), Within(Food, 3.0)]),
            done: Any([Not(Perceives(Food)), Below(Drive(Hunger), 0.2), TimeIn(3.0)]),
            steer: Pursue(target: Food, prediction: Intercept),
            contact: Some(Eat(reach: 0.5)),
            cooldown: 1.0,
        ),
        Behavior(
            name: "return",
            priority: 2,
            when: Script("far_from_den"),
            done: Not(Script("far_from_den")),
            steer: Script("to_den"),
        ),
        Behavior(name: "lurk", priority: 3, steer: Stop),
    ],
)
"##;

const EEL_RHAI: &str = r#"// Script of the eel: its den is where it was born.
import "common/den" as den;

fn far_from_den() {
    if !this.has("den") {
        this["den"] = this.pos;
    }
    den::away(this.pos, this["den"], 1.0)
}

fn to_den() {
    if !this.has("den") {
        return this.stop();
    }
    this.arrive(this["den"], 2.0)
}

fn on_event(kind) {
    if kind == "meal" {
        this["meals"] = if this.has("meals") { this["meals"] + 1 } else { 1 };
    }
}
"#;

const DEN: &str = "// Shared den helpers.\nfn away(p, den, r) {\n    p.distance(den) > r\n}\n";

const SCENARIO: &str = r#"Scenario(
    seed: 5,
    dt: 0.05,
    duration: 20.0,
    bounds: (min: (-10.0, 0.0, -10.0), max: (10.0, 8.0, 10.0)),
    species: ["eel"],
    groups: [(species: "eel", count: 4, region: (min: (-6.0, 1.0, -6.0), max: (6.0, 3.0, 6.0)))],
    events: [(at: 2.0, action: DropFood(count: 40, region: (min: (-8.0, 1.0, -8.0), max: (8.0, 6.0, 8.0))))],
)
"#;

fn files() -> tempfile::TempDir {
    folder(&[
        ("behaviors/eel.ron", EEL),
        ("behaviors/eel.rhai", EEL_RHAI),
        ("behaviors/common/den.rhai", DEN),
        ("scenarios/eels.ron", SCENARIO),
    ])
}

fn run(dir: &std::path::Path) -> Run {
    let sc = Scenario::load(&dir.join("scenarios/eels.ron")).unwrap_or_else(|e| panic!("{e}"));
    let mut run = Run::new(sc, Overrides::default());
    let mut log = Vec::new();
    while !run.finished() {
        run.step();
        log.extend(run.pipeline.events.iter().cloned());
    }
    run.pipeline.events = log;
    run
}

#[test]
fn a_new_species_from_files_loads_runs_and_behaves() {
    let dir = files();
    let run = run(dir.path());
    let sp = &run.scenario.species.species[0];
    assert_eq!(sp.name, "eel");
    // Its script and the module it imports are part of the scenario's inputs.
    let inputs: Vec<String> = run
        .scenario
        .files()
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(inputs, ["eels.ron", "eel.ron", "eel.rhai", "den.rhai"]);

    let events = &run.pipeline.events;
    assert!(
        !events
            .iter()
            .any(|e| matches!(e, Event::ScriptError { .. })),
        "{events:?}"
    );
    let names = |from: u16, to: u16| (sp.behavior_name(from), sp.behavior_name(to));
    let transitions: Vec<(&str, &str, Cause)> = events
        .iter()
        .filter_map(|e| match e {
            Event::Transition {
                from, to, cause, ..
            } => {
                let (a, b) = names(*from, *to);
                Some((a, b, *cause))
            }
            _ => None,
        })
        .collect();
    for expected in [
        ("lurk", "strike", Cause::Interrupted),
        ("strike", "return", Cause::Completed),
        ("return", "lurk", Cause::Resumed),
    ] {
        assert!(
            transitions.contains(&expected),
            "{expected:?} in {transitions:?}"
        );
    }
    assert!(run.pipeline.stats.meals >= 2, "{:?}", run.pipeline.stats);
    // Every eel remembers its den; the ones that ate counted their meals (on_event).
    let mut meals = 0;
    for a in &run.world.agents {
        let den = a
            .memory
            .iter()
            .find(|(k, _)| &**k == "den")
            .map(|(_, v)| v.clone());
        let Some(MemValue::Vec3(den)) = den else {
            panic!("no den: {:?}", a.memory)
        };
        assert!(den.y >= 1.0 && den.y <= 3.0);
        if let Some((_, MemValue::Int(n))) = a.memory.iter().find(|(k, _)| &**k == "meals") {
            meals += n;
        }
    }
    assert_eq!(meals as u64, run.pipeline.stats.meals);
}

#[test]
fn the_new_species_runs_bit_identically_whatever_the_thread_count() {
    let dir = files();
    let positions = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let run = run(dir.path());
            run.world
                .agents
                .iter()
                .map(|a| (a.id, a.pos.to_array().map(f32::to_bits), a.mind.current))
                .collect::<Vec<_>>()
        })
    };
    assert_eq!(positions(1), positions(4));
}
