//! Perceived strength, seed 001: what an agent perceives weakens with distance, as the inverse
//! square or the inverse cube of it. Perception itself does not weigh percepts by it; it is a
//! value the decision stage reads of the nearest percept of a category (`Strength(category)` in
//! conditions and blend weights, `this.<category>.nearest_strength` in scripts), computed where
//! it is read, so a species that does not read it pays nothing.
//!
//! The paper's `1/dᵖ` grows without bound as `d → 0`; the engine scales it by `nearᵖ` and caps it
//! at 1, so that it is a number in [0, 1]: 1 at `near` and closer, `(near/d)ᵖ` beyond, 0 when
//! nothing is perceived. Beyond `near` it is the paper's law up to that constant factor.

use serde::{Deserialize, Serialize};

/// Seed 001's exponent of the fall of strength with distance: inverse square (2); the paper's
/// other form, the inverse cube, is 3.
pub const PAPER_POWER: f32 = 2.0;

/// How perceived strength falls with distance (seed 001): `min(1, (near/d)^power)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Strength {
    /// Exponent of the fall: 2 inverse square (the default), 3 inverse cube.
    pub power: f32,
    /// Distance at and within which the strength is 1 (the law has no finite value at 0).
    pub near: f32,
}

impl Default for Strength {
    fn default() -> Self {
        Strength {
            power: PAPER_POWER,
            near: 1.0,
        }
    }
}

impl Strength {
    /// Perceived strength of a thing at distance `d`: 1 within `near`, `(near/d)^power` beyond,
    /// 0 at infinity (nothing perceived).
    #[inline]
    pub fn at(&self, d: f32) -> f32 {
        crate::math::powf(self.near / d.max(self.near), self.power)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-6 * b.abs().max(1e-6)
    }

    #[test]
    fn strength_falls_as_the_inverse_square_beyond_near() {
        let s = Strength {
            power: 2.0,
            near: 0.5,
        };
        // (0.5/2)² = 0.25² = 0.0625.
        assert!(close(s.at(2.0), 0.0625), "{}", s.at(2.0));
        // (0.5/4)² = 0.125² = 0.015625: twice as far, a quarter as strong.
        assert!(close(s.at(4.0), 0.015625), "{}", s.at(4.0));
        // (0.5/0.8)² = 0.625² = 0.390625.
        assert!(close(s.at(0.8), 0.390625), "{}", s.at(0.8));
    }

    #[test]
    fn strength_falls_as_the_inverse_cube_with_power_3() {
        let s = Strength {
            power: 3.0,
            near: 1.0,
        };
        // (1/2)³ = 0.125; (1/4)³ = 0.015625.
        assert!(close(s.at(2.0), 0.125), "{}", s.at(2.0));
        assert!(close(s.at(4.0), 0.015625), "{}", s.at(4.0));
        // near 2, d 5: (2/5)³ = 0.4³ = 0.064.
        let s = Strength {
            power: 3.0,
            near: 2.0,
        };
        assert!(close(s.at(5.0), 0.064), "{}", s.at(5.0));
    }

    #[test]
    fn strength_is_one_within_near_and_zero_when_nothing_is_perceived() {
        let s = Strength {
            power: 2.0,
            near: 0.5,
        };
        for d in [0.0, 0.1, 0.25, 0.5] {
            assert_eq!(s.at(d), 1.0, "d = {d}");
        }
        assert_eq!(s.at(f32::INFINITY), 0.0);
        // Just past `near` it is just below 1: (0.5/0.51)² = 0.961169....
        assert!(close(s.at(0.51), 0.961_169), "{}", s.at(0.51));
    }

    #[test]
    fn the_default_is_the_papers_inverse_square() {
        let s = Strength::default();
        assert_eq!(s.power, 2.0);
        assert_eq!(s.near, 1.0);
        // (1/10)² = 0.01.
        assert!(close(s.at(10.0), 0.01), "{}", s.at(10.0));
    }
}
