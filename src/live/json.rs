//! The JSON a live viewer reads: the world description (the `world.json` of a recording), frames
//! of agent states, and one agent's inspection (drives, behavior, stack, memory and its last
//! decisions with their causes). Formats in `docs/viewer.md` (live mode).

use crate::scenario::Run;
use crate::world::{Agent, MemValue, Shape};
use serde::Serialize;
use std::collections::VecDeque;

/// Most agents sent in one frame; larger worlds are sent with a stride (every k-th agent).
pub const MAX_FRAME_AGENTS: usize = 20_000;

/// Decisions kept per agent for inspection.
pub const DECISIONS_KEPT: usize = 32;

/// One behavior change of an agent, as the inspection panel shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Decision {
    /// Tick it happened at.
    pub tick: u64,
    /// Behavior before.
    pub from: String,
    /// Behavior after.
    pub to: String,
    /// Why (`interrupted`, `completed`, `resumed`, `fallback`, ...).
    pub cause: &'static str,
    /// Text of the condition that fired.
    pub condition: Option<String>,
    /// The stack after it, bottom first (`a > b`).
    pub stack: String,
}

/// The decisions of one agent, oldest first.
pub type DecisionLog = VecDeque<Decision>;

/// Drives of an inspected agent.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DrivesInfo {
    /// Hunger.
    pub hunger: f32,
    /// Libido.
    pub libido: f32,
    /// Fear.
    pub fear: f32,
    /// Fatigue.
    pub fatigue: f32,
}

/// One agent, inspected (`GET /agent/<id>`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AgentInfo {
    /// Id.
    pub id: u32,
    /// Species name.
    pub species: String,
    /// Current behavior.
    pub behavior: String,
    /// Stack of interrupted behaviors, bottom first.
    pub stack: Vec<String>,
    /// Drives.
    pub drives: DrivesInfo,
    /// The agent's blackboard.
    pub memory: serde_json::Map<String, serde_json::Value>,
    /// Last decisions, oldest first.
    pub decisions: Vec<Decision>,
    /// Position.
    pub pos: [f32; 3],
    /// Speed.
    pub speed: f32,
    /// Seconds in the current behavior.
    pub time_in_behavior: f32,
    /// Tick of this answer.
    pub tick: u64,
    /// Seconds per tick.
    pub dt: f32,
    /// Its latest explained frame (the steering term in control, target, pressures, ...; see
    /// `crate::tick::Explain`), once a tick has run since it was first inspected.
    pub explain: Option<serde_json::Value>,
    /// Its latest explained decisions (clauses, why not), oldest first.
    pub explained_decisions: Vec<serde_json::Value>,
    /// Its meals, catches and matings: `[tick, kind, other id]`, oldest first.
    pub contacts: Vec<serde_json::Value>,
}

fn mem_json(v: &MemValue) -> serde_json::Value {
    match v {
        MemValue::Bool(b) => (*b).into(),
        MemValue::Int(i) => (*i).into(),
        MemValue::Float(f) => {
            serde_json::Number::from_f64(*f as f64).map_or(serde_json::Value::Null, Into::into)
        }
        MemValue::Vec3(p) => serde_json::json!([p.x, p.y, p.z]),
        MemValue::Str(s) => s.as_str().into(),
    }
}

/// Inspection of `agent` in `run`.
pub fn agent_info(run: &Run, agent: &Agent, decisions: Option<&DecisionLog>) -> AgentInfo {
    let sp = &run.pipeline.species.species[agent.species.0 as usize];
    let m = &agent.mind;
    AgentInfo {
        id: agent.id.0,
        species: sp.name.clone(),
        behavior: sp.behavior_name(m.current).to_string(),
        stack: m
            .stack()
            .iter()
            .map(|&b| sp.behavior_name(b).to_string())
            .collect(),
        drives: DrivesInfo {
            hunger: agent.drives.hunger,
            libido: agent.drives.libido,
            fear: agent.drives.fear,
            fatigue: agent.drives.fatigue,
        },
        memory: agent
            .memory
            .iter()
            .map(|(k, v)| (k.to_string(), mem_json(v)))
            .collect(),
        decisions: decisions.map_or_else(Vec::new, |d| d.iter().cloned().collect()),
        pos: agent.pos.to_array(),
        speed: agent.speed,
        time_in_behavior: run.world.tick.saturating_sub(m.entered_tick) as f32 * run.world.dt,
        tick: run.world.tick,
        dt: run.world.dt,
        explain: None,
        explained_decisions: Vec::new(),
        contacts: Vec::new(),
    }
}

#[derive(Serialize)]
struct Bounds {
    min: [f32; 3],
    max: [f32; 3],
}

#[derive(Serialize)]
#[serde(tag = "shape", rename_all = "lowercase")]
enum ObstacleJson {
    Sphere {
        id: u32,
        center: [f32; 3],
        radius: f32,
        removed_tick: Option<u64>,
    },
    Box {
        id: u32,
        min: [f32; 3],
        max: [f32; 3],
        removed_tick: Option<u64>,
    },
    Cylinder {
        id: u32,
        base: [f32; 3],
        radius: f32,
        height: f32,
        removed_tick: Option<u64>,
    },
}

