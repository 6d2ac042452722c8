//! Species as data: RON species files and their Rhai scripts, loaded and validated once per
//! (re)load into the runtime [`Species`] the decision stage runs. Nothing in the tick parses or
//! looks up by string what is resolved here.
//!
//! In the core's layers (`tests/layers.rs`) the species sits above what it is built from (the
//! perception and drive types, the later stages' parameter types in [`crate::params`], scripts)
//! and below the stages that read it (`ctx`, steering, decision, the tick).

mod blackboard;
pub mod compose;
mod conditions;
pub mod def;
pub mod describe;
pub mod events;
mod look_check;
mod params;
mod recipes;
pub mod seeds;
pub mod set;
pub mod validate;

pub use def::*;
pub use events::EventSpec;
pub use set::SpeciesSet;
pub use validate::{load_species, load_species_str};

use crate::load::Diagnostics;
use crate::params::steering::AvoidParams;
use crate::perception::{Category, SenseParams};
use crate::script::Script;
use crate::world::Signal;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A number read from the agent's state, resolved.
#[derive(Debug, Clone, PartialEq)]
pub enum ValueNode {
    /// A constant.
    Const(f32),
    /// A drive.
    Drive(DriveKind),
    /// Distance to the nearest of a category.
    Distance(Category),
    /// Count of a category.
    Count(Category),
    /// Perceived strength of the nearest of a category (seed 001).
    Strength(Category),
    /// Own speed.
    Speed,
    /// Seconds in the current behavior.
    TimeInBehavior,
    /// An attribute.
    Attribute(AttrKind),
    /// Mean kin speed.
    KinSpeed,
    /// `1 − v`.
    OneMinus(Box<ValueNode>),
    /// Product.
    Mul(Box<ValueNode>, Box<ValueNode>),
    /// Sum.
    Add(Box<ValueNode>, Box<ValueNode>),
    /// Cached script value slot.
    Script(u16),
}

/// A condition, resolved into a native evaluator.
#[derive(Debug, Clone, PartialEq)]
pub enum CondNode {
    /// True.
    Always,
    /// False.
    Never,
    /// All.
    All(Vec<CondNode>),
    /// Any.
    Any(Vec<CondNode>),
    /// Not.
    Not(Box<CondNode>),
    /// `v > x`.
    Above(ValueNode, f32),
    /// `v < x`.
    Below(ValueNode, f32),
    /// Hysteresis latch number `bit`.
    Latch {
        /// Latch bit.
        bit: u8,
        /// On.
        on: Box<CondNode>,
        /// Off.
        off: Box<CondNode>,
    },
    /// Seen.
    Sees(Category),
    /// Smelt only.
    Smells(Category),
    /// Perceived.
    Perceives(Category),
    /// Nearest within distance.
    Within(Category, f32),
    /// Nearest in one of the horizontal sectors: bit `1 << (sector as u8)` of the mask.
    InSector(Category, u8),
    /// Nearest at one of the levels: bit `1 << (level as u8)` of the mask.
    AtLevel(Category, u8),
    /// Escape completion test.
    EscapeDone,
    /// Static obstacle pressure above M_min.
    ObstacleNear,
    /// Dynamic obstacle pressure above M_min.
    TrafficNear,
    /// Heard a message (a built-in kind or a declared event).
    Heard(Signal),
    /// Time in behavior at least (s).
    TimeIn(f32),
    /// Chance per second.
    Chance(f32),
    /// Near the bounds.
    NearBounds(f32),
    /// Cached script condition slot.
    Script(u16),
    /// The current behavior's contact happened.
    Contacted,
    /// Within this distance of the station.
    AtStation(f32),
}

/// A steering recipe, resolved.
#[derive(Debug, Clone, PartialEq)]
pub enum RecipeNode {
    /// First non-empty wins.
    Priority(Vec<RecipeNode>),
    /// Weighted blend: (constant weight, optional factor, recipe).
    Blend(Vec<(f32, Option<ValueNode>, RecipeNode)>),
    /// Script-built steering, slot index.
    Script(u16),
    /// A native primitive (a leaf of [`Recipe`]).
    Leaf(Recipe),
}

