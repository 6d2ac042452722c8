//! One agent's state: kinematics, drives, attributes, decision state and animation channel.

use super::Rng;
use crate::command::{Steer, Term};
use crate::frame;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use thin_vec::{thin_vec, ThinVec};

/// Stable agent id: never reused within a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct AgentId(pub u32);

/// Index of a species in the loaded species set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct SpeciesId(pub u16);

/// Sex attribute (seed 003 fish model).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Sex {
    /// Female.
    #[default]
    Female,
    /// Male.
    Male,
}

/// Attributes of seed 003's fish model ⟨sex, age, mass, type⟩.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Attributes {
    /// Sex.
    pub sex: Sex,
    /// Age (s or any unit the species uses).
    pub age: f32,
    /// Mass.
    pub mass: f32,
    /// Free type tag (school membership in seed 003).
    pub kind: u16,
}

impl Default for Attributes {
    fn default() -> Self {
        Attributes {
            sex: Sex::Female,
            age: 1.0,
            mass: 1.0,
            kind: 0,
        }
    }
}

/// Drive values and their histories (seed 000 §2, seed 003).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct Drives {
    /// Hunger H(t) ∈ [0, 1].
    pub hunger: f32,
    /// Libido L(t) ∈ [0, 1].
    pub libido: f32,
    /// Fear F(t) ∈ [0, 1].
    pub fear: f32,
    /// Fatigue ∈ [0, 1] (seed 003 internal state; scripts may drive it).
    pub fatigue: f32,
    /// Seed 003 internal state `S(t) = S_max·exp(−t²/δ²)`, t the time since the last meal.
    pub state: f32,
    /// Time since the last meal Δt_H (s).
    pub since_meal: f32,
    /// Time since the last mating Δt_L (s).
    pub since_mating: f32,
    /// Food eaten in the last meal, n_e.
    pub eaten: f32,
}

/// Capacity of the behavior stack; deeper interrupts drop the oldest entry.
pub const STACK_CAPACITY: usize = 8;

/// Decision state: the current behavior, the behavior stack and anti-dithering timers
/// (seed 000 §3). Its lists are thin (one pointer, no allocation while empty): every agent
/// has a mind, and a million minds of `Vec`s would hold 80 MB of lengths and capacities.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mind {
    /// Index of the current behavior in the species' behavior list.
    pub current: u16,
    /// Interrupted behaviors, bottom first.
    pub stack: [u16; STACK_CAPACITY],
    /// Number of entries used in `stack`.
    pub depth: u8,
    /// Tick the current behavior started (or resumed).
    pub entered_tick: u64,
    /// Hysteresis latches: bit i set while hysteresis condition i is latched on.
    pub latches: u64,
    /// The cooldowns started and not yet dropped: when each behavior may start again.
    pub cooldowns: Cooldowns,
    /// Cached results of script conditions and weights, refreshed at the decision rate.
    pub script_values: ThinVec<f32>,
    /// Last valid steering, kept when a script fails.
    pub last_steer: Steer,
    /// Script-built steering per script recipe slot, refreshed at the decision rate.
    pub script_steer: ThinVec<Vec<(f32, Term)>>,
    /// Whether this agent already reported a script error (reported once).
    pub script_error_reported: bool,
    /// Whether the current behavior's contact happened (a meal, a catch, a mating): its end
    /// is then not held back by `min_time`.
    #[serde(default)]
    pub reached: bool,
    /// What few agents use: the quiet times of messages sent on entering a behavior, a marked
    /// station, composite behaviors' entry ticks, seed 003's foraging memory. Held apart, so
    /// that every other agent's record carries one pointer for it instead of 80 bytes.
    #[serde(default)]
    pub rare: RareMind,
}

/// A place or none, in 12 bytes instead of an `Option<Vec3>`'s 16 (two of them in a mind's
/// rare parts): none is a NaN `x`, which no place the engine remembers has (a non-finite
/// place is held as none). Read and written as an `Option<Vec3>`, serialized as one too.
#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(from = "Option<Vec3>", into = "Option<Vec3>")]
pub struct Spot(Vec3);

impl Spot {
    /// No place.
    pub const NONE: Spot = Spot(Vec3::new(f32::NAN, 0.0, 0.0));

