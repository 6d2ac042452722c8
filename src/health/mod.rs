//! Run health: figures that tell a designer when a species misbehaves (agents that stop where
//! they should swim, flicker between behaviors, turn back and forth, crowd into each other or
//! into rocks).
//!
//! Not a tick stage: a layer above the run, like scenario expectations. A [`Monitor`] is built
//! once from the species, fed the world and the tick's events after every tick
//! ([`Monitor::observe`], cheap enough to leave on in every run) and asked for a [`Health`]
//! report at the end ([`Monitor::report`]). The report is plain data (serde), written as
//! `health.json` into a run folder; [`Health::warnings`] turns its figures into designer-facing
//! lines, each with a tick and an agent to look at.
//!
//! Each figure, its default bound, and what it measures:
//!
//! | figure | bound | what |
//! |---|---|---|
//! | stopped share | [`MAX_STOPPED_SHARE`] | agent-ticks slower than [`STOPPED_SPEED`], in behaviors whose steering asks to move |
//! | frozen agents | [`MAX_FROZEN`] | agents stopped ≥ [`FROZEN_SECONDS`] in one such behavior |
//! | pitch-limit share | [`MAX_PITCH_LIMIT_SHARE`] | agent-ticks with \|pitch\| ≥ the limit − [`PITCH_LIMIT_MARGIN`] (no bound for an `upright` body) |
//! | switch rate | [`MAX_SWITCH_RATE`] | behavior transitions per agent per second |
//! | short episodes | [`MAX_SHORT_EPISODE_SHARE`] | completed behavior episodes shorter than [`SHORT_EPISODE_SECONDS`] (held to the bound from [`MIN_EPISODES`] episodes) |
//! | turning waste | [`MAX_TURNING_WASTE`] | turning ÷ net heading change over [`TURN_WINDOW_SECONDS`] windows |
//! | coincident pairs | [`MAX_COINCIDENT`] | pairs of agents closer than [`COINCIDENT_DISTANCE`] |
//! | overlap share | [`MAX_OVERLAP_SHARE`] | same-species neighbor pairs closer than [`OVERLAP_WIDTH`] × body width |
//! | obstacle penetration | [`MAX_OBSTACLE_PENETRATION`] | agent-ticks inside an obstacle or within half a body width of it |

mod monitor;
mod pairs;
mod warnings;

pub use monitor::{may_stop, Monitor};
pub use warnings::{percent, thousands, Figure, Warning};

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Name of the report in a run folder.
pub const FILE: &str = "health.json";

/// Version of the report's format (`format` in `health.json`).
pub const FORMAT: u32 = 1;

