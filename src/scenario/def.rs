//! The scenario file format (`scenarios/*.ron`): plain `*Def` types read with RON.

use crate::species::Draw;
use crate::world::Aabb;
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A scenario file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Scenario")]
pub struct ScenarioDef {
    /// Name (defaults to the file stem).
    #[serde(default)]
    pub name: Option<String>,
    /// Run seed.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Fixed time step (s).
    #[serde(default = "default_dt")]
    pub dt: f32,
    /// Duration (s).
    pub duration: f32,
    /// World bounds.
    pub bounds: Aabb,
    /// Uniform current (world units / s).
    #[serde(default)]
    pub current: Vec3,
    /// Folder of species files, relative to the scenario file (default `../behaviors`).
    #[serde(default)]
    pub behaviors: Option<String>,
    /// Species to load, by name (`<behaviors>/<name>.ron`).
    pub species: Vec<String>,
    /// Static obstacles; their index is their id.
    #[serde(default)]
    pub obstacles: Vec<ObstacleDef>,
    /// Food.
    #[serde(default)]
    pub food: FoodDef,
    /// Agent groups spawned at t = 0.
    #[serde(default)]
    pub groups: Vec<SpawnGroupDef>,
    /// Timed events.
    #[serde(default)]
    pub events: Vec<TimedEvent>,
    /// Recording options.
    #[serde(default)]
    pub record: RecordDef,
    /// Expectations checked at the end of a run (`shoal test` and `shoal run` report them).
    #[serde(default)]
    pub expect: Vec<Expectation>,
    /// Terrain (for walking species and squads).
    #[serde(default)]
    pub terrain: Option<TerrainDef>,
    /// Squads that plan formation-keeping paths over the terrain.
    #[serde(default)]
    pub squads: Vec<SquadDef>,
}

fn default_seed() -> u64 {
    1
}
fn default_dt() -> f32 {
    0.05
}

/// A static obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum ObstacleDef {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// An axis-aligned box.
    Box {
        /// Smallest corner.
        min: Vec3,
        /// Largest corner.
        max: Vec3,
    },
    /// An upright cylinder: a disc of `radius` around `base`, extruded up by `height`
    /// (seed 001's cylinder bounds).
    Cylinder {
        /// Centre of the bottom disc.
        base: Vec3,
        /// Radius.
        radius: f32,
        /// Height.
        height: f32,
    },
}

impl ObstacleDef {
    /// The world's shape of this obstacle.
    pub fn shape(&self) -> crate::world::Shape {
        match *self {
            ObstacleDef::Sphere { center, radius } => {
                crate::world::Shape::Sphere { center, radius }
            }
            ObstacleDef::Box { min, max } => {
                crate::world::Shape::Box(crate::world::Aabb::new(min, max))
            }
            ObstacleDef::Cylinder {
                base,
                radius,
                height,
            } => crate::world::Shape::Cylinder {
                base,
                radius,
                height,
            },
        }
    }
}

/// Food: initial items and respawning.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FoodDef {
    /// Items at t = 0.
    pub initial: u32,
    /// Where food appears (default: the world bounds).
    pub region: Option<Aabb>,
    /// New items per second.
    pub respawn_per_second: f32,
    /// Never more items than this.
    pub max: u32,
}

impl Default for FoodDef {
    fn default() -> Self {
        FoodDef {
            initial: 0,
            region: None,
            respawn_per_second: 0.0,
            max: 1000,
        }
    }
}

/// Initial headings of a group.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum HeadingDef {
    /// Random yaw, level.
    #[default]
    Random,
    /// All facing this yaw (degrees; 0 = +Z, positive to the right).
    Yaw(f32),
    /// All facing this point.
    Toward(Vec3),
}

/// Initial drive overrides of a group.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct DrivesOverride {
    /// Hunger.
    pub hunger: Option<Draw>,
    /// Libido.
    pub libido: Option<Draw>,
    /// Fear.
    pub fear: Option<Draw>,
    /// Fatigue.
    pub fatigue: Option<Draw>,
}

