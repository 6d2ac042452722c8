//! Steering recipes as written in a species file: a primitive with its parameters, a priority
//! list or a weighted blend (seeds 000 §4, 001, 002, 003). Validation resolves them into
//! [`crate::species::RecipeNode`]s.

use super::Value;
use crate::params::steering::AvoidParams;
use crate::params::steering::EscapeRules;
use crate::params::steering::WanderParams;
use crate::params::steering::Zones;
use crate::params::steering::{GoalRules, Prediction, VisionTurn};
use crate::perception::Category;
use crate::perception::Sectors;
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// What to steer toward or away from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Target {
    /// The nearest percept of this category.
    Nearest(Category),
    /// The centroid of this category.
    Centroid(Category),
    /// A fixed point.
    Point(Vec3),
    /// The centre of the world bounds.
    Home,
    /// The agent's station (marked by the `MarkStation` action); none until marked.
    Station,
}

/// Parameters of move-to-goal (seed 000 §4.3, seed 003's foraging); the angles default to the
/// paper's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChaseDef {
    /// Category to move to.
    pub target: Category,
    /// Catch distance d0.
    pub d0: f32,
    /// Largest turn per step in vision mode (π/4).
    pub max_turn: f32,
    /// Smell-mode turn toward a target in a front side sector, and pitch toward one above or
    /// below (π/8).
    pub turn: f32,
    /// Smell-mode turn toward a target in a rear sector (π/4).
    pub rear_turn: f32,
    /// Half-width of the front sector (π/6); also the vertical level band.
    pub front: f32,
    /// Where the rear sector begins (5π/6).
    pub rear: f32,
    /// Vision mode within the clamp: `Bearing` turns by the bearing (seed 003's foraging),
    /// `KeepHeading` keeps the heading (seed 000 as printed).
    pub vision: VisionTurn,
}

impl Default for ChaseDef {
    fn default() -> Self {
        let r = GoalRules::default();
        ChaseDef {
            target: Category::Food,
            d0: 0.5,
            max_turn: r.max_turn,
            turn: r.turn,
            rear_turn: r.rear_turn,
            front: r.sectors.front,
            rear: r.sectors.rear,
            vision: r.vision,
        }
    }
}

impl ChaseDef {
    /// The angles of move-to-goal.
    pub fn rules(&self) -> GoalRules {
        GoalRules {
            turn: self.turn,
            rear_turn: self.rear_turn,
            sectors: Sectors {
                front: self.front,
                rear: self.rear,
            },
            max_turn: self.max_turn,
            vision: self.vision,
        }
    }
}

/// Parameters of escape (seed 000 §4.4, seed 002).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EscapeDef {
    /// Category to escape from.
    pub from: Category,
    /// The paper's rules as written: pitch ±π/8 (smell) or ±π/4 (vision) every step, `Vc/2`
    /// from a predator ahead in smell mode. The default adds a pitch aim and a speed floor.
    pub paper: bool,
    /// A predator within this angle of the horizontal counts as level: escape flees level.
    pub level_band: f32,
    /// Largest pitch escape aims for (rad).
    pub max_pitch: f32,
    /// Slowest escape speed, as a fraction of `V_max`.
    pub speed_floor: f32,
    /// Smell-mode turn and pitch away from the predator (π/8).
    pub turn: f32,
    /// Vision-mode turn and pitch away from the predator (π/4).
    pub vision_turn: f32,
    /// Half-width of the front sector, and of the level band in smell mode (π/6).
    pub front: f32,
    /// Smell mode, predator ahead: speed `smell_brake·Vc` (the paper's `Vc/2`).
    pub smell_brake: f32,
    /// Vision mode, predator beyond `v_r`: speed `far_speed·V_max` (the paper's `V_max/2`).
    pub far_speed: f32,
}

impl Default for EscapeDef {
    fn default() -> Self {
        let l = crate::params::steering::Leveling::default();
        let r = EscapeRules::default();
        EscapeDef {
            from: Category::Predator,
            paper: false,
            level_band: l.level_band,
            max_pitch: l.max_pitch,
            speed_floor: l.speed_floor,
            turn: r.turn,
            vision_turn: r.vision_turn,
            front: r.front,
            smell_brake: r.smell_brake,
            far_speed: r.far_speed,
        }
    }
}

impl EscapeDef {
    /// The constants of the paper's escape.
    pub fn rules(&self) -> EscapeRules {
        EscapeRules {
            turn: self.turn,
            vision_turn: self.vision_turn,
            front: self.front,
            smell_brake: self.smell_brake,
            far_speed: self.far_speed,
        }
    }

    /// The runtime's additions to the paper's escape.
    pub fn leveling(&self) -> crate::params::steering::Leveling {
        crate::params::steering::Leveling {
            level_band: self.level_band,
            max_pitch: self.max_pitch,
            speed_floor: self.speed_floor,
        }
    }
}

/// Parameters of pursuit (seed 002).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PursueDef {
    /// Category to pursue.
    pub target: Category,
    /// Prediction method.
    pub prediction: Prediction,
}

impl Default for PursueDef {
    fn default() -> Self {
        PursueDef {
            target: Category::Food,
            prediction: Prediction::Linear,
        }
    }
}