    /// `p`; none for none or a non-finite place.
    #[inline]
    pub fn new(p: Option<Vec3>) -> Self {
        match p {
            Some(v) if v.is_finite() => Spot(v),
            _ => Spot::NONE,
        }
    }
    /// The place, if any.
    #[inline]
    pub fn get(self) -> Option<Vec3> {
        (!self.0.x.is_nan()).then_some(self.0)
    }
    /// Whether there is a place.
    #[inline]
    pub fn is_some(self) -> bool {
        !self.0.x.is_nan()
    }
}

impl Default for Spot {
    fn default() -> Self {
        Spot::NONE
    }
}

impl From<Option<Vec3>> for Spot {
    fn from(p: Option<Vec3>) -> Self {
        Spot::new(p)
    }
}

impl From<Spot> for Option<Vec3> {
    fn from(s: Spot) -> Self {
        s.get()
    }
}

impl PartialEq for Spot {
    fn eq(&self, other: &Self) -> bool {
        self.get() == other.get()
    }
}

impl std::fmt::Debug for Spot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.get().fmt(f)
    }
}

/// A mind's cooldowns: for each behavior whose cooldown was started, the tick before which it
/// may not start again, by behavior. Only started ones are held (those that ran out are
/// dropped at the next start): a list of every behavior held 96 bytes for each reef fish,
/// whose 12 behaviors have 5 cooldowns and rarely more than one running.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Cooldowns(ThinVec<(u16, u64)>);

impl Cooldowns {
    /// The tick before which behavior `b` may not start again (`None`: no cooldown held).
    #[inline]
    pub fn until(&self, b: u16) -> Option<u64> {
        self.0.iter().find(|e| e.0 == b).map(|e| e.1)
    }
    /// Whether behavior `b` may start at `tick` (its cooldown, if any, has run out).
    #[inline]
    pub fn ready(&self, b: u16, tick: u64) -> bool {
        self.until(b).is_none_or(|t| tick >= t)
    }
    /// Starts behavior `b`'s cooldown at `tick`, to run until `until`; those that ran out by
    /// `tick` are dropped.
    pub fn start(&mut self, b: u16, tick: u64, until: u64) {
        self.0.retain(|e| e.1 > tick && e.0 != b);
        let at = self.0.partition_point(|e| e.0 < b);
        self.0.insert(at, (b, until));
    }
    /// The cooldowns still running at `tick`, as (behavior, until), by behavior.
    pub fn running(&self, tick: u64) -> impl Iterator<Item = (u16, u64)> + '_ {
        self.0.iter().copied().filter(move |e| e.1 > tick)
    }
    /// Cooldowns from (behavior, until) pairs in any order (the last of a behavior's wins).
    pub fn from_pairs(pairs: impl IntoIterator<Item = (u16, u64)>) -> Self {
        let mut v: ThinVec<(u16, u64)> = pairs.into_iter().collect();
        v.reverse();
        v.sort_by_key(|e| e.0);
        v.dedup_by_key(|e| e.0);
        Cooldowns(v)
    }
    /// Whether none is held.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// The parts of a [`Mind`] few agents use.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct MindParts {
    /// Per message kind: the tick before which entering a behavior sends no more of it.
    pub quiet_until: [u64; 3],
    /// Per declared event of the species: the tick before which entering a behavior sends no
    /// more of it (empty until the first such send).
    pub quiet_events: ThinVec<u64>,
    /// Its station (the `MarkStation` action), which `HoldStation` returns to
    /// ([`Mind::station`]).
    pub station: Spot,
    /// Per depth of composed behaviors: the tick the composite current at that depth was
    /// entered (empty for species without composites).
    pub scope_entered: ScopeTicks,
    /// Seed 003's foraging memory: its own best food position ([`Mind::best_food`]).
    #[serde(default)]
    pub best_food: Spot,
    /// The school's best food position ([`Mind::school_best`]).
    #[serde(default)]
    pub school_best: Spot,
}

