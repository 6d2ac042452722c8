//! What perception hands to the later stages: percepts, sectors and per-category summaries.

use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::f32::consts::{FRAC_PI_2, FRAC_PI_6};

/// What a percept is to the perceiving agent, resolved from its species' relations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, PartialOrd, Ord)]
pub enum Category {
    /// Something it eats: a food item or a prey agent.
    Food = 0,
    /// Something that eats it.
    Predator = 1,
    /// Same kind: schooling partners.
    Kin = 2,
    /// A possible mate (kin of the other sex).
    Mate = 3,
    /// A static obstacle.
    Obstacle = 4,
    /// Any other agent (still a dynamic obstacle).
    Other = 5,
}

impl Category {
    /// Number of categories.
    pub const COUNT: usize = 6;
    /// All categories in index order.
    pub const ALL: [Category; 6] = [
        Category::Food,
        Category::Predator,
        Category::Kin,
        Category::Mate,
        Category::Obstacle,
        Category::Other,
    ];
    /// Lower-case name, as used in scripts and logs.
    pub fn name(self) -> &'static str {
        match self {
            Category::Food => "food",
            Category::Predator => "predator",
            Category::Kin => "kin",
            Category::Mate => "mate",
            Category::Obstacle => "obstacle",
            Category::Other => "other",
        }
    }
}

/// Which sense delivered a percept (seed 000 §1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Sense {
    /// Inside the vision sphere and cone (or the custom volume) and not occluded: exact.
    Vision,
    /// Inside the smell sphere only: direction sectors, fuzzy.
    Smell,
}

/// Horizontal sector of a bearing θ (seed 000 §4.3): front (−π/6, π/6), left-front
/// (−π/2, −π/6], right-front [π/6, π/2), left-rear (−5π/6, −π/2], right-rear [π/2, 5π/6),
/// rear |θ| ≥ 5π/6.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Sector {
    /// Ahead.
    Front,
    /// Ahead to the left.
    LeftFront,
    /// Ahead to the right.
    RightFront,
    /// Behind to the left.
    LeftRear,
    /// Behind to the right.
    RightRear,
    /// Straight behind.
    Rear,
}

impl Sector {
    /// All sectors, clockwise from the front.
    pub const ALL: [Sector; 6] = [
        Sector::Front,
        Sector::RightFront,
        Sector::RightRear,
        Sector::Rear,
        Sector::LeftRear,
        Sector::LeftFront,
    ];
    /// Lower-case name, as scripts and transition texts read it (`"left_rear"`).
    pub fn name(self) -> &'static str {
        match self {
            Sector::Front => "front",
            Sector::LeftFront => "left_front",
            Sector::RightFront => "right_front",
            Sector::LeftRear => "left_rear",
            Sector::RightRear => "right_rear",
            Sector::Rear => "rear",
        }
    }
    /// Classifies a bearing (right positive).
    pub fn of(theta: f32) -> Sector {
        let five_sixths = 5.0 * FRAC_PI_6;
        if theta > -FRAC_PI_6 && theta < FRAC_PI_6 {
            Sector::Front
        } else if theta <= -FRAC_PI_6 && theta > -FRAC_PI_2 {
            Sector::LeftFront
        } else if (FRAC_PI_6..FRAC_PI_2).contains(&theta) {
            Sector::RightFront
        } else if theta <= -FRAC_PI_2 && theta > -five_sixths {
            Sector::LeftRear
        } else if (FRAC_PI_2..five_sixths).contains(&theta) {
            Sector::RightRear
        } else {
            Sector::Rear
        }
    }
}

/// Vertical sector of an elevation ω: above, level (|ω| < π/6, "front" in the vertical plane) or
/// below.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Level {
    /// Higher than the heading by at least π/6.
    Above,
    /// Within ±π/6 of the heading.
    Level,
    /// Lower than the heading by at least π/6.
    Below,
}

impl Level {
    /// All levels, top down.
    pub const ALL: [Level; 3] = [Level::Above, Level::Level, Level::Below];
    /// Lower-case name, as scripts and transition texts read it (`"above"`).
    pub fn name(self) -> &'static str {
        match self {
            Level::Above => "above",
            Level::Level => "level",
            Level::Below => "below",
        }
    }
    /// Classifies an elevation (up positive).
    pub fn of(omega: f32) -> Level {
        if omega >= FRAC_PI_6 {
            Level::Above
        } else if omega <= -FRAC_PI_6 {
            Level::Below
        } else {
            Level::Level
        }
    }
}

/// Where a percept comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Source {
    /// An agent, by its index in `World::agents` at the start of the tick.
    Agent(u32),
    /// A food item, by index in `World::food`.
    Food(u32),
    /// A static obstacle, by index in `World::obstacles`.
    Obstacle(u32),
    /// Fed to the agent directly (script tests): no object of the world stands behind it, so
    /// contacts, pursuit prediction and neighbor lists ignore it.
    Injected,
}

