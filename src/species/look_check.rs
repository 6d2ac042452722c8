//! The species' `look` section checked at load: colors written `#rrggbb`, a positive length,
//! behavior colors that name behaviors of the species, custom outlines a viewer can draw. The
//! engine never reads the look; a bad one is still an error, located like every other.

use super::def::look::is_hex_color;
use super::validate::Builder;
use super::*;
use crate::load::did_you_mean;

/// The most points a custom outline may have.
const MAX_OUTLINE: usize = 64;

impl Builder<'_> {
    /// Checks `def.look`, each problem located at its key or value.
    pub(super) fn look(&mut self, def: &SpeciesDef) {
        let look = &def.look;
        if *look == LookDef::default() {
            return;
        }
        self.cursor = super::validate::locate(self.text, "look", 0).map_or(0, |x| x.2);
        self.nums.from = self.cursor;
        if let Some(len) = look.length {
            self.nums.positive("length", len);
        }
        if let Some(c) = &look.color {
            if !is_hex_color(c) {
                self.error_at(
                    &format!("\"{c}\""),
                    format!("look `color`: expected a color written \"#rrggbb\", not \"{c}\""),
                );
            }
        }
        if let Some(ShapeDef::Custom(points)) = &look.shape {
            if !(3..=MAX_OUTLINE).contains(&points.len()) {
                self.error_at(
                    "Custom",
                    format!(
                        "look `Custom` outline: expected 3 to {MAX_OUTLINE} (along, up) points, not {}",
                        points.len()
                    ),
                );
            } else if !points.iter().all(|(a, u)| a.is_finite() && u.is_finite()) {
                self.error_at(
                    "Custom",
                    "look `Custom` outline: every coordinate must be a finite number".into(),
                );
            } else {
                let (lo, hi) = points.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
                    (lo.min(p.0), hi.max(p.0))
                });
                if hi - lo <= 0.0 {
                    self.error_at(
                        "Custom",
                        "look `Custom` outline: the points must span some length along the body"
                            .into(),
                    );
                }
            }
        }
        let paths: Vec<String> = super::compose::flatten(&def.behaviors)
            .into_iter()
            .map(|n| n.path)
            .collect();
        let names: Vec<&str> = paths.iter().map(|p| p.as_str()).collect();
        for (name, c) in &look.behavior_colors {
            if !names.contains(&name.as_str()) {
                self.error_at(
                    &format!("\"{name}\""),
                    format!(
                        "look `behavior_colors` names an undefined behavior \"{name}\"{}",
                        did_you_mean(name, names.iter().copied())
                    ),
                );
            }
            if !is_hex_color(c) {
                self.error_at(
                    &format!("\"{c}\""),
                    format!(
                        "look `behavior_colors`: the color of \"{name}\" must be written \"#rrggbb\", not \"{c}\""
                    ),
                );
            }
        }
        self.cursor = 0;
    }
}