/// Below this speed (world units / s) an agent counts as stopped.
pub const STOPPED_SPEED: f32 = 0.05;
/// Largest share of stopped agent-ticks in a behavior that asks to move.
pub const MAX_STOPPED_SHARE: f64 = 0.05;
/// Stopped this long (s) without a break, in a behavior that asks to move, an agent is frozen.
pub const FROZEN_SECONDS: f64 = 5.0;
/// Most frozen agents per species.
pub const MAX_FROZEN: u64 = 0;
/// An agent within this much (rad) of its species' pitch limit is at the limit.
pub const PITCH_LIMIT_MARGIN: f32 = 0.01;
/// Largest share of agent-ticks at the pitch limit.
pub const MAX_PITCH_LIMIT_SHARE: f64 = 0.05;
/// Most behavior transitions per agent per second.
pub const MAX_SWITCH_RATE: f64 = 0.5;
/// Fewest episodes a species needs before its short-episode share is held to the bound: two
/// sharks' ten episodes, two of them a quick reaction to prey, say nothing about flicker.
pub const MIN_EPISODES: u64 = 20;
/// A behavior episode shorter than this (s) is short.
pub const SHORT_EPISODE_SECONDS: f64 = 0.5;
/// Largest share of short episodes.
pub const MAX_SHORT_EPISODE_SHARE: f64 = 0.10;
/// A→B then B→A within this time (s) is a flip.
pub const FLIP_SECONDS: f64 = 0.5;
/// Length (s) of the windows turning waste is measured over.
pub const TURN_WINDOW_SECONDS: f64 = 1.0;
/// Largest turning waste (turning ÷ net heading change).
pub const MAX_TURNING_WASTE: f64 = 2.0;
/// Two agents closer than this (world units) coincide.
pub const COINCIDENT_DISTANCE: f32 = 0.02;
/// Most coincident pairs in a sampled tick.
pub const MAX_COINCIDENT: u64 = 0;
/// Same-species agents whose centres are closer than this many body lengths are neighbors.
pub const NEIGHBOR_LENGTHS: f32 = 2.0;
/// Neighbors whose centres are closer than this many body widths overlap (deeper than 10 % of
/// the width).
pub const OVERLAP_WIDTH: f32 = 0.9;
/// Largest share of overlapping neighbor pairs.
pub const MAX_OVERLAP_SHARE: f64 = 0.01;
/// Most agent-ticks inside or within half a body width of an obstacle.
pub const MAX_OBSTACLE_PENETRATION: u64 = 0;
/// A frozen agent is placed at the nearest obstacle within this distance (world units), else at
/// the nearest agent.
pub const NEAR_OBSTACLE: f32 = 5.0;
/// Pair figures (coincident, overlap) are sampled every this many ticks.
pub const PAIR_INTERVAL: u64 = 5;
/// Frozen episodes kept as examples per species (the longest).
pub const FROZEN_EXAMPLES: usize = 20;
/// Flip pairs kept per species (the most frequent).
pub const TOP_FLIPS: usize = 5;

/// Where to look: an agent at a tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Spot {
    /// Tick (the state after this many ticks).
    pub tick: u64,
    /// Agent id.
    pub agent: u32,
}

/// What a frozen agent was next to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NextTo {
    /// The nearest active obstacle, within [`NEAR_OBSTACLE`].
    Obstacle {
        /// Obstacle id (its index in the scenario).
        id: u32,
        /// "sphere 2", "box 4".
        label: String,
        /// Distance from the agent's centre to its surface (0 inside).
        distance: f32,
    },
    /// No obstacle that close: the nearest other agent.
    Agent {
        /// Its id.
        id: u32,
        /// Its species.
        species: String,
        /// Distance between the centres.
        distance: f32,
    },
    /// Nothing else in the world.
    Nothing,
}

impl NextTo {
    /// Short text: "box 4", "near sardine #12", "alone".
    pub fn label(&self) -> String {
        match self {
            NextTo::Obstacle { label, .. } => label.clone(),
            NextTo::Agent { id, species, .. } => format!("near {species} #{id}"),
            NextTo::Nothing => "alone".to_string(),
        }
    }
}

/// One frozen episode: an agent stopped ≥ [`FROZEN_SECONDS`] in a behavior that asks to move.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Frozen {
    /// Agent id.
    pub agent: u32,
    /// The behavior it was in.
    pub behavior: String,
    /// First tick it was stopped.
    pub start_tick: u64,
    /// How long it stayed stopped (s); an episode still going at the end counts to the end.
    pub seconds: f64,
    /// Where it was.
    pub pos: Vec3,
    /// What it was next to.
    pub near: NextTo,
}

/// A → B followed by B → A for the same agent within [`FLIP_SECONDS`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Flip {
    /// One behavior (the first one left, the first time the pair flipped).
    pub a: String,
    /// The other.
    pub b: String,
    /// How many times.
    pub count: u64,
    /// The first time.
    pub first: Spot,
}

/// Where frozen agents of a behavior stood, and how many.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrozenAt {
    /// An obstacle ("box 4") or "open water" (no obstacle within [`NEAR_OBSTACLE`]).
    pub place: String,
    /// Agents.
    pub agents: u64,
}

