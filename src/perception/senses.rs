//! What a species brings to stage 2, resolved at load time: its senses (vision sphere and cone
//! or a custom volume, smell, occlusion, how many percepts it keeps; seed 000 §1, seed 001),
//! what every other species is to it ([`Relations`]), and what its behaviors read of the stage
//! ([`Reads`]). Plain data: the walks read it, nothing here reads the world.

use super::Sectors;
use super::{Category, Extent, GroupQueries, Occluders, Strength, Volume};
use super::{DEFAULT_PERCEPTS, MAX_PERCEPTS};
use serde::{Deserialize, Serialize};

/// A species' senses (defaults from seed 000: vision ±150°, smell farther than vision).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SenseParams {
    /// Vision radius v_r.
    pub vision_radius: f32,
    /// Half-angle of the vision cone (rad); 150° by default.
    pub vision_half_angle: f32,
    /// Smell radius O_r (≥ v_r to matter).
    pub smell_radius: f32,
    /// A custom body-frame volume replacing the vision sphere and cone.
    pub volume: Option<Volume>,
    /// Whether obstacles hide what lies fully behind them ([`occlusion`](super::occlusion)).
    pub occlusion: bool,
    /// What obstacles occlude with: their own shape (default) or their bounding sphere
    /// (seed 001's form).
    pub occluders: Occluders,
    /// What must lie in the vision field for a thing to be seen: its centre (default) or any
    /// part of its bounding sphere (seed 001's form, [`Extent::AnyPart`]).
    pub extent: Extent,
    /// Percepts kept per agent (the nearest ones, and always the nearest of each category), at
    /// least one per [`Category`] and at most [`MAX_PERCEPTS`]. Summaries and group sums still cover everything perceived.
    pub max_percepts: usize,
    /// A bound on the kin perceived: the nearest `n` kin within range (a topological
    /// neighborhood), not every kin within range (seed 000 §1's metric one, the default). The
    /// walk grows its box outward and stops once it holds the nearest `n`, so the cost per
    /// perceiver stays bounded as a school packs tighter. Agents of other categories
    /// (predators, food, others) are perceived within range as ever; mates are kin of the other
    /// sex, so they come from the nearest `n`.
    pub neighbors: Option<u32>,
    /// How perceived strength falls with distance (seed 001): read by `Strength(category)` and
    /// scripts, never by perception itself.
    pub strength: Strength,
    /// Direction sector bounds (seed 000 §4.3–4.4: π/6, 5π/6) of the conditions `InSector` and
    /// `AtLevel` and of scripts' `nearest_sector` / `nearest_level`. `Chase` and `Escape` have
    /// their own (`front`, `rear`), with the same defaults.
    pub sectors: Sectors,
}

impl Default for SenseParams {
    fn default() -> Self {
        SenseParams {
            vision_radius: 10.0,
            vision_half_angle: 150f32.to_radians(),
            smell_radius: 20.0,
            volume: None,
            occlusion: true,
            occluders: Occluders::Shape,
            extent: Extent::Centre,
            max_percepts: DEFAULT_PERCEPTS,
            neighbors: None,
            strength: Strength::default(),
            sectors: Sectors::default(),
        }
    }
}

impl SenseParams {
    /// Percepts kept per agent, within `Category::COUNT..=MAX_PERCEPTS`: fewer slots could not
    /// hold the nearest of each category.
    pub fn slots(&self) -> usize {
        self.max_percepts.clamp(Category::COUNT, MAX_PERCEPTS)
    }
    /// The radius a spatial query must cover.
    pub fn query_radius(&self) -> f32 {
        let v = self.volume.map_or(self.vision_radius, |v| v.max_reach());
        v.max(self.smell_radius).max(0.0)
    }
}

/// What each species is to each other one, resolved at load time.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Relations {
    n: usize,
    cats: Vec<Option<Category>>,
    eats_items: Vec<bool>,
    mates: Vec<bool>,
}

impl Relations {
    /// A table for `n` species where everything is ignored.
    pub fn new(n: usize) -> Self {
        Relations {
            n,
            cats: vec![None; n * n],
            eats_items: vec![false; n],
            mates: vec![false; n],
        }
    }
    /// Sets what `other` is to `perceiver`.
    pub fn set(&mut self, perceiver: usize, other: usize, cat: Option<Category>) {
        self.cats[perceiver * self.n + other] = cat;
    }
    /// What `other` is to `perceiver`.
    #[inline]
    pub fn get(&self, perceiver: usize, other: usize) -> Option<Category> {
        self.cats.get(perceiver * self.n + other).copied().flatten()
    }
    /// What every species is to `perceiver`, by species index.
    #[inline]
    pub(super) fn row(&self, perceiver: usize) -> &[Option<Category>] {
        self.cats
            .get(perceiver * self.n..(perceiver + 1) * self.n)
            .unwrap_or(&[])
    }
    /// Declares that `perceiver` eats food items.
    pub fn set_eats_items(&mut self, perceiver: usize, yes: bool) {
        self.eats_items[perceiver] = yes;
    }
    /// Whether `perceiver` eats food items.
    pub fn eats_items(&self, perceiver: usize) -> bool {
        self.eats_items.get(perceiver).copied().unwrap_or(false)
    }
    /// Declares that kin of the other sex are mates for `perceiver`.
    pub fn set_mates(&mut self, perceiver: usize, yes: bool) {
        self.mates[perceiver] = yes;
    }
    /// Whether kin of the other sex are mates for `perceiver`.
    #[inline]
    pub(super) fn mates(&self, perceiver: usize) -> bool {
        self.mates.get(perceiver).copied().unwrap_or(false)
    }
    /// Number of species.
    pub fn len(&self) -> usize {
        self.n
    }
    /// Whether the table has no species.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }
}

/// What a species' behaviors read of its perception, worked out at load time (see
/// `tick::reads`), so that the stage does only that work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reads {
    /// Whether any behavior, condition, script or drive reads individual percepts. Without, the
    /// agent keeps none (its summaries and group sums are still complete).
    pub percepts: bool,
    /// Whether it reads agent and food percepts individually too (without, only obstacles are
    /// kept, and agents are folded into summaries and group sums alone).
    pub agent_percepts: bool,
    /// Distance within which agent percepts get their bearing and elevation (obstacles and the
    /// nearest of each category always do); `None`: every percept kept.
    pub bearing_range: Option<f32>,
    /// Neighborhood sums its group rules read.
    pub groups: GroupQueries,
    /// Whether the mean heading of a category is read (by a script that names it); without,
    /// the kin kernel leaves it zero, and while no species reads it no summary keeps it.
    pub headings: bool,
}

impl Default for Reads {
    /// Everything: every percept kept with its bearing, no group sums.
    fn default() -> Self {
        Reads {
            percepts: true,
            agent_percepts: true,
            bearing_range: None,
            groups: GroupQueries::new(),
            headings: true,
        }
    }
}
