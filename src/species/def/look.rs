//! A species' look in viewers: the body's shape family, its drawn length and color, and the
//! colors of its behaviors. Read from the species file's optional `look` section; the engine never
//! reads it, only recordings (`world.json`) and the live page carry it to the viewer.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

use super::BodyDef;

/// The shape family a viewer draws a body with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ShapeDef {
    /// A fish: spindle body, tail fin, dorsal fin.
    Fish,
    /// A shark: long body, tall dorsal fin, pectoral fins, swept tail.
    Shark,
    /// A jellyfish: a bell with trailing tentacles; its axis is the heading.
    Jelly,
    /// A walker (a soldier): an upright figure standing on the ground, facing its heading.
    Walker,
    /// A flat silhouette given as its outline in the side view: `(along, up)` points in body
    /// lengths, the nose towards +along (3 to 64 points, drawn as a slab).
    Custom(Vec<(f32, f32)>),
}

/// The `look` section of a species file; every field may be left out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct LookDef {
    /// Shape family; left out: `Walker` for bodies `on_ground`, `Jelly` for `upright` ones,
    /// `Fish` otherwise.
    pub shape: Option<ShapeDef>,
    /// Drawn length (a walker's height) in world units; left out: the body's length.
    pub length: Option<f32>,
    /// Body color (`#rrggbb`); left out: the species' `color`.
    pub color: Option<String>,
    /// Colors (`#rrggbb`) of some behaviors, by behavior name, over the viewer's palette.
    pub behavior_colors: BTreeMap<String, String>,
}

/// A species' look with every default filled in, as `world.json` carries it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Look<'a> {
    /// `fish`, `shark`, `jelly`, `walker` or `custom`.
    pub shape: &'static str,
    /// The outline of a `custom` shape (empty otherwise).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub outline: Vec<[f32; 2]>,
    /// Drawn length in world units.
    pub length: f32,
    /// Body color.
    pub color: &'a str,
    /// Colors of some behaviors, by name.
    pub behavior_colors: &'a BTreeMap<String, String>,
}

impl LookDef {
    /// The shape drawn for a body: the one written, or the body's default.
    pub fn shape_for(&self, body: &BodyDef) -> ShapeDef {
        match &self.shape {
            Some(s) => s.clone(),
            None if body.on_ground => ShapeDef::Walker,
            None if body.upright => ShapeDef::Jelly,
            None => ShapeDef::Fish,
        }
    }

    /// This look with its defaults taken from the species' `color` and `body`.
    pub fn resolve<'a>(&'a self, color: &'a str, body: &BodyDef) -> Look<'a> {
        let (shape, outline) = match self.shape_for(body) {
            ShapeDef::Fish => ("fish", Vec::new()),
            ShapeDef::Shark => ("shark", Vec::new()),
            ShapeDef::Jelly => ("jelly", Vec::new()),
            ShapeDef::Walker => ("walker", Vec::new()),
            ShapeDef::Custom(points) => ("custom", points.iter().map(|&(a, u)| [a, u]).collect()),
        };
        Look {
            shape,
            outline,
            length: self.length.unwrap_or(body.size.z),
            color: self.color.as_deref().unwrap_or(color),
            behavior_colors: &self.behavior_colors,
        }
    }
}

/// Whether `s` is a color written `#rrggbb`.
pub fn is_hex_color(s: &str) -> bool {
    s.len() == 7 && s.starts_with('#') && s[1..].chars().all(|c| c.is_ascii_hexdigit())
}