/// One perceived thing, relative to the perceiving agent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Percept {
    /// What it is.
    pub source: Source,
    /// What it is to the perceiver.
    pub category: Category,
    /// Which sense saw it.
    pub sense: Sense,
    /// Target minus own position (for obstacles: to the nearest surface point).
    pub offset: Vec3,
    /// Distance (for obstacles: to the surface).
    pub dist: f32,
    /// Horizontal bearing θ (rad, right positive). In the tick pipeline it is computed only
    /// where the species' behaviors can read it (obstacles, the nearest of each category, agents
    /// within its dynamic-avoidance range) and is 0 elsewhere, unless
    /// `Pipeline::set_full_bearings(true)`; [`crate::frame::bearing_elevation`] gives it from
    /// `offset` at any time.
    pub bearing: f32,
    /// Elevation ω (rad, up positive); computed where `bearing` is.
    pub elevation: f32,
    /// Size S: bounding-box diagonal.
    pub size: f32,
}

impl Percept {
    /// Horizontal sector of the bearing.
    pub fn sector(&self) -> Sector {
        Sector::of(self.bearing)
    }
    /// Vertical sector of the elevation.
    pub fn level(&self) -> Level {
        Level::of(self.elevation)
    }
}

/// Per-category summary: nearest, count, centroid, mean heading (issue "Engine core" §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Number of percepts of the category.
    pub count: u32,
    /// Number of them seen (vision), the rest only smelt.
    pub seen: u32,
    /// Index (into the agent's percept slice) of the nearest, if any.
    pub nearest: Option<u16>,
    /// Distance to the nearest (`f32::INFINITY` when none).
    pub nearest_dist: f32,
    /// Mean position (world), zero when none.
    pub centroid: Vec3,
    /// Mean forward vector of agent percepts (not normalized), zero when none.
    pub mean_heading: Vec3,
    /// Mean velocity of agent percepts, zero when none.
    pub mean_velocity: Vec3,
    /// `Σ 1/d` over every percept of the category (predators only; 0 for the others): what
    /// fear sums over all the predators perceived, not only the kept percepts.
    pub inv_dist_sum: f32,
}

impl Summary {
    /// Nothing of the category perceived.
    pub const NONE: Summary = Summary {
        count: 0,
        seen: 0,
        nearest: None,
        nearest_dist: f32::INFINITY,
        centroid: Vec3::ZERO,
        mean_heading: Vec3::ZERO,
        mean_velocity: Vec3::ZERO,
        inv_dist_sum: 0.0,
    };

    /// Whether it is [`Summary::NONE`], bit for bit.
    #[inline]
    pub fn is_none(&self) -> bool {
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        self.count == 0
            && self.seen == 0
            && self.nearest.is_none()
            && self.nearest_dist.to_bits() == f32::INFINITY.to_bits()
            && bits(self.centroid) == [0; 3]
            && bits(self.mean_heading) == [0; 3]
            && bits(self.mean_velocity) == [0; 3]
            && self.inv_dist_sum.to_bits() == 0
    }
}

impl Default for Summary {
    fn default() -> Self {
        Summary::NONE
    }
}

/// Sector bounds of seed 000 §4.3 / §4.4: front is `(−front, front)`, the sides run to ±π/2, the
/// rear sectors to `±rear`, and beyond `rear` is the rear. Vertically, a target more than
/// `front` above or below the heading is above or below. As a species key (`senses.sectors`)
/// it sets the bounds of the conditions `InSector` and `AtLevel` and of scripts'
/// `nearest_sector` / `nearest_level`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sectors {
    /// Half-width of the front sector (π/6).
    pub front: f32,
    /// Where the rear sector begins (5π/6).
    pub rear: f32,
}

impl Default for Sectors {
    fn default() -> Self {
        Sectors {
            front: FRAC_PI_6,
            rear: 5.0 * FRAC_PI_6,
        }
    }
}

impl Sectors {
    /// The horizontal sector of a bearing θ (right positive).
    pub fn horizontal(&self, theta: f32) -> Sector {
        if theta > -self.front && theta < self.front {
            Sector::Front
        } else if theta <= -self.front && theta > -FRAC_PI_2 {
            Sector::LeftFront
        } else if theta >= self.front && theta < FRAC_PI_2 {
            Sector::RightFront
        } else if theta <= -FRAC_PI_2 && theta > -self.rear {
            Sector::LeftRear
        } else if theta >= FRAC_PI_2 && theta < self.rear {
            Sector::RightRear
        } else {
            Sector::Rear
        }
    }

    /// The vertical sector of an elevation ω (up positive).
    pub fn vertical(&self, omega: f32) -> Level {
        if omega >= self.front {
            Level::Above
        } else if omega <= -self.front {
            Level::Below
        } else {
            Level::Level
        }
    }
}