/// Entry ticks of composed behaviors, by depth: the first in place and the deeper ones in a
/// list, so that a species nesting one level (most do) holds no heap block for them beside its
/// mind's rare parts (16 bytes in them, as a list's pointer and the first tick). Serialized as
/// the list of ticks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "Vec<u64>", into = "Vec<u64>")]
pub struct ScopeTicks {
    /// Depth 0's tick; [`ScopeTicks::NONE`] when the list is empty (no tick reaches it).
    first: u64,
    more: ThinVec<u64>,
}

impl ScopeTicks {
    const NONE: u64 = u64::MAX;

    /// How many depths are tracked.
    #[inline]
    pub fn len(&self) -> usize {
        if self.is_empty() {
            0
        } else {
            1 + self.more.len()
        }
    }
    /// Whether none is.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.first == Self::NONE
    }
    /// The tick depth `d`'s composite was entered, if tracked.
    #[inline]
    pub fn get(&self, d: usize) -> Option<u64> {
        match d {
            _ if self.is_empty() => None,
            0 => Some(self.first),
            _ => self.more.get(d - 1).copied(),
        }
    }
    /// Sets depth `d`'s tick, if tracked (else nothing).
    #[inline]
    pub fn set(&mut self, d: usize, tick: u64) {
        match d {
            _ if self.is_empty() => {}
            0 => self.first = tick,
            _ => {
                if let Some(e) = self.more.get_mut(d - 1) {
                    *e = tick;
                }
            }
        }
    }
    /// Tracks `depth` depths: a depth added is entered at `tick`, the list beyond the first
    /// holds just its room.
    pub fn resize(&mut self, depth: usize, tick: u64) {
        if depth == 0 {
            *self = ScopeTicks::default();
            return;
        }
        if self.is_empty() {
            self.first = tick;
        }
        let more = depth - 1;
        if more == 0 {
            self.more = ThinVec::new();
            return;
        }
        self.more
            .reserve_exact(more.saturating_sub(self.more.len()));
        self.more.resize(more, tick);
    }
    /// Depths held without growing: the first and the list's capacity.
    pub fn room(&self) -> usize {
        usize::from(!self.is_empty()) + self.more.capacity()
    }
    /// The ticks, depth 0 first.
    pub fn to_vec(&self) -> Vec<u64> {
        if self.is_empty() {
            return Vec::new();
        }
        std::iter::once(self.first)
            .chain(self.more.iter().copied())
            .collect()
    }
}

impl Default for ScopeTicks {
    fn default() -> Self {
        ScopeTicks {
            first: Self::NONE,
            more: ThinVec::new(),
        }
    }
}

impl From<Vec<u64>> for ScopeTicks {
    fn from(v: Vec<u64>) -> Self {
        let mut s = ScopeTicks::default();
        if let Some((&first, rest)) = v.split_first() {
            // A tick of `NONE` is none: it would read as an empty list.
            if first != Self::NONE {
                s.first = first;
                s.more = rest.iter().copied().collect();
            }
        }
        s
    }
}

impl From<ScopeTicks> for Vec<u64> {
    fn from(s: ScopeTicks) -> Self {
        s.to_vec()
    }
}

/// A mind's [`MindParts`], absent until one is set. Absent and all-default parts are equal:
/// which of the two a mind holds is not part of what it is.
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
pub struct RareMind(pub Option<Box<MindParts>>);

impl PartialEq for RareMind {
    fn eq(&self, other: &Self) -> bool {
        let empty = |p: &MindParts| *p == MindParts::default();
        match (&self.0, &other.0) {
            (Some(a), Some(b)) => a == b,
            (Some(p), None) | (None, Some(p)) => empty(p),
            (None, None) => true,
        }
    }
}

/// `n` zeros; no call at all for none (every agent's pass makes an empty mind).
#[inline]
fn zeros<T: Default + Clone>(n: usize) -> ThinVec<T> {
    if n == 0 {
        ThinVec::new()
    } else {
        thin_vec![T::default(); n]
    }
}