/// Figures of one behavior of a species.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BehaviorHealth {
    /// Behavior name.
    pub name: String,
    /// Whether its steering may stop the agent (it has a `Stop`, `Arrive` or `FollowPlan`
    /// recipe): stopping there is not a problem.
    pub may_stop: bool,
    /// Agent-ticks spent in it.
    pub agent_ticks: u64,
    /// Share of those with speed < [`STOPPED_SPEED`].
    pub stopped_share: f64,
    /// The longest stop in it.
    pub longest_stop: Option<Spot>,
    /// Distinct agents frozen in it.
    pub frozen_agents: u64,
    /// Where they were frozen (each agent's first frozen episode in it), most agents first.
    pub frozen_at: Vec<FrozenAt>,
    /// The longest frozen episode in it.
    pub longest_frozen: Option<Spot>,
}

/// Agents in or against obstacles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Penetration {
    /// Agent-ticks with the centre inside an active obstacle or closer to its surface than
    /// half the body width.
    pub agent_ticks: u64,
    /// Agent-ticks with the centre inside.
    pub inside_ticks: u64,
    /// Distinct agents that were ever inside.
    pub agents_inside: u64,
    /// The worst case: the smallest signed distance from a centre to an obstacle's surface
    /// (world units, negative inside).
    pub closest: Option<f32>,
    /// Where the worst case was.
    pub closest_at: Option<Spot>,
    /// Which obstacle ("sphere 2").
    pub closest_obstacle: Option<String>,
}

/// The figures of one species.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpeciesHealth {
    /// Species name.
    pub name: String,
    /// Distinct agents seen.
    pub agents: u64,
    /// Agent-ticks observed.
    pub agent_ticks: u64,
    /// Share of agent-ticks stopped, in behaviors that do not [`may_stop`].
    pub stopped_share: f64,
    /// Distinct agents frozen (in any behavior).
    pub frozen_agents: u64,
    /// Frozen episodes.
    pub frozen_episodes: u64,
    /// Share of agent-ticks at the pitch limit.
    pub pitch_limit_share: f64,
    /// The species rests upright (`body.upright`): its pitch-limit share has no bound.
    #[serde(default)]
    pub upright: bool,
    /// The longest stretch an agent spent at the pitch limit.
    pub pitch_limit_at: Option<Spot>,
    /// Behavior transitions.
    pub transitions: u64,
    /// Behavior transitions per agent per second.
    pub switch_rate: f64,
    /// The agent with the most transitions (at its last one).
    pub most_switches_at: Option<Spot>,
    /// Completed behavior episodes (from one transition of an agent to its next).
    pub episodes: u64,
    /// Share of them shorter than [`SHORT_EPISODE_SECONDS`].
    pub short_episode_share: f64,
    /// Share of them that lasted a single tick (or less).
    pub one_tick_share: f64,
    /// The first short episode.
    pub short_episode_at: Option<Spot>,
    /// The most frequent flips, most first (at most [`TOP_FLIPS`]).
    pub flips: Vec<Flip>,
    /// Σ turning over all complete windows (rad).
    pub turning: f64,
    /// Σ net heading change over the same windows (rad).
    pub net_turning: f64,
    /// `turning / net_turning` (1 = every turn went toward the new heading); `None` when the
    /// heading never changed.
    pub turning_waste: Option<f64>,
    /// The window that wasted the most (its start).
    pub turning_waste_at: Option<Spot>,
    /// Same-species neighbor pairs counted over the sampled ticks.
    pub neighbor_pairs: u64,
    /// Of those, pairs closer than [`OVERLAP_WIDTH`] × body width.
    pub overlapping_pairs: u64,
    /// `overlapping_pairs / neighbor_pairs`.
    pub overlap_share: f64,
    /// The sampled tick with the most overlapping pairs (one agent of one of them).
    pub overlap_at: Option<Spot>,
    /// Agents in or against obstacles.
    pub obstacles: Penetration,
    /// Messages sent.
    pub messages: u64,
    /// Messages per agent per second.
    pub messages_per_agent_second: f64,
    /// Per behavior, in the species' order.
    pub behaviors: Vec<BehaviorHealth>,
    /// The longest frozen episodes (at most [`FROZEN_EXAMPLES`]).
    pub frozen: Vec<Frozen>,
}

