//! Embedding the engine in a program of your own: load species, spawn agents, step, read what
//! they do, speak to them, and swap a species' file while the world runs.
//!
//! `cargo run --example embed` (an embedder depends on `shoal` with `default-features = false`:
//! no command line, file watcher, HTTP server or viewer).

use shoal::prelude::*;
use std::path::Path;

fn main() -> std::process::ExitCode {
    // Diagnostics print as `file:line:col: message` with the line quoted.
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let behaviors = Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors");

    // Species come from files (or from strings with `Species::parse`); a located error says
    // file:line:col and what was expected.
    let sardine = Species::load(behaviors.join("sardine.ron"))?;
    let shark = Species::load(behaviors.join("shark.ron"))?;
    // Every species a relation names must be in the set (the shark also hunts reef fish).
    let reef_fish = Species::load(behaviors.join("reef_fish.ron"))?;
    let species = SpeciesSet::new(vec![sardine.into(), shark.into(), reef_fish.into()])?;

    let water = Aabb::new(Vec3::new(-30.0, 0.0, -30.0), Vec3::new(30.0, 20.0, 30.0));
    let mut sim = Sim::new(species, water, 0.05, 42);
    let fish: Vec<AgentId> = (0..20)
        .map(|k| {
            let at = Vec3::new((k % 5) as f32 * 1.5, 10.0, (k / 5) as f32 * 1.5);
            sim.spawn("sardine", at, 0.0)
        })
        .collect::<Result<_, _>>()?;
    let shark = sim.spawn("shark", Vec3::new(0.0, 10.0, -20.0), 0.0)?;

    // Step the world; every tick's events (transitions with their cause, meals, catches,
    // messages) are there until the next step.
    for _ in 0..200 {
        sim.step();
        for e in sim.events() {
            if let Event::Catch { agent, prey } = e {
                println!("t={:5.2}s {agent:?} caught {prey:?}", sim.time());
            }
        }
    }
    let alive = fish.iter().filter(|id| sim.agent(**id).is_some()).count();
    println!(
        "after {} ticks: {alive} of {} sardines left; the shark is in `{}`",
        sim.tick(),
        fish.len(),
        sim.behavior(shark).unwrap_or("?")
    );

    // A game's own signal: a danger call heard by one sardine next tick.
    if let Some(&first) = fish.iter().find(|id| sim.agent(**id).is_some()) {
        sim.send(first, MessageKind::Danger);
        sim.step();
        println!(
            "sardine {first:?} heard danger and is in `{}`",
            sim.behavior(first).unwrap_or("?")
        );
    }

    // Hot swap: a new version of the shark, matched by name; agents keep their state.
    let text = std::fs::read_to_string(behaviors.join("shark.ron"))?;
    let faster = Species::parse(
        behaviors.join("shark.ron"),
        &text.replace("max_speed: 5.5", "max_speed: 6.5"),
    )?;
    let mut all: Vec<_> = sim.species().species.clone();
    let k = sim.species().index_of("shark").expect("loaded above");
    all[k] = faster.into();
    let remap = sim.set_species(SpeciesSet::new(all)?);
    println!(
        "species swapped at tick {} ({} agents fell back)",
        sim.tick(),
        remap.events.len()
    );
    sim.step();
    Ok(())
}