#[derive(Serialize)]
struct SpeciesJson<'a> {
    name: &'a str,
    color: &'a str,
    length: f32,
    behaviors: Vec<&'a str>,
    look: crate::species::def::look::Look<'a>,
    behavior_info: Vec<serde_json::Value>,
}

#[derive(Serialize)]
struct WorldJson<'a> {
    bounds: Bounds,
    obstacles: Vec<ObstacleJson>,
    species: Vec<SpeciesJson<'a>>,
    terrain: Option<()>,
    plans: [(); 0],
}

/// The world description of `run` (`world.json` of a recording). `removed_at[i]` is the tick
/// obstacle `i` was removed at, if it was.
pub fn world_json(run: &Run, removed_at: &[Option<u64>]) -> String {
    let w = &run.world;
    let obstacles = w
        .obstacles
        .iter()
        .enumerate()
        .map(|(i, o)| {
            let removed_tick = removed_at.get(i).copied().flatten();
            match o.shape {
                Shape::Sphere { center, radius } => ObstacleJson::Sphere {
                    id: o.id,
                    center: center.to_array(),
                    radius,
                    removed_tick,
                },
                Shape::Box(b) => ObstacleJson::Box {
                    id: o.id,
                    min: b.min.to_array(),
                    max: b.max.to_array(),
                    removed_tick,
                },
                Shape::Cylinder {
                    base,
                    radius,
                    height,
                } => ObstacleJson::Cylinder {
                    id: o.id,
                    base: base.to_array(),
                    radius,
                    height,
                    removed_tick,
                },
            }
        })
        .collect();
    let species = run
        .pipeline
        .species
        .species
        .iter()
        .map(|s| SpeciesJson {
            name: &s.name,
            color: &s.def.color,
            length: s.def.body.size.z,
            behaviors: s.behaviors.iter().map(|b| &*b.name).collect(),
            look: s.def.look.resolve(&s.def.color, &s.def.body),
            behavior_info: crate::record::behavior_info(s),
        })
        .collect();
    serde_json::to_string(&WorldJson {
        bounds: Bounds {
            min: w.bounds.min.to_array(),
            max: w.bounds.max.to_array(),
        },
        obstacles,
        species,
        terrain: None,
        plans: [],
    })
    .unwrap_or_else(|_| "{}".into())
}

#[derive(Serialize, Default)]
struct FrameJson {
    tick: u64,
    time: f64,
    ids: Vec<u32>,
    species: Vec<u16>,
    behavior: Vec<u16>,
    pos: Vec<f32>,
    fwd: Vec<f32>,
    speed: Vec<f32>,
    stack_depth: Vec<u8>,
    hunger: Vec<f32>,
    libido: Vec<f32>,
    fear: Vec<f32>,
    swim_phase: Vec<f32>,
    tail_bend: Vec<f32>,
    food: Vec<f32>,
}

/// One frame of `run`: every agent's state (with a stride above [`MAX_FRAME_AGENTS`]) and the
/// food items.
pub fn frame_json(run: &Run) -> String {
    let w = &run.world;
    let set = &run.scenario.species;
    let stride = w.agents.len().div_ceil(MAX_FRAME_AGENTS).max(1);
    let n = w.agents.len().div_ceil(stride);
    let mut f = FrameJson {
        tick: w.tick,
        time: w.time(),
        ids: Vec::with_capacity(n),
        species: Vec::with_capacity(n),
        behavior: Vec::with_capacity(n),
        pos: Vec::with_capacity(3 * n),
        fwd: Vec::with_capacity(3 * n),
        speed: Vec::with_capacity(n),
        stack_depth: Vec::with_capacity(n),
        hunger: Vec::with_capacity(n),
        libido: Vec::with_capacity(n),
        fear: Vec::with_capacity(n),
        swim_phase: Vec::with_capacity(n),
        tail_bend: Vec::with_capacity(n),
        food: Vec::with_capacity(3 * w.food.len()),
    };
    for a in w.agents.iter().step_by(stride) {
        f.ids.push(a.id.0);
        f.species.push(a.species.0);
        f.behavior.push(a.mind.current);
        f.pos.extend(a.pos.to_array());
        f.fwd.extend(a.forward().to_array());
        f.speed.push(a.speed);
        f.stack_depth.push(a.mind.depth);
        f.hunger.push(a.drives.hunger);
        f.libido.push(a.drives.libido);
        f.fear.push(a.drives.fear);
        f.swim_phase.push(a.anim.phase);
        f.tail_bend.push(crate::locomotion::anim::bend_of(set, a));
    }
    for food in &w.food {
        f.food.extend(food.pos.to_array());
    }
    serde_json::to_string(&f).unwrap_or_else(|_| "{}".into())
}
