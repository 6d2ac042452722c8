//! The embedding API (`shoal::Sim` and the prelude) as a game would use it.

use shoal::prelude::*;
use std::path::Path;

fn shipped(names: &[&str]) -> SpeciesSet {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors");
    let species = names
        .iter()
        .map(|n| Species::load(dir.join(format!("{n}.ron"))).unwrap_or_else(|e| panic!("{e}")))
        .map(std::sync::Arc::new)
        .collect();
    SpeciesSet::new(species).unwrap_or_else(|e| panic!("{e}"))
}

fn water() -> Aabb {
    Aabb::new(Vec3::new(-30.0, 0.0, -30.0), Vec3::new(30.0, 20.0, 30.0))
}

#[test]
fn spawn_step_read_and_despawn() {
    let mut sim = Sim::new(
        shipped(&["sardine", "shark", "reef_fish"]),
        water(),
        0.05,
        3,
    );
    let a = sim
        .spawn("sardine", Vec3::new(0.0, 10.0, 0.0), 0.0)
        .unwrap();
    let b = sim
        .spawn("sardine", Vec3::new(1.0, 10.0, 0.0), 0.0)
        .unwrap();
    // Spawns between ticks are events of the next tick.
    sim.step();
    assert_eq!(sim.tick(), 1);
    assert!((sim.time() - 0.05).abs() < 1e-9);
    assert!(sim.behavior(a).is_some());
    assert!(sim.despawn(b));
    assert!(!sim.despawn(b), "already gone");
    assert!(sim.agent(b).is_none());
    assert_eq!(sim.agents().len(), 1);
    sim.step();
    assert!(sim.agent(a).is_some());
}

#[test]
fn an_unknown_species_is_an_error_naming_the_loaded_ones() {
    let mut sim = Sim::new(
        shipped(&["sardine", "shark", "reef_fish"]),
        water(),
        0.05,
        3,
    );
    let e = sim.spawn("sardines", Vec3::ZERO, 0.0).unwrap_err();
    assert_eq!(e.name, "sardines");
    assert!(e.to_string().contains("sardine, shark, reef_fish"), "{e}");
}

#[test]
fn a_sent_message_is_heard_in_the_next_tick_only() {
    let mut sim = Sim::new(
        shipped(&["sardine", "shark", "reef_fish"]),
        water(),
        0.05,
        3,
    );
    let a = sim
        .spawn("sardine", Vec3::new(0.0, 10.0, 0.0), 0.0)
        .unwrap();
    sim.step();
    assert!(sim.send(a, MessageKind::Danger));
    assert_eq!(
        sim.agent(a).unwrap().inbox.kind(),
        Some(MessageKind::Danger)
    );
    sim.step();
    sim.step();
    assert_eq!(
        sim.agent(a).unwrap().inbox.kind(),
        None,
        "a message lasts one tick"
    );
    assert!(!sim.send(AgentId(999), MessageKind::Danger));
}

#[test]
fn a_hot_swapped_species_keeps_the_agents_and_applies_the_new_values() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors");
    let mut sim = Sim::new(
        shipped(&["sardine", "shark", "reef_fish"]),
        water(),
        0.05,
        3,
    );
    let s = sim.spawn("shark", Vec3::new(0.0, 10.0, 0.0), 0.0).unwrap();
    for _ in 0..10 {
        sim.step();
    }
    let pos = sim.agent(s).unwrap().pos;
    let text = std::fs::read_to_string(dir.join("shark.ron")).unwrap();
    let faster = text.replace("max_speed: 5.5", "max_speed: 9.0");
    assert_ne!(faster, text, "the shark file names its speed");
    let shark = Species::parse(dir.join("shark.ron"), &faster).unwrap_or_else(|e| panic!("{e}"));
    let mut all = sim.species().species.clone();
    let k = sim.species().index_of("shark").unwrap();
    all[k] = shark.into();
    sim.set_species(SpeciesSet::new(all).unwrap());
    assert_eq!(sim.agent(s).unwrap().pos, pos, "state kept across the swap");
    assert_eq!(sim.species().species[k].def.body.limits.max_speed, 9.0);
    sim.step();
    assert!(sim.agent(s).is_some());
}

#[test]
fn a_bad_species_text_is_a_located_error() {
    let e = Species::parse("bad.ron", "(name: \"x\", behaviors: [Behavior(name: 3)])").unwrap_err();
    let text = e.to_string();
    assert!(text.starts_with("bad.ron:1:"), "{text}");
}

#[test]
fn the_same_seed_gives_the_same_world() {
    let run = || {
        let mut sim = Sim::new(
            shipped(&["sardine", "shark", "reef_fish"]),
            water(),
            0.05,
            9,
        );
        for k in 0..30 {
            let at = Vec3::new((k % 6) as f32, 8.0 + (k / 6) as f32, 0.0);
            sim.spawn("sardine", at, 0.3 * k as f32).unwrap();
        }
        for _ in 0..60 {
            sim.step();
        }
        sim.agents()
            .iter()
            .map(|a| a.pos.to_array())
            .collect::<Vec<_>>()
    };
    assert_eq!(run(), run());
}
