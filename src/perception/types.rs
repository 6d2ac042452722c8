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

/// The most objects of one kind (agents, food items, obstacles) a percept can name: a source's
/// index is held in 26 bits. Far above what a scenario may create (10 million agents, 10
/// million food items); a percept of a larger index stops with this message rather than name
/// the wrong object.
pub const MAX_SOURCES: u32 = 1 << 26;

/// A percept's source, category and sense in one word, so that a percept is 32 bytes, not 40
/// (a reef fish keeps eight): the category in the low 3 bits (the part read most: one mask),
/// the sense (1 bit), the source's kind (2) and the source's index (the high 26).
#[derive(Clone, Copy, PartialEq, Eq)]
struct What(u32);

impl What {
    #[inline(always)]
    const fn new(source: Source, category: Category, sense: Sense) -> Self {
        let (kind, index) = match source {
            Source::Agent(i) => (0, i),
            Source::Food(i) => (1, i),
            Source::Obstacle(i) => (2, i),
            Source::Injected => (3, 0),
        };
        assert!(
            index < MAX_SOURCES,
            "a percept names an object past the 2^26th of its kind (perception::MAX_SOURCES)"
        );
        What(category as u32 | (sense as u32) << 3 | kind << 4 | index << 6)
    }

    #[inline(always)]
    fn source(self) -> Source {
        let i = self.0 >> 6;
        match (self.0 >> 4) & 3 {
            0 => Source::Agent(i),
            1 => Source::Food(i),
            2 => Source::Obstacle(i),
            _ => Source::Injected,
        }
    }

    #[inline(always)]
    fn category(self) -> Category {
        // Only `new` writes the field, from a category: it is one of the six. A table of all
        // eight values, `Category::ALL` (index order) and `Other` past it: one load, no
        // compare (a reef fish decodes about a hundred a tick).
        const BY_BITS: [Category; 8] = {
            let mut t = [Category::Other; 8];
            let mut k = 0;
            while k < Category::COUNT {
                t[k] = Category::ALL[k];
                k += 1;
            }
            t
        };
        BY_BITS[(self.0 & 7) as usize]
    }

    #[inline(always)]
    fn sense(self) -> Sense {
        if self.0 & 8 == 0 {
            Sense::Vision
        } else {
            Sense::Smell
        }
    }
}

/// One perceived thing, relative to the perceiving agent. Its source, category and sense are
/// read with [`Percept::source`], [`Percept::category`] and [`Percept::sense`] (held packed).
#[derive(Clone, Copy, PartialEq)]
pub struct Percept {
    what: What,
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

impl std::fmt::Debug for Percept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Percept")
            .field("source", &self.source())
            .field("category", &self.category())
            .field("sense", &self.sense())
            .field("offset", &self.offset)
            .field("dist", &self.dist)
            .field("bearing", &self.bearing)
            .field("elevation", &self.elevation)
            .field("size", &self.size)
            .finish()
    }
}

impl Percept {
    /// A percept of `source`, what it is to the perceiver and the sense that found it, at
    /// `offset` (`dist` away) of size `size`; bearing and elevation 0 (set them where read).
    /// Stops if `source`'s index is [`MAX_SOURCES`] or more.
    #[inline(always)]
    pub const fn new(
        source: Source,
        category: Category,
        sense: Sense,
        offset: Vec3,
        dist: f32,
        size: f32,
    ) -> Self {
        Percept {
            what: What::new(source, category, sense),
            offset,
            dist,
            bearing: 0.0,
            elevation: 0.0,
            size,
        }
    }
    /// What it is.
    #[inline(always)]
    pub fn source(&self) -> Source {
        self.what.source()
    }
    /// What it is to the perceiver.
    #[inline(always)]
    pub fn category(&self) -> Category {
        self.what.category()
    }
    /// Which sense found it.
    #[inline(always)]
    pub fn sense(&self) -> Sense {
        self.what.sense()
    }
    /// Horizontal sector of the bearing.
    pub fn sector(&self) -> Sector {
        Sector::of(self.bearing)
    }
    /// Vertical sector of the elevation.
    pub fn level(&self) -> Level {
        Level::of(self.elevation)
    }
}

