//! A group's agents are numbered in the order of the agent grid's cells, so that agents close in
//! space are close in the world's agent list; the places, headings and drives drawn for the
//! group are those it drew in list order (only who gets which number changes).

use glam::Vec3;
use shoal::scenario::{Overrides, Run, Scenario};
use shoal::world::{Aabb, Agent, Rng};
use std::path::Path;

const SCENARIO: &str = r#"Scenario(
    seed: 11,
    dt: 0.05,
    duration: 1.0,
    bounds: (min: (-40.0, 0.0, -40.0), max: (40.0, 12.0, 40.0)),
    species: ["reef_fish", "shark"],
    groups: [
        (species: "reef_fish", count: 500, region: (min: (-30.0, 1.0, -30.0), max: (30.0, 11.0, 30.0)),
         drives: (hunger: Uniform(0.6, 0.9), fear: Some(Fixed(0.25)))),
        (species: "shark", count: 3, region: (min: (20.0, 5.0, 20.0), max: (25.0, 7.0, 25.0)),
         heading: Toward(0.0, 6.0, 0.0)),
    ],
)"#;

fn run() -> Run {
    let sc = Scenario::load_str(Path::new("behaviors/spawn_order.ron"), SCENARIO)
        .unwrap_or_else(|e| panic!("{e}"));
    Run::new(sc, Overrides::default())
}

fn fish_region() -> Aabb {
    Aabb::new(Vec3::new(-30.0, 1.0, -30.0), Vec3::new(30.0, 11.0, 30.0))
}

#[test]
fn a_group_is_numbered_in_the_order_of_the_agent_grids_cells() {
    let r = run();
    let agents = &r.world.agents;
    assert_eq!(agents.len(), 503);
    // Ids ascend with the index (the world's order), first group first.
    for (i, a) in agents.iter().enumerate() {
        assert_eq!(a.id.0 as usize, i);
    }
    let (fish, sharks) = agents.split_at(500);
    let region = fish_region();
    // The grid of the first tick: cells of the fish's query radius, for all 503 agents.
    let layout = r.pipeline.agent_layout(r.world.bounds, &[500, 3]);
    let keys: Vec<u32> = fish.iter().map(|a| layout.cell_of(a.pos)).collect();
    assert!(
        keys.windows(2).all(|w| w[0] <= w[1]),
        "not in the grid's order"
    );
    // Consecutive fish are close: the mean step from one to the next is under a third of
    // the mean distance between two fish of the group (what it is in the order drawn).
    let step = fish
        .windows(2)
        .map(|w| w[0].pos.distance(w[1].pos))
        .sum::<f32>()
        / 499.0;
    let pairs = fish
        .iter()
        .enumerate()
        .flat_map(|(i, a)| fish[i + 1..].iter().map(|b| a.pos.distance(b.pos)))
        .sum::<f32>()
        / (500.0 * 499.0 / 2.0);
    assert!(
        step < pairs / 3.0,
        "mean step {step}, mean pair distance {pairs}"
    );
    // Every fish's group draws are in place: fixed fear, hunger within its range.
    for a in fish {
        assert!(region.contains(a.pos));
        assert_eq!(a.drives.fear, 0.25);
        assert!((0.6..0.9).contains(&a.drives.hunger), "{}", a.drives.hunger);
    }
    // A heading toward a point is worked out from the agent's own place (yaw 0 faces +z,
    // positive turns right, toward −x).
    for a in sharks {
        let to = Vec3::new(0.0, 6.0, 0.0) - a.pos;
        let want = shoal::frame::atan2(-to.x, to.z);
        assert!((a.yaw - want).abs() < 1e-5, "yaw {} want {want}", a.yaw);
    }
}

#[test]
fn numbering_in_grid_order_keeps_the_draws_of_the_group() {
    // The group's stream (seed ^ 0x5EED_0000, stream = the group's place in the list) drawn in
    // list order, as each fish draws: position (x, y, z), random yaw, then hunger (fear is
    // fixed, so not drawn). The numbered fish hold exactly these draws, each set whole.
    let region = fish_region();
    let mut rng = Rng::new(11 ^ 0x5EED_0000, 0);
    let pi = std::f32::consts::PI;
    let mut drawn: Vec<[u32; 5]> = (0..500)
        .map(|_| {
            let x = rng.range(region.min.x, region.max.x);
            let y = rng.range(region.min.y, region.max.y);
            let z = rng.range(region.min.z, region.max.z);
            let yaw = rng.range(-pi, pi);
            let hunger = rng.range(0.6, 0.9);
            [x, y, z, yaw, hunger].map(f32::to_bits)
        })
        .collect();
    let r = run();
    let fish: Vec<&Agent> = r.world.agents.iter().take(500).collect();
    let mut got: Vec<[u32; 5]> = fish
        .iter()
        .map(|a| [a.pos.x, a.pos.y, a.pos.z, a.yaw, a.drives.hunger].map(f32::to_bits))
        .collect();
    assert_ne!(
        got, drawn,
        "the fish are in the order drawn, not the grid's"
    );
    drawn.sort_unstable();
    got.sort_unstable();
    assert_eq!(got, drawn);
    // The same scenario numbered again gives the same world.
    let again = run();
    for (a, b) in r.world.agents.iter().zip(&again.world.agents) {
        assert_eq!((a.id, a.pos, a.yaw), (b.id, b.pos, b.yaw));
        assert_eq!(a.drives.hunger.to_bits(), b.drives.hunger.to_bits());
    }
}

/// Each group's agents, as the grid of the first tick lists them: in ascending index order.
fn in_grid_order(r: &mut Run, groups: &[std::ops::Range<usize>]) {
    let world = r.world.clone();
    r.pipeline.perceive(&world);
    let entries = r.pipeline.agent_grid().entries();
    for g in groups {
        let order: Vec<u32> = entries
            .iter()
            .copied()
            .filter(|&i| g.contains(&(i as usize)))
            .collect();
        assert_eq!(order.len(), g.len());
        assert!(
            order.windows(2).all(|w| w[0] < w[1]),
            "group {g:?} is not in the grid's order"
        );
    }
}

#[test]
fn every_group_is_numbered_against_the_grid_of_the_first_tick() {
    // Two big groups of one species, a few sharks between them and sardines, the most
    // numerous species over all: the grid's cells are the sardines' (narrower than the fish's),
    // and its cell budget counts every group. Each group, however small or early, is listed by
    // that grid in its own order.
    let text = r#"Scenario(
    seed: 5,
    dt: 0.05,
    duration: 1.0,
    bounds: (min: (-300.0, 0.0, -300.0), max: (300.0, 20.0, 300.0)),
    species: ["reef_fish", "shark", "sardine"],
    groups: [
        (species: "reef_fish", count: 600, region: (min: (-280.0, 1.0, -280.0), max: (280.0, 19.0, 280.0))),
        (species: "shark", count: 40, region: (min: (-280.0, 1.0, -280.0), max: (280.0, 19.0, 280.0))),
        (species: "reef_fish", count: 600, region: (min: (-280.0, 1.0, -280.0), max: (280.0, 19.0, 280.0))),
        (species: "sardine", count: 1500, region: (min: (-280.0, 1.0, -280.0), max: (280.0, 19.0, 280.0))),
    ],
)"#;
    let sc = Scenario::load_str(Path::new("behaviors/spawn_groups.ron"), text)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut r = Run::new(sc, Overrides::default());
    assert_eq!(r.world.agents.len(), 2740);
    in_grid_order(&mut r, &[0..600, 600..640, 640..1240, 1240..2740]);
}