/// A group of agents of one species.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpawnGroupDef {
    /// Species name.
    pub species: String,
    /// The group's name, for expectations about one group (`GroupCatches("ambushers", 3)`);
    /// the species name when not given. Groups sharing a name count as one group.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// How many.
    pub count: i64,
    /// Spawn region (inside the bounds).
    pub region: Aabb,
    /// Headings.
    #[serde(default)]
    pub heading: HeadingDef,
    /// Drive overrides.
    #[serde(default)]
    pub drives: DrivesOverride,
}

impl SpawnGroupDef {
    /// The group's name: its `name`, else its species.
    pub fn group_name(&self) -> &str {
        self.name.as_deref().unwrap_or(&self.species)
    }
}

/// Something that happens at a given time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimedEvent {
    /// Time (s).
    pub at: f32,
    /// What.
    pub action: EventAction,
}

/// A timed event's action.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum EventAction {
    /// Spawn a group.
    Spawn(SpawnGroupDef),
    /// Remove the obstacle with this id.
    RemoveObstacle(u32),
    /// Drop food.
    DropFood {
        /// How many items.
        count: u32,
        /// Where.
        region: Aabb,
    },
    /// Change the current.
    SetCurrent(Vec3),
}

/// Recording options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RecordDef {
    /// Record every this many ticks.
    pub interval: u32,
    /// Also record `explain.jsonl` (why each agent moves as it does; `shoal run --explain`).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub explain: bool,
}

impl Default for RecordDef {
    fn default() -> Self {
        RecordDef {
            interval: 1,
            explain: false,
        }
    }
}

/// An end-of-run expectation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Expectation {
    /// At least `fraction` of the agents of `species` are in `behavior` at some tick within
    /// `within` seconds after `after` seconds.
    BehaviorShare {
        /// Species.
        species: String,
        /// Behavior.
        behavior: String,
        /// Fraction in [0, 1].
        fraction: f32,
        /// Start of the window (s).
        after: f32,
        /// Length of the window (s).
        within: f32,
    },
    /// At least this many catches by the end.
    MinCatches(u64),
    /// At least this many meals by the end.
    MinMeals(u64),
    /// At least this many catches by agents of one species by the end: `SpeciesCatches("shark", 3)`.
    SpeciesCatches(String, u64),
    /// At least this many meals by agents of one species by the end: `SpeciesMeals("reef_fish", 5)`.
    SpeciesMeals(String, u64),
    /// At least this many catches by agents of one named group (see [`SpawnGroupDef::name`]) by
    /// the end: `GroupCatches("ambushers", 3)`.
    GroupCatches(String, u64),
    /// At least this many meals by agents of one named group by the end:
    /// `GroupMeals("school", 5)`.
    GroupMeals(String, u64),
    /// At least this many agents of one named group alive at the end: `GroupMinAlive("school", 10)`.
    GroupMinAlive(String, u64),
    /// At most this many agents of one named group alive at the end: `GroupMaxAlive("bait", 0)`.
    GroupMaxAlive(String, u64),
    /// At least this many agents of a species alive at the end.
    MinAlive(String, u64),
    /// At most this many agents of a species alive at the end.
    MaxAlive(String, u64),
    /// The polarization of a species (|mean heading|, 1 = aligned) is at least this at the end.
    MinPolarization(String, f32),
    /// No script errors.
    NoScriptErrors,
    /// At most this many agents of a species frozen: stopped (speed < 0.05) for 5 s or more in
    /// a behavior whose steering asks to move (run health, [`crate::health`]).
    MaxFrozen(String, u64),
    /// At most this many behavior transitions per agent of a species per second.
    MaxSwitchRate(String, f32),
    /// At most this fraction of a species' agent-ticks at the pitch limit.
    MaxPitchLimitShare(String, f32),
    /// At most this fraction of a species' completed behavior episodes shorter than 0.5 s.
    MaxShortEpisodes(String, f32),
    /// At most this turning waste (turning ÷ net heading change over 1-s windows, ≥ 1).
    MaxTurningWaste(String, f32),
    /// At most this fraction of a species' neighbor pairs overlapping by more than 10 % of the
    /// body width.
    MaxInterpenetration(String, f32),
    /// At most this many agent-ticks of a species inside an obstacle or within half a body
    /// width of it.
    MaxObstaclePenetration(String, u64),
}