/// A kept percept as perception's rows hold it: 20 bytes, not 32 (a reef fish keeps eight).
/// Its size is its source's, read back from the tick's copies, and its bearing and elevation
/// are worked out again when it is read ([`super::Perception::percepts_in`]), from the same
/// offset and the same heading: the same bits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Stored {
    what: What,
    offset: Vec3,
    dist: f32,
}

impl Stored {
    /// `p` without its bearing, elevation and size.
    #[inline(always)]
    pub(super) const fn new(p: &Percept) -> Self {
        Stored {
            what: p.what,
            offset: p.offset,
            dist: p.dist,
        }
    }
    /// Its source.
    #[inline(always)]
    pub(super) fn source(&self) -> Source {
        self.what.source()
    }
    /// The percept, of size `size`, bearing and elevation 0.
    #[inline(always)]
    pub(super) fn percept(&self, size: f32) -> Percept {
        Percept {
            what: self.what,
            offset: self.offset,
            dist: self.dist,
            bearing: 0.0,
            elevation: 0.0,
            size,
        }
    }
}

impl std::fmt::Debug for What {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:?} {:?} {:?}",
            self.source(),
            self.category(),
            self.sense()
        )
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
    /// Mean forward vector of agent percepts (not normalized), zero when none. Scripts alone
    /// read it: in the tick pipeline it is kept only while some species' script names it
    /// ([`crate::script::names_heading`]), and is zero otherwise.
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_percept_is_32_bytes_and_reads_back_what_it_was_made_of() {
        // A reef fish keeps eight: four bytes more each is 32 more per fish. A row holds each
        // in 20.
        assert_eq!(std::mem::size_of::<Percept>(), 32);
        assert_eq!(std::mem::size_of::<Stored>(), 20);
        let last = MAX_SOURCES - 1;
        let sources = [
            Source::Agent(0),
            Source::Agent(7),
            Source::Agent(last),
            Source::Food(0),
            Source::Food(last),
            Source::Obstacle(3),
            Source::Obstacle(last),
            Source::Injected,
        ];
        let offset = Vec3::new(1.0, -2.0, 3.0);
        for source in sources {
            for category in Category::ALL {
                for sense in [Sense::Vision, Sense::Smell] {
                    let p = Percept::new(source, category, sense, offset, 3.5, 0.25);
                    assert_eq!(
                        (p.source(), p.category(), p.sense()),
                        (source, category, sense)
                    );
                    assert_eq!((p.offset, p.dist, p.size), (offset, 3.5, 0.25));
                    assert_eq!((p.bearing, p.elevation), (0.0, 0.0));
                    // As a row holds it: all but its size, which is given back.
                    let held = Stored::new(&p);
                    assert_eq!(held.source(), source);
                    assert_eq!(held.percept(0.25), p);
                    assert_eq!(held.percept(1.5).size, 1.5);
                    // Debug prints the fields as they read.
                    let text = format!("{p:?}");
                    assert!(text.contains(&format!("source: {source:?}")), "{text}");
                    assert!(text.contains(&format!("category: {category:?}")), "{text}");
                }
            }
        }
        // Percepts differing in any one part differ.
        let of = |source, category, sense| Percept::new(source, category, sense, offset, 1.0, 1.0);
        let p = of(Source::Agent(5), Category::Kin, Sense::Vision);
        assert_ne!(p, of(Source::Food(5), Category::Kin, Sense::Vision));
        assert_ne!(p, of(Source::Agent(5), Category::Mate, Sense::Vision));
        assert_ne!(p, of(Source::Agent(5), Category::Kin, Sense::Smell));
        assert_eq!(p, of(Source::Agent(5), Category::Kin, Sense::Vision));
    }

    #[test]
    #[should_panic(expected = "MAX_SOURCES")]
    fn a_percept_of_an_index_past_the_limit_stops_rather_than_name_another_object() {
        let _ = Percept::new(
            Source::Agent(MAX_SOURCES),
            Category::Kin,
            Sense::Vision,
            Vec3::ZERO,
            0.0,
            0.0,
        );
    }
}
