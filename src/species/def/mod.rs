//! The species file format: plain `*Def` types deserialized from RON (`behaviors/<name>.ron`).
//! [`super::validate`] turns them into the runtime [`super::Species`].
//!
//! Every constant has the papers' value as its default, so a species file only says what differs.
//! The steering recipes' parameter types are in [`recipe`].

use crate::drives::DriveParams;
pub use crate::events::MessageKind;
use crate::params::locomotion::AnimParams;
use crate::params::locomotion::{BodyLimits, Mode};
use crate::params::steering::AvoidParams;
use crate::perception::{Category, Level, Sector, SenseParams};
use crate::terrain::Mobility;
use glam::Vec3;
use serde::{Deserialize, Serialize};

pub mod events;
pub mod look;
pub mod memory;
pub mod recipe;
pub use events::{EventDef, FieldType, MessageRef};
pub use look::{LookDef, ShapeDef};
pub use memory::MemDecl;
pub use recipe::*;

/// A species file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Species")]
pub struct SpeciesDef {
    /// Unique name; agents and relations refer to it.
    pub name: String,
    /// Display color (`#rrggbb`) for viewers.
    #[serde(default = "default_color")]
    pub color: String,
    /// Body: size, limits, locomotion mode, animation.
    #[serde(default)]
    pub body: BodyDef,
    /// Senses.
    #[serde(default)]
    pub senses: SenseParams,
    /// Obstacle-avoidance constants used by `ObstacleNear`/`TrafficNear` and by `AvoidStatic()` /
    /// `AvoidDynamic()` written without parameters.
    #[serde(default)]
    pub avoid: AvoidParams,
    /// Attribute distributions for spawned agents.
    #[serde(default)]
    pub attributes: AttributesDef,
    /// Drive constants and initial values.
    #[serde(default)]
    pub drives: DrivesDef,
    /// What other species are to this one.
    #[serde(default)]
    pub relations: RelationsDef,
    /// The Rhai script of this species, relative to the species file.
    #[serde(default)]
    pub script: Option<String>,
    /// Script conditions and weights are re-evaluated every this many ticks (staggered over
    /// agents); native conditions run every tick.
    #[serde(default = "default_interval")]
    pub decision_interval: u32,
    /// An agent sends a message of a given kind on entering a behavior at most once per this
    /// many seconds (0: every entry). Seed 003's messages are warnings; a fish that re-enters
    /// escape does not warn its kin again every time.
    #[serde(default = "default_resend")]
    pub resend_after: f32,
    /// Name of the behavior agents start in and fall back to.
    pub initial: String,
    /// The behaviors, in declaration order (ties of priority go to the earlier one).
    pub behaviors: Vec<BehaviorDef>,
    /// Named recipes that scripts can compose (`this.recipe("school")`).
    #[serde(default)]
    pub recipes: std::collections::BTreeMap<String, Recipe>,
    /// How viewers draw the species (shape, size, colors); the engine does not read it.
    #[serde(default)]
    pub look: LookDef,
    /// Named events the species sends or reacts to (`Send("alarm_call", 8.0)`,
    /// `Heard("alarm_call")`), with their rank and payload fields.
    #[serde(default)]
    pub events: Vec<EventDef>,
    /// The blackboard keys its agents keep, with their types and start values; a script may
    /// use no other key.
    #[serde(default)]
    pub memory: std::collections::BTreeMap<String, MemDecl>,
}

fn default_color() -> String {
    "#4090e0".into()
}
fn default_interval() -> u32 {
    4
}
fn default_resend() -> f32 {
    2.0
}
fn default_min_time() -> f32 {
    0.5
}

/// Body of a species.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BodyDef {
    /// Bounding box (width, height, length).
    pub size: Vec3,
    /// Speed and turn limits.
    pub limits: BodyLimits,
    /// Kinematic or rigid-body locomotion.
    pub locomotion: Mode,
    /// Animation channel constants.
    pub anim: AnimParams,
    /// Whether the body walks on the terrain surface (2.5D) instead of swimming in 3D.
    pub on_ground: bool,
    /// Whether it rests with its axis upright (a jellyfish's bell): being at the pitch limit is
    /// its posture, not a nose stuck up or down, and run health does not warn of it.
    pub upright: bool,
    /// How a walking body moves over terrain (slope limit, what blocks and slows it): builds the
    /// species' cost grid for path planning and the cells it may never stand on.
    pub mobility: Mobility,
}

impl Default for BodyDef {
    fn default() -> Self {
        BodyDef {
            size: Vec3::new(0.2, 0.3, 1.0),
            limits: BodyLimits::default(),
            locomotion: Mode::Kinematic,
            anim: AnimParams::default(),
            on_ground: false,
            upright: false,
            mobility: Mobility::default(),
        }
    }
}

/// A value drawn per agent at spawn: a constant or a uniform range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Draw {
    /// Always this value.
    Fixed(f32),
    /// Uniform in [lo, hi).
    Uniform(f32, f32),
}

