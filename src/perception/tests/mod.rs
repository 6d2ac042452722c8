//! Unit tests of the stage, one file per concept: what a sense perceives (`senses.rs`), what
//! is kept and summarized, injected percepts included (`keep.rs`), and the walks — kin kernel,
//! plain and general, grid and agent order — agreeing bit for bit (`paths.rs`). The shared
//! world builders are here.

use super::*;
use crate::world::{Aabb, Agent, AgentId, Anim, Attributes, Drives, Mind, Rng, Shape, SpeciesId};

pub(crate) fn agent(id: u32, species: u16, pos: Vec3, yaw: f32) -> Agent {
    Agent {
        id: AgentId(id),
        species: SpeciesId(species),
        pos,
        prev_pos: pos,
        yaw,
        pitch: 0.0,
        speed: 1.0,
        yaw_rate: 0.0,
        pitch_rate: 0.0,
        size: Vec3::new(0.2, 0.3, 1.0),
        drives: Drives::default(),
        attrs: Attributes::default(),
        mind: Mind::new(0, 0),
        anim: Anim::default(),
        rng: Rng::new(0, id as u64),
        memory: Default::default(),
        inbox: crate::world::Inbox::Empty,
        forward_cache: crate::world::ForwardCache::NONE,
    }
}

/// Adds `n` agents of species 0 at random points within `spread` of the origin, each with a
/// random yaw, pitch and speed (drawn from `rng` in that order).
pub(crate) fn push_swarm(w: &mut World, rng: &mut Rng, n: u32, spread: f32) {
    push_school(w, rng, n, spread, |_| 0);
}

/// [`push_swarm`] with agent `k` of species `species(k)`.
pub(crate) fn push_school(
    w: &mut World,
    rng: &mut Rng,
    n: u32,
    spread: f32,
    species: impl Fn(u32) -> u16,
) {
    for k in 0..n {
        let pos = random_point(rng, spread);
        let mut a = agent(k, species(k), pos, rng.range(-3.0, 3.0));
        a.pitch = rng.range(-0.5, 0.5);
        a.speed = rng.range(0.0, 2.0);
        w.agents.push(a);
    }
}

fn run(world: &World, rel: &Relations, sense: SenseParams) -> Perception {
    run_with(world, rel, sense, Perception::new())
}

/// [`run`] with rows of every category, as the pipeline perceives while it feeds percepts.
fn run_full(world: &World, rel: &Relations, sense: SenseParams) -> Perception {
    let mut p = Perception::new();
    p.set_full_rows(true);
    run_with(world, rel, sense, p)
}

fn run_with(world: &World, rel: &Relations, sense: SenseParams, mut p: Perception) -> Perception {
    let (ag, fg) = grids(world, sense.query_radius());
    p.run(world, &ag, &fg, &[sense, sense], rel);
    p
}

/// The agent and food grids of `world`, of cells `cell`.
fn grids(world: &World, cell: f32) -> (Grid, Grid) {
    let mut ag = Grid::new();
    ag.rebuild(world.bounds, cell, world.agents.iter().map(|a| a.pos));
    let mut fg = Grid::new();
    fg.rebuild(world.bounds, cell, world.food.iter().map(|f| f.pos));
    (ag, fg)
}

/// A point drawn uniformly in the cube `[-half, half]³`.
fn random_point(rng: &mut Rng, half: f32) -> Vec3 {
    Vec3::new(
        rng.range(-half, half),
        rng.range(-half, half),
        rng.range(-half, half),
    )
}

/// What a plain flocker reads: no percepts, no headings, one separation query of `radius`.
fn separation_only(radius: f32) -> Reads {
    let mut groups = GroupQueries::new();
    groups.insert(GroupQuery::Separation { radius });
    Reads {
        percepts: false,
        agent_percepts: false,
        bearing_range: Some(0.0),
        groups,
        headings: false,
    }
}

fn rel() -> Relations {
    let mut r = Relations::new(2);
    r.set(0, 0, Some(Category::Kin));
    r.set(0, 1, Some(Category::Predator));
    r.set(1, 0, Some(Category::Food));
    r.set_eats_items(0, true);
    r
}

mod keep;
mod nearest;
mod paths;
mod senses;
