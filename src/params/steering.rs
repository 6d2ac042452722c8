//! Steering's parameter types (stage 5), as species files write them: the static and dynamic
//! obstacle fields' constants (seed 000 §4.1–4.2), escape (§4.4) and the runtime's leveling of
//! it, move-to-goal (§4.3), seed 002's pursuit prediction and wandering, seed 003's R–A zones.
//! Every default is the paper's value. Pure data: the rules that read them, and these types'
//! own methods, stay in [`crate::steering`], which re-exports each type under its old path.

use crate::perception::Sectors;
use serde::{Deserialize, Serialize};
use std::f32::consts::{FRAC_PI_4, FRAC_PI_6, FRAC_PI_8};

/// Parameters of the static-obstacle field (seed 000 §4.1); defaults follow the paper's form.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AvoidParams {
    /// Margin m0 added to every distance.
    pub m0: f32,
    /// Turn applied when one side's pressure dominates (π/8).
    pub turn: f32,
    /// Obstacles farther than this are ignored (`None`: everything in view counts, as in the
    /// paper).
    pub range: Option<f32>,
    /// Whether kin count as dynamic obstacles (schooling species leave that to separation).
    pub kin: bool,
    /// Whether the static field takes the paper's form as written: every obstacle in view
    /// counts, with its horizontal and vertical angles θ_i, ω_i
    /// ([`pressures`](crate::steering::avoid::pressures)). The default (`false`) is the
    /// front-half field ([`front_pressures`](crate::steering::avoid::front_pressures)): §4.1
    /// integrates over the front half only, and an obstacle straight above or below has no
    /// horizontal angle at all.
    pub paper_field: bool,
    /// Slowest speed braking brings a body to, as a fraction of `V_max` (0: the paper's `Vc/2`
    /// applied every tick, which decays to a standstill next to any obstacle that stays in view).
    pub brake_floor: f32,
    /// Braking factor of the static field: the speed becomes `brake·Vc` when a pressure exceeds
    /// `M_max` (the paper's `Vc/2`: 0.5).
    pub brake: f32,
    /// Factor of the dynamic field's threshold `M_min = −factor·cos α/(v_r + m0)` (seed 000
    /// §4.2). `None`: `1 − cos(half-angle)` of the species' vision cone, the paper's integral
    /// over the whole view; `Some(1.866)`: the paper's `1 + √3/2` (its 150° view) whatever the
    /// view.
    pub m_min_factor: Option<f32>,
}

impl Default for AvoidParams {
    fn default() -> Self {
        AvoidParams {
            m0: 1.0,
            turn: FRAC_PI_8,
            range: None,
            kin: false,
            paper_field: false,
            brake_floor: 0.3,
            brake: 0.5,
            m_min_factor: None,
        }
    }
}

/// The paper's fixed factor of the dynamic `M_min`, `1 + √3/2 = 1 − cos 150°` (seed 000 §4.2).
pub const PAPER_M_MIN_FACTOR: f32 = 1.866_025_4;

/// The constants of escape (seed 000 §4.4); the defaults are the paper's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EscapeRules {
    /// Smell-mode turn and pitch away from the predator (π/8).
    pub turn: f32,
    /// Vision-mode turn and pitch away from the predator (π/4).
    pub vision_turn: f32,
    /// Half-width of the front sector, and of the level band in smell mode (π/6).
    pub front: f32,
    /// Smell mode, predator ahead: the speed becomes `smell_brake·Vc` (the paper's `Vc/2`).
    pub smell_brake: f32,
    /// Vision mode, predator beyond `v_r`: the speed is `far_speed·V_max` (the paper's
    /// `V_max/2`).
    pub far_speed: f32,
}

impl Default for EscapeRules {
    fn default() -> Self {
        EscapeRules {
            turn: FRAC_PI_8,
            vision_turn: FRAC_PI_4,
            front: FRAC_PI_6,
            smell_brake: 0.5,
            far_speed: 0.5,
        }
    }
}