impl Mind {
    /// A mind starting in behavior `initial`, with `script_values` cached script results.
    pub fn new(initial: u16, script_values: usize) -> Self {
        Mind {
            current: initial,
            stack: [0; STACK_CAPACITY],
            depth: 0,
            entered_tick: 0,
            latches: 0,
            cooldowns: Cooldowns::default(),
            script_values: zeros(script_values),
            last_steer: Steer::NONE,
            script_steer: ThinVec::new(),
            script_error_reported: false,
            reached: false,
            rare: RareMind::default(),
        }
    }
    /// The stack, bottom first.
    pub fn stack(&self) -> &[u16] {
        &self.stack[..self.depth as usize]
    }
    /// Top of the stack.
    pub fn top(&self) -> Option<u16> {
        self.stack().last().copied()
    }
    /// Pushes an interrupted behavior; when full, the oldest entry is dropped.
    pub fn push(&mut self, b: u16) {
        if self.depth as usize == STACK_CAPACITY {
            self.stack.copy_within(1.., 0);
            self.depth -= 1;
        }
        self.stack[self.depth as usize] = b;
        self.depth += 1;
    }
    /// Its station (the `MarkStation` action), which `HoldStation` returns to.
    #[inline]
    pub fn station(&self) -> Option<Vec3> {
        self.rare.0.as_ref().and_then(|r| r.station.get())
    }
    /// Per depth of composed behaviors: the tick the composite current at that depth was
    /// entered (none for species without composites, and past the depths tracked).
    #[inline]
    pub fn scope_entered(&self, depth: usize) -> Option<u64> {
        self.rare
            .0
            .as_deref()
            .and_then(|r| r.scope_entered.get(depth))
    }
    /// How many depths [`Mind::scope_entered`] tracks.
    #[inline]
    pub fn scope_depth(&self) -> usize {
        self.rare.0.as_deref().map_or(0, |r| r.scope_entered.len())
    }
    /// Sets [`Mind::scope_entered`] at `depth` (nothing for a depth the mind does not track).
    #[inline]
    pub fn set_scope_entered(&mut self, depth: usize, tick: u64) {
        if let Some(r) = self.rare.0.as_deref_mut() {
            r.scope_entered.set(depth, tick);
        }
    }
    /// Tracks composed behaviors `depth` deep ([`Mind::scope_entered`]): a depth added is
    /// entered at `tick`. Every fish of a composed species has them: the first depth is held
    /// in the rare parts, deeper ones in just their room.
    pub fn track_scopes(&mut self, depth: usize, tick: u64) {
        self.rare_mut().scope_entered.resize(depth, tick);
    }
    /// Seed 003 foraging memory (particle-swarm style), its own best food position: where it
    /// last perceived food (the nearest), kept until it comes within vision of the place and
    /// perceives none.
    #[inline]
    pub fn best_food(&self) -> Option<Vec3> {
        self.rare.0.as_ref().and_then(|r| r.best_food.get())
    }
    /// The school's best food position: the nearest own best of the kin it perceives (from the
    /// start of the tick); `None` when none of them knows food.
    #[inline]
    pub fn school_best(&self) -> Option<Vec3> {
        self.rare.0.as_ref().and_then(|r| r.school_best.get())
    }
    /// Sets [`Mind::best_food`] (a non-finite place is none).
    #[inline]
    pub fn set_best_food(&mut self, p: Option<Vec3>) {
        self.set_spot(p, |r| &mut r.best_food);
    }
    /// Sets [`Mind::school_best`] (a non-finite place is none).
    #[inline]
    pub fn set_school_best(&mut self, p: Option<Vec3>) {
        self.set_spot(p, |r| &mut r.school_best);
    }
    /// A place in the rare parts: none makes no parts (a flock that never sees food has none).
    #[inline]
    fn set_spot(&mut self, p: Option<Vec3>, spot: impl FnOnce(&mut MindParts) -> &mut Spot) {
        let s = Spot::new(p);
        if s.is_some() || self.rare.0.is_some() {
            *spot(self.rare_mut()) = s;
        }
    }
    /// The rarely used parts, made on first use.
    pub fn rare_mut(&mut self) -> &mut MindParts {
        self.rare.0.get_or_insert_with(Default::default)
    }
    /// Pops the top of the stack.
    pub fn pop(&mut self) -> Option<u16> {
        if self.depth == 0 {
            None
        } else {
            self.depth -= 1;
            Some(self.stack[self.depth as usize])
        }
    }
}