/// A resolved on-enter action.
#[derive(Debug, Clone, PartialEq)]
pub enum ActionNode {
    /// Broadcast a message (a built-in kind or a declared event).
    Send(Signal, f32),
    /// Call a script function.
    Call(String),
    /// Mark the agent's station where it is.
    MarkStation,
}

/// One behavior, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Behavior {
    /// Name.
    pub name: Arc<str>,
    /// Priority level (1 highest).
    pub priority: u8,
    /// Activation condition.
    pub when: CondNode,
    /// Completion condition.
    pub done: CondNode,
    /// Text of the activation condition (for transition causes).
    pub when_text: Arc<str>,
    /// Text of the completion condition.
    pub done_text: Arc<str>,
    /// Steering.
    pub steer: RecipeNode,
    /// Whether equal levels may interrupt it.
    pub equal_may_interrupt: bool,
    /// Minimum time (s).
    pub min_time: f32,
    /// Cooldown (s).
    pub cooldown: f32,
    /// Contact action.
    pub contact: Option<Contact>,
    /// On-enter actions.
    pub on_enter: Vec<ActionNode>,
    /// Turn response while it runs (`None`: the body's).
    pub response: Option<f32>,
    /// What its steering reads (`None`: everything; [`crate::decision::focus`]).
    pub focus: Option<crate::params::decision::Focus>,
    /// Line and column (1-based) of its `name` in the species file (0, 0: not found), for the
    /// viewer's state-machine graph.
    pub source: (u32, u32),
    /// Failure condition (checked after `done`, which is success).
    pub fail: CondNode,
    /// Text of the failure condition.
    pub fail_text: Arc<str>,
    /// The composed behavior holding it (`None`: the species' own list).
    pub parent: Option<u16>,
    /// Nesting level (0: the species' own list).
    pub level: u8,
    /// What it is made of.
    pub compose: Compose,
    /// Its sub-behaviors or steps, in the order written.
    pub children: Vec<u16>,
    /// The sibling started when it succeeds.
    pub on_success: Option<u16>,
    /// The sibling started when it fails.
    pub on_failure: Option<u16>,
}

/// What a behavior is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compose {
    /// Nothing: it steers.
    Leaf,
    /// A prioritized list of sub-behaviors (`behaviors:`).
    Select,
    /// Steps in order, each success starting the next (`sequence:`).
    Sequence,
    /// Steps in order, each failure starting the next (`fallback:`).
    Fallback,
}

/// What a script slot returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlotKind {
    /// A condition (bool).
    Bool,
    /// A number.
    Number,
    /// A steering value.
    Steer,
}

/// A script function the species uses, evaluated at the decision rate.
#[derive(Debug, Clone, PartialEq)]
pub struct ScriptSlot {
    /// Function name.
    pub name: String,
    /// What it returns.
    pub kind: SlotKind,
    /// Index among slots of its kind (`Steer` slots index `Mind::script_steer`).
    pub index: u16,
}