/// The runtime's additions to the paper's escape (see [`crate::steering::escape`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leveling {
    /// A predator whose elevation above the horizontal is within this band counts as level.
    pub level_band: f32,
    /// Largest pitch escape aims for.
    pub max_pitch: f32,
    /// Slowest escape speed, as a fraction of `V_max`.
    pub speed_floor: f32,
}

impl Default for Leveling {
    fn default() -> Self {
        Leveling {
            level_band: std::f32::consts::FRAC_PI_6,
            max_pitch: FRAC_PI_4,
            speed_floor: 0.5,
        }
    }
}

/// What move-to-goal does in vision with a target within the clamp (`|θ| < max_turn`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum VisionTurn {
    /// Turn exactly by the bearing (seed 003's foraging; the digest's reading of 000).
    #[default]
    Bearing,
    /// Keep the heading (seed 000 eq. 15–16 as printed); turn by ±`max_turn` beyond it.
    KeepHeading,
}

/// The angles of move-to-goal (seed 000 §4.3); the defaults are the paper's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoalRules {
    /// Smell-mode turn toward a target in a front side sector, and pitch toward one above or
    /// below (π/8).
    pub turn: f32,
    /// Smell-mode turn toward a target in a rear sector (π/4).
    pub rear_turn: f32,
    /// Sector bounds (π/6, 5π/6).
    pub sectors: Sectors,
    /// Largest turn per step in vision mode (π/4).
    pub max_turn: f32,
    /// Within the clamp in vision mode: turn by the bearing or keep the heading.
    pub vision: VisionTurn,
}

impl Default for GoalRules {
    fn default() -> Self {
        GoalRules {
            turn: FRAC_PI_8,
            rear_turn: FRAC_PI_4,
            sectors: Sectors::default(),
            max_turn: FRAC_PI_4,
            vision: VisionTurn::Bearing,
        }
    }
}

/// How a pursuer predicts its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
pub enum Prediction {
    /// Aim at where the target is.
    None,
    /// `2·X_t − X_{t−1}` (seed 002's robust choice).
    #[default]
    Linear,
    /// The intercept point from the target's velocity.
    Intercept,
}

/// Radii of seed 003's zones, `r_r < r_m < r_a`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Zones {
    /// Repulsion radius r_r.
    pub repulsion: f32,
    /// Velocity-matching radius r_m.
    pub matching: f32,
    /// Attraction radius r_a.
    pub attraction: f32,
    /// Soft repulsion band, a fraction of r_r (runtime addition; 0 is seed 003's hard zone). A
    /// neighbor entering r_r repels with a weight rising from 0 at r_r to 1 at `(1 − soft)·r_r`
    /// and keeps being matched with the rest; the other zones count for what repulsion leaves.
    /// With the hard zone, a neighbor crossing r_r flips the heading between "away from it" and
    /// "with the school" from one tick to the next: schools zig-zag (turning 4–5× the net
    /// heading change in `school_formation`).
    #[serde(default = "default_soft")]
    pub soft: f32,
}

fn default_soft() -> f32 {
    0.5
}

impl Default for Zones {
    fn default() -> Self {
        Zones {
            repulsion: 1.0,
            matching: 4.0,
            attraction: 10.0,
            soft: default_soft(),
        }
    }
}

/// Wander parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WanderParams {
    /// Largest random yaw increment per step (rad).
    pub yaw_jitter: f32,
    /// Largest random pitch increment per step (rad).
    pub pitch_jitter: f32,
    /// Fraction of the current pitch undone each step (keeps wandering near level).
    pub level_bias: f32,
    /// Cruise speed as a fraction of the maximum speed.
    pub cruise: f32,
}

impl Default for WanderParams {
    fn default() -> Self {
        WanderParams {
            yaw_jitter: 0.3,
            pitch_jitter: 0.1,
            level_bias: 0.1,
            cruise: 0.5,
        }
    }
}