/// Terrain of a scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerrainDef {
    /// Elevation file, relative to the scenario file: an ESRI ASCII grid (`.asc`) or a binary
    /// PGM height map (`.pgm`, which also needs `cell_size` and `height_scale`).
    pub dem: String,
    /// Feature file (RON), relative to the scenario file.
    #[serde(default)]
    pub features: Option<String>,
    /// PGM only: metres per pixel (an ESRI grid gives its own `cellsize`).
    #[serde(default)]
    pub cell_size: Option<f32>,
    /// PGM only: metres of height per sample unit (height = sample × `height_scale`).
    #[serde(default)]
    pub height_scale: Option<f32>,
}

/// A squad: members of one species that plan a formation-keeping path to a goal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SquadDef {
    /// Species of the members.
    pub species: String,
    /// Members.
    pub count: u32,
    /// Start (x, z) of the leader.
    pub start: (f32, f32),
    /// Goal (x, z).
    pub goal: (f32, f32),
    /// Formations allowed, widest first (e.g. `["wedge", "column"]`).
    pub formations: Vec<String>,
    /// Task class: `MustKeep`, `MayChangeRarely`, `ShortestFirst`.
    pub task: String,
    /// Slot spacing (world units).
    #[serde(default = "default_spacing")]
    pub spacing: f32,
    /// Seed 004's planning constants: relaxation step, `fm_broken`, whether K2 is the share of
    /// followers that must fit, and the task classes' `(k1, k2)`; the source's values by default.
    #[serde(default)]
    pub planning: crate::formation::PlanningParams,
    /// How the leader is chosen, once (seed 004: by slot, by role, or at random); slot 0 by
    /// default.
    #[serde(default)]
    pub leader: SquadLeader,
    /// One role name per member, for `leader: Role("…")` (empty: no roles).
    #[serde(default)]
    pub roles: Vec<String>,
}

/// How a squad's leader is chosen (seed 004); the choice is kept for the whole run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum SquadLeader {
    /// The member in this slot (0-based): `Slot(2)`.
    Slot(usize),
    /// The first member with this role in `roles`: `Role("scout")`.
    Role(String),
    /// A member drawn from the scenario's seed (the squad's own stream): the same scenario and
    /// seed always give the same leader.
    Random,
}

impl Default for SquadLeader {
    fn default() -> Self {
        SquadLeader::Slot(0)
    }
}

impl SquadLeader {
    /// The leader's member index among `count` members with `roles` (empty or one per member);
    /// `seed` and `squad` select the random stream. `Err` says what is wrong.
    pub fn resolve(
        &self,
        count: usize,
        roles: &[String],
        seed: u64,
        squad: usize,
    ) -> Result<usize, String> {
        match self {
            SquadLeader::Slot(s) if *s < count => Ok(*s),
            SquadLeader::Slot(s) => Err(format!(
                "leader slot {s} is out of range: the squad has {count} members (slots 0 to {})",
                count.saturating_sub(1)
            )),
            SquadLeader::Role(r) => roles.iter().position(|x| x == r).ok_or_else(|| {
                if roles.is_empty() {
                    format!("leader role \"{r}\" needs `roles: [...]`, one per member")
                } else {
                    format!(
                        "no member has the role \"{r}\"; the roles are {}",
                        roles.join(", ")
                    )
                }
            }),
            SquadLeader::Random => {
                let mut rng = crate::world::Rng::new(seed, LEADER_STREAM + squad as u64);
                Ok((rng.next_f32() * count as f32) as usize % count.max(1))
            }
        }
    }
}

/// Base of the random streams squads draw a leader from (one stream per squad).
pub const LEADER_STREAM: u64 = 0x1EAD_E700_0000;

fn default_spacing() -> f32 {
    4.0
}