/// A validated species, ready to run. The tick reads only the checked fields below, never
/// [`Species::def`].
#[derive(Debug, Clone)]
pub struct Species {
    /// Name.
    pub name: String,
    /// The species file.
    pub file: PathBuf,
    /// The definition as read, for tools and viewers (color, relations); the tick does not read
    /// it.
    pub def: SpeciesDef,
    /// Body: size, limits, locomotion, animation, terrain mobility; every number checked.
    pub body: BodyDef,
    /// Senses.
    pub senses: SenseParams,
    /// Avoidance constants (seed 000 §4.1–§4.2) of `ObstacleNear` / `TrafficNear` and of
    /// `AvoidStatic()` / `AvoidDynamic()` written without parameters; checked.
    pub avoid: AvoidParams,
    /// Attribute distributions drawn at spawn; checked.
    pub attributes: AttributesDef,
    /// Drive constants and initial draws; checked.
    pub drives: DrivesDef,
    /// Script conditions and weights are re-evaluated every this many ticks (at least 1).
    pub decision_interval: u32,
    /// Seconds before an agent sends a message of the same kind again on entering a behavior
    /// (≥ 0).
    pub resend_after: f32,
    /// Behaviors, composed ones before their parts, named by path (`eat/chase`).
    pub behaviors: Vec<Behavior>,
    /// Index of the behavior an agent starts in: the initial behavior, or its first part when
    /// it is composed (always one that steers).
    pub initial: u16,
    /// Index of the initial behavior as named (composed or not).
    pub initial_node: u16,
    /// The species' own list (behaviors not inside another).
    pub roots: Vec<u16>,
    /// Nesting levels holding composed behaviors (0: none, the flat rules of seed 000 §3); at
    /// least 1 where some behavior ends on a failure or names what follows it (`fail`,
    /// `on_success`, `on_failure`), which only the composed rules read.
    pub depth: u8,
    /// Named recipes (for scripts).
    pub recipes: Vec<RecipeNode>,
    /// Their names.
    pub recipe_names: Arc<[String]>,
    /// The compiled script.
    pub script: Option<Arc<Script>>,
    /// Script functions used, in slot order.
    pub slots: Vec<ScriptSlot>,
    /// Number of `Steer` slots.
    pub steer_slots: usize,
    /// Whether the script defines `on_tick()`.
    pub has_on_tick: bool,
    /// Whether every slot is a condition or value evaluated natively
    /// ([`crate::script::native`]) and there is no `on_tick()`: its calls read only the
    /// agent's scalars and summaries (and its blackboard when `natives_read_memory`), and
    /// write nothing back.
    pub scripts_native: bool,
    /// Whether a natively evaluated function reads the blackboard (`this.has("k")`,
    /// `this["k"]`).
    pub natives_read_memory: bool,
    /// Whether the script defines `on_event(kind)`.
    pub has_on_event: bool,
    /// The declared blackboard: keys, types, and what a new agent remembers.
    pub memory: Arc<crate::script::memory::MemorySpec>,
    /// Declared events, in declaration order ([`Signal::Event`] indexes them).
    pub events: Arc<[EventSpec]>,
    /// Whether the script defines `on_event(kind, payload)`.
    pub has_on_event_payload: bool,
}

impl Species {
    /// Reads and validates the species file `file` and its script; shared script modules are
    /// imported relative to the file's folder.
    pub fn load(file: impl AsRef<Path>) -> Result<Species, Diagnostics> {
        let file = file.as_ref();
        let root = file.parent().unwrap_or(Path::new("."));
        validate::load_species(file, root, &crate::script::SandboxLimits::default())
    }

    /// Validates species `text`, named `file` in messages; a script it names is read relative to
    /// `file`'s folder.
    pub fn parse(file: impl AsRef<Path>, text: &str) -> Result<Species, Diagnostics> {
        let file = file.as_ref();
        let root = file.parent().unwrap_or(Path::new("."));
        validate::load_species_str(file, text, root, &crate::script::SandboxLimits::default())
    }

    /// Index of the behavior named `name`.
    pub fn behavior_index(&self, name: &str) -> Option<u16> {
        self.behaviors
            .iter()
            .position(|b| &*b.name == name)
            .map(|i| i as u16)
    }
    /// Name of behavior `i` ("?" when out of range).
    pub fn behavior_name(&self, i: u16) -> &str {
        self.behaviors.get(i as usize).map_or("?", |b| &b.name)
    }
    /// Every file this species was built from: the species file, its script and its imports.
    pub fn files(&self) -> Vec<PathBuf> {
        let mut v = vec![self.file.clone()];
        if let Some(s) = &self.script {
            v.push(s.file.clone());
            v.extend(s.imports.iter().cloned());
        }
        v
    }
}