/// Animation channel for a renderer (seed 001 tail tween).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct Anim {
    /// Swim-cycle phase in [0, 1).
    pub phase: f32,
    /// The last step's turn against the body's fastest, in [−1, 1] (right positive). With the
    /// phase it gives the tail's bend ([`crate::locomotion::anim::bend`]), worked out only
    /// where something reads it (a recording, the viewer), not every tick for every agent.
    #[serde(default)]
    pub turn: f32,
}

/// The forward vector of a body, kept with the heading it was computed for, so that the
/// stages after locomotion reuse it instead of computing two `sin_cos` again. A cache, not
/// state: it answers only for the very heading it was made for, and never takes part in
/// comparisons.
#[derive(Debug, Clone, Copy)]
pub struct ForwardCache {
    yaw: f32,
    pitch: f32,
    forward: Vec3,
}

impl ForwardCache {
    /// Holds nothing.
    pub const NONE: ForwardCache = ForwardCache {
        yaw: f32::NAN,
        pitch: f32::NAN,
        forward: Vec3::ZERO,
    };

    /// `forward` is `frame::forward(yaw, pitch)`.
    pub fn new(yaw: f32, pitch: f32, forward: Vec3) -> Self {
        ForwardCache {
            yaw,
            pitch,
            forward,
        }
    }

    /// The forward vector for exactly this heading, if held.
    #[inline]
    pub fn get(&self, yaw: f32, pitch: f32) -> Option<Vec3> {
        (self.yaw.to_bits() == yaw.to_bits() && self.pitch.to_bits() == pitch.to_bits())
            .then_some(self.forward)
    }
}

impl Default for ForwardCache {
    fn default() -> Self {
        Self::NONE
    }
}

impl PartialEq for ForwardCache {
    /// Always: a cache is not part of what an agent is.
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// One agent.
#[derive(Debug, Clone, PartialEq)]
pub struct Agent {
    /// Stable id.
    pub id: AgentId,
    /// Species.
    pub species: SpeciesId,
    /// Position.
    pub pos: Vec3,
    /// Position one tick ago (for linear prediction, seed 002).
    pub prev_pos: Vec3,
    /// Heading yaw about world up (rad, right positive).
    pub yaw: f32,
    /// Heading pitch (rad, up positive), |pitch| < 90°.
    pub pitch: f32,
    /// Speed along the forward axis.
    pub speed: f32,
    /// Yaw rate (rad/s), used by the rigid-body mode.
    pub yaw_rate: f32,
    /// Pitch rate (rad/s), used by the rigid-body mode.
    pub pitch_rate: f32,
    /// Bounding box size (width, height, length).
    pub size: Vec3,
    /// Drives.
    pub drives: Drives,
    /// Attributes.
    pub attrs: Attributes,
    /// Decision state.
    pub mind: Mind,
    /// Animation channel.
    pub anim: Anim,
    /// The agent's own random stream.
    pub rng: Rng,
    /// Per-agent memory (a small blackboard that persists across ticks), in key order.
    pub memory: ThinVec<(Arc<str>, MemValue)>,
    /// The highest-ranked message or declared event received last tick (one slot).
    pub inbox: super::Inbox,
    /// Forward vector of the current heading, when locomotion left it.
    pub forward_cache: ForwardCache,
}

/// A value on an agent's blackboard.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum MemValue {
    /// A flag.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A number.
    Float(f32),
    /// A vector.
    Vec3(Vec3),
    /// A short string.
    Str(String),
}

/// Most keys on one blackboard.
pub const MEMORY_CAPACITY: usize = 32;

impl Agent {
    /// Forward unit vector.
    #[inline]
    pub fn forward(&self) -> Vec3 {
        self.forward_cache
            .get(self.yaw, self.pitch)
            .unwrap_or_else(|| frame::forward(self.yaw, self.pitch))
    }
    /// Velocity (forward × speed, without the world current).
    #[inline]
    pub fn velocity(&self) -> Vec3 {
        self.forward() * self.speed
    }
    /// Size `S_f` of seed 000: the bounding box diagonal.
    #[inline]
    pub fn diagonal(&self) -> f32 {
        self.size.length()
    }
    /// Radius of the bounding sphere.
    #[inline]
    pub fn radius(&self) -> f32 {
        self.size.length() * 0.5
    }
}