/// Parameters of seek / flee / arrive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SeekDef {
    /// Where.
    pub target: Target,
    /// Slow-down radius (arrive only).
    pub slow_radius: f32,
    /// Fraction of the maximum speed.
    pub speed: f32,
}

impl Default for SeekDef {
    fn default() -> Self {
        SeekDef {
            target: Target::Home,
            slow_radius: 2.0,
            speed: 1.0,
        }
    }
}

/// Parameters of hold-station.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HoldDef {
    /// Slow-down radius around the station.
    pub slow_radius: f32,
    /// Fraction of the maximum speed on the way back.
    pub speed: f32,
}

impl Default for HoldDef {
    fn default() -> Self {
        HoldDef {
            slow_radius: 3.0,
            speed: 0.5,
        }
    }
}

/// Parameters of separation / alignment / cohesion (seed 001).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroupRuleDef {
    /// Gain k.
    pub k: f32,
    /// Separation length factor.
    pub factor: f32,
    /// Only neighbors closer than this count.
    pub radius: f32,
}

impl Default for GroupRuleDef {
    fn default() -> Self {
        GroupRuleDef {
            k: 1.0,
            factor: 1.0,
            radius: f32::INFINITY,
        }
    }
}

/// Parameters of Vicsek alignment (seed 003).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VicsekDef {
    /// Neighborhood radius r_n.
    pub radius: f32,
    /// Angular noise η (rad).
    pub noise: f32,
    /// Fixed speed as a fraction of the maximum.
    pub speed: f32,
}

impl Default for VicsekDef {
    fn default() -> Self {
        VicsekDef {
            radius: 5.0,
            noise: 0.0,
            speed: 0.7,
        }
    }
}

/// Parameters of collision prediction and containment (seed 001).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LookAheadDef {
    /// Seconds looked ahead.
    pub horizon: f32,
    /// Margin kept from the bounds (containment only).
    pub margin: f32,
}

impl Default for LookAheadDef {
    fn default() -> Self {
        LookAheadDef {
            horizon: 1.5,
            margin: 2.0,
        }
    }
}

/// Parameters of cruising / stopping.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CruiseDef {
    /// Fraction of the maximum speed.
    pub speed: f32,
}

impl Default for CruiseDef {
    fn default() -> Self {
        CruiseDef { speed: 0.5 }
    }
}

/// Parameters of group escape by density (seed 003).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DisperseDef {
    /// Speed threshold v_d under which the agent re-draws its speed.
    pub below: f32,
}

impl Default for DisperseDef {
    fn default() -> Self {
        DisperseDef { below: 0.3 }
    }
}

/// A weighted entry of a blend.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Weighted {
    /// Constant weight.
    #[serde(default = "one")]
    pub w: f32,
    /// Optional state-dependent factor (seed 003's weights adjusted from the internal state).
    #[serde(default)]
    pub by: Option<Value>,
    /// The recipe weighted.
    pub steer: Recipe,
}

fn one() -> f32 {
    1.0
}

/// A steering recipe: one primitive, a priority list or a weighted blend.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Recipe {
    /// First entry that has something to do wins.
    Priority(Vec<Recipe>),
    /// Weighted blend.
    Blend(Vec<Weighted>),
    /// A Rhai function returning a steering command (at the decision rate).
    Script(String),
    /// Avoid static obstacles (seed 000 §4.1).
    AvoidStatic(AvoidParams),
    /// Avoid dynamic obstacles (seed 000 §4.2).
    AvoidDynamic(AvoidParams),
    /// Collision prediction by the path test (seed 001).
    PredictCollision(LookAheadDef),
    /// Keep inside the world bounds (seed 001).
    Contain(LookAheadDef),
    /// Move to goal, smell and vision modes (seed 000 §4.3, seed 003).
    Chase(ChaseDef),
    /// Escape, smell and vision modes (seed 000 §4.4).
    Escape(EscapeDef),
    /// Escape by seeking the mirrored point (seed 002).
    EscapeMirror(EscapeDef),
    /// Pursuit with prediction (seed 002).
    Pursue(PursueDef),
    /// Seek a target.
    Seek(SeekDef),
    /// Flee a target.
    Flee(SeekDef),
    /// Arrive at a target.
    Arrive(SeekDef),
    /// Separation (seed 001).
    Separation(GroupRuleDef),
    /// Alignment (seed 001).
    Alignment(GroupRuleDef),
    /// Cohesion.
    Cohesion(GroupRuleDef),
    /// R–A zones (seed 003).
    Zones(Zones),
    /// Vicsek alignment (seed 003).
    Vicsek(VicsekDef),
    /// Group escape by density (seed 003): below the speed threshold, re-draw the speed.
    Disperse(DisperseDef),
    /// Wander (seed 002).
    Wander(WanderParams),
    /// Keep heading at a cruise speed.
    Cruise(CruiseDef),
    /// Stop.
    Stop,
    /// Follow the agent's planned path (leader) or keep its formation slot (member).
    FollowPlan(CruiseDef),
    /// Hold station: arrive at the agent's station (`MarkStation`) and stay there; nothing
    /// to do while it has none.
    HoldStation(HoldDef),
}