impl SpeciesHealth {
    /// Whether `figure` is held to its bound for this species: not the pitch limit of an
    /// upright body, nor the short-episode share of fewer than [`MIN_EPISODES`] episodes (the
    /// figures are reported either way; scenario expectations check them as written).
    pub fn judged(&self, figure: Figure) -> bool {
        match figure {
            Figure::PitchLimit => !self.upright,
            Figure::ShortEpisodes => self.episodes >= MIN_EPISODES,
            _ => true,
        }
    }

    /// Why `figure` is not held to its bound for this species (`None` when it is), in words for
    /// the tables that show it anyway.
    pub fn not_judged_because(&self, figure: Figure) -> Option<String> {
        if self.judged(figure) {
            return None;
        }
        Some(match figure {
            Figure::PitchLimit => "an upright body: its pitch is its posture".to_string(),
            _ => format!(
                "only {} episode{}, judged from {MIN_EPISODES}",
                self.episodes,
                if self.episodes == 1 { "" } else { "s" }
            ),
        })
    }

    /// Agent-ticks inside or against obstacles (the figure `MaxObstaclePenetration` bounds).
    pub fn obstacle_penetration(&self) -> u64 {
        self.obstacles.agent_ticks
    }
}

/// Coincident agents (any species), over the sampled ticks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Coincident {
    /// Ticks sampled.
    pub samples: u64,
    /// Mean coincident pairs per sampled tick.
    pub mean: f64,
    /// Most coincident pairs in one sampled tick.
    pub max: u64,
    /// That tick, and one agent of a pair.
    pub max_at: Option<Spot>,
}

/// The health report of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Health {
    /// Report format ([`FORMAT`]).
    pub format: u32,
    /// Time step (s).
    pub dt: f32,
    /// Ticks observed.
    pub ticks: u64,
    /// Pair figures were sampled every this many ticks.
    pub pair_interval: u64,
    /// Per species, in the species set's order.
    pub species: Vec<SpeciesHealth>,
    /// Coincident agents.
    pub coincident: Coincident,
}

impl Health {
    /// The figures of the species named `name`.
    pub fn species(&self, name: &str) -> Option<&SpeciesHealth> {
        self.species.iter().find(|s| s.name == name)
    }

    /// The report as JSON, with its [`Health::warnings`] under `warnings` (for readers that do
    /// not compute them; reading the JSON back as a [`Health`] ignores them).
    pub fn to_json(&self) -> serde_json::Value {
        let mut v = serde_json::to_value(self).unwrap_or(serde_json::Value::Null);
        if let Some(o) = v.as_object_mut() {
            o.insert(
                "warnings".into(),
                serde_json::to_value(self.warnings()).unwrap_or_default(),
            );
        }
        v
    }

    /// The headline figures per species and the warnings: what a run's manifest summary keeps.
    pub fn headline(&self) -> serde_json::Value {
        let species: serde_json::Map<String, serde_json::Value> = self
            .species
            .iter()
            .map(|s| {
                (
                    s.name.clone(),
                    serde_json::json!({
                        "stopped_share": round(s.stopped_share, 4),
                        "frozen_agents": s.frozen_agents,
                        "pitch_limit_share": round(s.pitch_limit_share, 4),
                        "switch_rate": round(s.switch_rate, 3),
                        "short_episode_share": round(s.short_episode_share, 4),
                        "turning_waste": s.turning_waste.map(|w| round(w, 3)),
                        "overlap_share": round(s.overlap_share, 4),
                        "obstacle_penetration": s.obstacles.agent_ticks,
                        "messages_per_agent_second": round(s.messages_per_agent_second, 3),
                    }),
                )
            })
            .collect();
        serde_json::json!({
            "species": species,
            "coincident_max": self.coincident.max,
            "warnings": self.warnings().iter().map(|w| w.message.clone()).collect::<Vec<_>>(),
        })
    }
}

fn round(x: f64, digits: i32) -> f64 {
    // Exact for the few digits asked (`powi`'s precision is unspecified).
    let k = (0..digits).fold(1.0f64, |k, _| k * 10.0);
    (x * k).round() / k
}

/// `a / b`, 0 when `b` is 0.
fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 {
        a / b
    } else {
        0.0
    }
}
