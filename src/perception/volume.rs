//! Perception volumes: the vision cone of seed 000 / 001 and the non-spherical, body-frame volume
//! of seed 002 ("larger ahead, smaller behind").

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A closed surface around the body, in the body frame (x left, y up, z forward). A target is
/// perceived when its distance is at most the distance to the surface along the same ray
/// (seed 002).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Volume {
    /// Two half-ellipsoids joined at the body: semi-axis `ahead` for z > 0, `behind` for z < 0,
    /// `side` along x and `up` along y.
    Egg {
        /// Reach straight ahead.
        ahead: f32,
        /// Reach straight behind.
        behind: f32,
        /// Reach to either side.
        side: f32,
        /// Reach up and down.
        up: f32,
    },
}

impl Volume {
    /// Distance from the body to the surface along the body-frame direction `dir` (unit).
    pub fn reach(&self, dir: Vec3) -> f32 {
        match *self {
            Volume::Egg {
                ahead,
                behind,
                side,
                up,
            } => {
                let az = if dir.z >= 0.0 { ahead } else { behind };
                let q = (dir.x / side.max(1e-6)).powi(2)
                    + (dir.y / up.max(1e-6)).powi(2)
                    + (dir.z / az.max(1e-6)).powi(2);
                if q > 0.0 {
                    1.0 / q.sqrt()
                } else {
                    0.0
                }
            }
        }
    }

    /// Largest reach in any direction (for the spatial query radius).
    pub fn max_reach(&self) -> f32 {
        match *self {
            Volume::Egg {
                ahead,
                behind,
                side,
                up,
            } => ahead.max(behind).max(side).max(up),
        }
    }

    /// Whether a target at body-frame offset `local` is inside the volume.
    pub fn contains(&self, local: Vec3) -> bool {
        let d = local.length();
        if d == 0.0 {
            return true;
        }
        d <= self.reach(local / d)
    }
}

/// Whether `offset` lies within `half_angle` of `forward` (the vision cone; ±150° by default).
/// A zero offset is inside.
pub fn in_cone(forward: Vec3, offset: Vec3, half_angle: f32) -> bool {
    let d = offset.length();
    if d == 0.0 {
        return true;
    }
    forward.dot(offset) / d >= half_angle.cos() - 1e-6
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn egg_is_larger_ahead_than_behind() {
        let v = Volume::Egg {
            ahead: 10.0,
            behind: 3.0,
            side: 5.0,
            up: 4.0,
        };
        assert!((v.reach(Vec3::Z) - 10.0).abs() < 1e-6);
        assert!((v.reach(-Vec3::Z) - 3.0).abs() < 1e-6);
        assert!((v.reach(Vec3::X) - 5.0).abs() < 1e-6);
        // Diagonal ahead-left: 1/sqrt((s/5)² + (s/10)²), s = 1/√2 → 6.3246.
        let d = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!((v.reach(d) - 6.324_555).abs() < 1e-4);
        assert!(v.contains(Vec3::new(0.0, 0.0, 9.0)));
        assert!(!v.contains(Vec3::new(0.0, 0.0, -4.0)));
    }

    #[test]
    fn cone_of_150_degrees_excludes_the_blind_spot() {
        let h = 150f32.to_radians();
        assert!(in_cone(Vec3::Z, Vec3::new(1.0, 0.0, -1.0), h)); // 135°
        assert!(!in_cone(Vec3::Z, Vec3::new(0.1, 0.0, -1.0), h)); // ~174°
    }
}