/// Sex of spawned agents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum SexDef {
    /// Half and half, drawn per agent.
    #[default]
    Random,
    /// All female.
    Female,
    /// All male.
    Male,
}

/// Attribute distributions (seed 003's ⟨sex, age, mass, type⟩).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AttributesDef {
    /// Sex.
    pub sex: SexDef,
    /// Age.
    pub age: Draw,
    /// Mass.
    pub mass: Draw,
    /// Type tag.
    pub kind: u16,
}

impl Default for AttributesDef {
    fn default() -> Self {
        AttributesDef {
            sex: SexDef::Random,
            age: Draw::Fixed(1.0),
            mass: Draw::Fixed(1.0),
            kind: 0,
        }
    }
}

/// Drives of a species.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DrivesDef {
    /// Constants of the drive formulas.
    pub params: DriveParams,
    /// Initial hunger.
    pub hunger: Draw,
    /// Initial libido.
    pub libido: Draw,
    /// Initial time since the last meal (s): sets where digestion starts.
    pub since_meal: Draw,
    /// Food units one meal adds to n_e.
    pub meal_size: f32,
    /// Whether drives follow the formulas each tick (off: only scripts change them).
    pub native: bool,
}

impl Default for DrivesDef {
    fn default() -> Self {
        DrivesDef {
            params: DriveParams::default(),
            hunger: Draw::Fixed(0.5),
            libido: Draw::Fixed(0.0),
            since_meal: Draw::Fixed(0.0),
            meal_size: 1.0,
            native: true,
        }
    }
}

/// Relations to other species (seed 000's food, predator, kin, mate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RelationsDef {
    /// Species this one eats.
    pub prey: Vec<String>,
    /// Whether it eats food items.
    pub eats_items: bool,
    /// Species that eat this one.
    pub predators: Vec<String>,
    /// Species it schools with (its own species is always kin).
    pub kin: Vec<String>,
    /// Whether kin of the other sex count as mates.
    pub mates: bool,
    /// Whether other species not named count as "other" (dynamic obstacles) or are ignored.
    pub see_others: bool,
}

impl Default for RelationsDef {
    fn default() -> Self {
        RelationsDef {
            prey: Vec::new(),
            eats_items: false,
            predators: Vec::new(),
            kin: Vec::new(),
            mates: false,
            see_others: true,
        }
    }
}

/// One behavior of the prioritized FSM (seed 000 §3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Behavior")]
pub struct BehaviorDef {
    /// Unique name within the species.
    pub name: String,
    /// Priority level: 1 is the highest. Higher levels interrupt lower ones. Required in a
    /// prioritized list (the species' `behaviors`, a behavior's `behaviors`); steps of a
    /// `sequence` or `fallback` run in order and take none.
    #[serde(default)]
    pub priority: u8,
    /// Activation condition.
    #[serde(default = "never")]
    pub when: Cond,
    /// Completion condition: the behavior ends with success.
    #[serde(default = "never")]
    pub done: Cond,
    /// Failure condition: the behavior ends with failure (when `done` does not hold; not held
    /// back by `min_time`).
    #[serde(default = "never")]
    pub fail: Cond,
    /// Steering recipe (a behavior made of sub-behaviors or steps has none: theirs steers).
    #[serde(default)]
    pub steer: Option<Recipe>,
    /// Sub-behaviors: a prioritized list of its own, with the same interrupt and stack rules
    /// as the species' list, run while this behavior is current.
    #[serde(default)]
    pub behaviors: Vec<BehaviorDef>,
    /// Steps run in order: each success starts the next, the last one's success is this
    /// behavior's success, any step's failure is its failure.
    #[serde(default)]
    pub sequence: Vec<BehaviorDef>,
    /// Steps tried in order: each failure starts the next, the last one's failure is this
    /// behavior's failure, any step's success is its success.
    #[serde(default)]
    pub fallback: Vec<BehaviorDef>,
    /// The sibling behavior (same list) to start when this one succeeds, in place of the
    /// list's own rule.
    #[serde(default)]
    pub on_success: Option<String>,
    /// The sibling behavior to start when this one fails.
    #[serde(default)]
    pub on_failure: Option<String>,
    /// Whether a behavior of the same level may interrupt this one.
    #[serde(default = "yes")]
    pub equal_may_interrupt: bool,
    /// Minimum time (s) in this behavior before it completes or an equal or lower level
    /// interrupts it (anti-dithering). Higher levels always interrupt. Half a second unless
    /// said: an episode shorter than that reads as flicker, not as a decision.
    #[serde(default = "default_min_time")]
    pub min_time: f32,
    /// Time (s) after it completes before it may start again.
    #[serde(default)]
    pub cooldown: f32,
    /// What happens on contact with the target while in this behavior.
    #[serde(default)]
    pub contact: Option<Contact>,
    /// Actions when the behavior starts or resumes.
    #[serde(default)]
    pub on_enter: Vec<Action>,
    /// The body's turn `response` (s) while this behavior runs, in place of the species' own
    /// (`body.limits.response`): a schooling fish that turns gently among its neighbours still
    /// snaps away from a predator.
    #[serde(default)]
    pub response: Option<f32>,
    /// The focuser of seed 000 §1: the categories this behavior's steering reads while it is
    /// current (`None`: everything). Conditions still read everything.
    #[serde(default)]
    pub focus: Option<Vec<Category>>,
}