/// Messages between agents (seed 003), highest priority first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum MessageKind {
    /// Danger (a predator).
    Danger = 0,
    /// An obstacle.
    Obstacle = 1,
    /// A mating call.
    Mate = 2,
}

impl MessageKind {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            MessageKind::Danger => "danger",
            MessageKind::Obstacle => "obstacle",
            MessageKind::Mate => "mate",
        }
    }
    /// Parses a lower-case name.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "danger" => Some(MessageKind::Danger),
            "obstacle" => Some(MessageKind::Obstacle),
            "mate" => Some(MessageKind::Mate),
            _ => None,
        }
    }
    /// Keeps the higher-priority of two messages.
    pub fn max_priority(a: Option<Self>, b: Self) -> Self {
        match a {
            Some(a) if a < b => a,
            _ => b,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spot_holds_a_place_or_none_and_reads_as_an_option() {
        let p = Vec3::new(1.0, -2.0, 3.5);
        assert_eq!(Spot::new(Some(p)).get(), Some(p));
        assert_eq!(Spot::new(None).get(), None);
        assert_eq!(Spot::default(), Spot::NONE);
        assert!(!Spot::NONE.is_some() && Spot::new(Some(p)).is_some());
        // A place that is no place is held as none.
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(Spot::new(Some(Vec3::new(0.0, bad, 0.0))).get(), None);
            assert_eq!(Spot::new(Some(Vec3::new(bad, 0.0, 0.0))).get(), None);
        }
        // Serialized as the `Option<Vec3>` it stands for, both ways.
        for s in [Spot::NONE, Spot::new(Some(p))] {
            let text = serde_json::to_string(&s).unwrap();
            assert_eq!(text, serde_json::to_string(&s.get()).unwrap());
            assert_eq!(serde_json::from_str::<Spot>(&text).unwrap(), s);
        }
        assert_eq!(
            format!("{:?}", Spot::new(Some(p))),
            format!("{:?}", Some(p))
        );
    }

    #[test]
    fn an_agent_record_is_no_larger_than_its_budget() {
        // Every agent carries it: a field added here costs a million agents its size. The
        // two foraging places are 12 bytes each, not an `Option<Vec3>`'s 16; the one inbox
        // slot is 8, not two options' 13.
        assert_eq!(std::mem::size_of::<Spot>(), 12);
        assert_eq!(std::mem::size_of::<super::super::Inbox>(), 8);
        assert!(
            std::mem::size_of::<Mind>() <= 112,
            "{}",
            std::mem::size_of::<Mind>()
        );
        // A mind's rare parts are one heap block of 96 bytes (88 and the allocator's 8),
        // composites' first entry tick included.
        assert!(
            std::mem::size_of::<MindParts>() <= 88,
            "{}",
            std::mem::size_of::<MindParts>()
        );
        assert!(
            std::mem::size_of::<Agent>() <= 272,
            "{}",
            std::mem::size_of::<Agent>()
        );
    }

    #[test]
    fn scope_ticks_read_and_serialize_as_the_list_they_stand_for() {
        for v in [vec![], vec![3], vec![3, 4], vec![3, 4, 5]] {
            let s = ScopeTicks::from(v.clone());
            assert_eq!(
                (s.len(), s.is_empty(), s.to_vec()),
                (v.len(), v.is_empty(), v.clone())
            );
            for d in 0..4 {
                assert_eq!(s.get(d), v.get(d).copied());
            }
            let text = serde_json::to_string(&s).unwrap();
            assert_eq!(text, serde_json::to_string(&v).unwrap());
            assert_eq!(serde_json::from_str::<ScopeTicks>(&text).unwrap(), s);
        }
        // A mind's parts read back as written, station and ticks included.
        let parts = MindParts {
            station: Spot::new(Some(Vec3::new(1.0, 2.0, 3.0))),
            scope_entered: vec![7, 8].into(),
            ..MindParts::default()
        };
        let text = serde_json::to_string(&parts).unwrap();
        assert!(text.contains("\"station\":[1.0,2.0,3.0]"), "{text}");
        assert!(text.contains("\"scope_entered\":[7,8]"), "{text}");
        assert_eq!(serde_json::from_str::<MindParts>(&text).unwrap(), parts);
    }
}