fn never() -> Cond {
    Cond::Never
}
fn yes() -> bool {
    true
}

/// What contact with the nearest target does (seed 000: eat and mate end in contact).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Contact {
    /// Eat the nearest food (item or prey agent) within `reach`.
    Eat {
        /// Contact distance d0.
        reach: f32,
    },
    /// Mate with the nearest mate within `reach`.
    Mate {
        /// Contact distance.
        reach: f32,
    },
}

/// An action on entering a behavior.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Action {
    /// Broadcast a message (a built-in kind or a declared event) to agents within `radius`:
    /// of the same species, or also of others that declare a `shared` event.
    Send(MessageRef, f32),
    /// Call a script function (with the agent as `this`).
    Call(String),
    /// Remember where the agent is now as its station (`HoldStation`, `Target::Station`,
    /// `AtStation` read it), until it marks another.
    MarkStation,
}

/// A drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum DriveKind {
    /// Hunger.
    Hunger,
    /// Libido.
    Libido,
    /// Fear.
    Fear,
    /// Fatigue.
    Fatigue,
    /// Seed 003 internal state S(t).
    State,
}

/// An attribute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum AttrKind {
    /// Age.
    Age,
    /// Mass.
    Mass,
}

/// A number read from the agent's state, for conditions and blend weights.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Value {
    /// A constant.
    Const(f32),
    /// A drive.
    Drive(DriveKind),
    /// Distance to the nearest percept of a category (∞ when none).
    Distance(Category),
    /// Number of percepts of a category.
    Count(Category),
    /// Perceived strength of the nearest percept of a category (seed 001): 1 within
    /// `senses.strength.near`, `(near/d)^power` beyond, 0 when none.
    Strength(Category),
    /// Own speed.
    Speed,
    /// Seconds in the current behavior.
    TimeInBehavior,
    /// An attribute.
    Attribute(AttrKind),
    /// Mean speed of the school around (kin mean velocity length).
    KinSpeed,
    /// `1 − value`.
    OneMinus(Box<Value>),
    /// Product of two values.
    Mul(Box<Value>, Box<Value>),
    /// Sum of two values.
    Add(Box<Value>, Box<Value>),
    /// A Rhai function returning a number (evaluated at the decision rate).
    Script(String),
}

/// A condition: typed data, resolved at load time into a native evaluator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Cond {
    /// Always true.
    Always,
    /// Never true.
    Never,
    /// All of them.
    All(Vec<Cond>),
    /// Any of them.
    Any(Vec<Cond>),
    /// The opposite.
    Not(Box<Cond>),
    /// `value > threshold`.
    Above(Value, f32),
    /// `value < threshold`.
    Below(Value, f32),
    /// Latched: turns true when `on` holds and stays true until `off` holds (hysteresis).
    Latch {
        /// Turn-on condition.
        on: Box<Cond>,
        /// Turn-off condition.
        off: Box<Cond>,
    },
    /// Something of this category is seen (vision).
    Sees(Category),
    /// Something of this category is smelt only.
    Smells(Category),
    /// Something of this category is perceived by any sense.
    Perceives(Category),
    /// The nearest of this category is within `d` (e.g. the catch distance d0).
    Within(Category, f32),
    /// The nearest of this category lies in one of these horizontal sectors (seed 000 §4.3–4.4,
    /// bounds `senses.sectors`); false when none is perceived.
    InSector(Category, Vec<Sector>),
    /// The nearest of this category lies at one of these levels (above, level, below; seed 000
    /// §4.3–4.4, band `senses.sectors.front`); false when none is perceived.
    AtLevel(Category, Vec<Level>),
    /// Seed 000 §4.4's escape completion test on the nearest predator (or none perceived).
    EscapeDone,
    /// Static obstacle pressure above M_min (seed 000 §4.1): an obstacle must be avoided.
    ObstacleNear,
    /// Dynamic obstacle pressure above M_min (seed 000 §4.2).
    TrafficNear,
    /// A message of this kind (or this declared event) arrived last tick.
    Heard(MessageRef),
    /// Seconds in the current behavior at least this.
    TimeIn(f32),
    /// True with this probability per second (drawn from the agent's own stream).
    Chance(f32),
    /// Outside the world bounds shrunk by this margin.
    NearBounds(f32),
    /// A Rhai function returning a bool (evaluated at the decision rate).
    Script(String),
    /// The current behavior's `contact` happened (it ate, caught or mated).
    Contacted,
    /// Within this distance of its station (`MarkStation`); false while it has none.
    AtStation(f32),
}
