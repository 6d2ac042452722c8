//! Perception volumes: the vision cone of seed 000 §1 / seed 001 and the non-spherical,
//! body-frame volumes of seed 002 ("larger ahead, smaller behind"; a target is perceived when its
//! distance is at most the distance to the surface `f(x, y, z) = 0` along the same ray).
//!
//! Each volume is a *reach function* of the ray direction in the body frame: the egg (two
//! half-ellipsoids), an ellipsoid whose centre sits ahead of the body, and a superquadric egg
//! whose exponent makes the front blunt (> 2) or pointed (< 2).
//!
//! Seed 001 sees a thing "if any part is in the field": [`Extent::AnyPart`] tests a target's
//! bounding sphere against the cone ([`sphere_in_cone`]) and the range (`d − r ≤ v_r`). The
//! engine's default stays [`Extent::Centre`] (the centre must be in the field), which every
//! shipped species was tuned with; the paper's form is a `senses.extent` away.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Smallest semi-axis the reach functions divide by (a zero axis reaches nowhere along it).
const TINY: f32 = 1e-6;

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
    /// An ellipsoid of semi-axes `length` (along z), `side` (x) and `up` (y) whose centre lies
    /// `offset` ahead of the body (negative: behind): it reaches `length + offset` ahead and
    /// `length − offset` behind. The body must be inside (`|offset| < length`).
    Ellipsoid {
        /// How far ahead of the body the centre lies.
        offset: f32,
        /// Semi-axis along the heading.
        length: f32,
        /// Semi-axis to either side.
        side: f32,
        /// Semi-axis up and down.
        up: f32,
    },
    /// The egg with an exponent: the surface `|x/side|^p + |y/up|^p + |z/a_z|^p = 1`, `a_z` =
    /// `ahead` for z > 0 and `behind` for z < 0. `p` = 2 is the egg; `p` > 2 is blunter (towards
    /// a box: it reaches farther along the diagonals), `p` < 2 more pointed (towards a
    /// double cone at `p` = 1).
    Superquadric {
        /// Reach straight ahead.
        ahead: f32,
        /// Reach straight behind.
        behind: f32,
        /// Reach to either side.
        side: f32,
        /// Reach up and down.
        up: f32,
        /// Exponent `p` (2: the egg).
        #[serde(default = "two")]
        exponent: f32,
    },
}

/// The superquadric's default exponent: 2, the egg.
pub const DEFAULT_EXPONENT: f32 = 2.0;

fn two() -> f32 {
    DEFAULT_EXPONENT
}

/// Which part of a target must be in the vision field for it to be seen (seed 001).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Extent {
    /// Its centre: the engine's default (what the shipped species were tuned with).
    #[default]
    Centre,
    /// Any part of its bounding sphere (seed 001: "visible if any part is in the field"): the
    /// angle to its centre minus `asin(r/d)` within the half-angle, and `d − r ≤ v_r`.
    AnyPart,
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
                let sq = |v: f32| v * v;
                let q = sq(dir.x / side.max(TINY))
                    + sq(dir.y / up.max(TINY))
                    + sq(dir.z / az.max(TINY));
                if q > 0.0 {
                    1.0 / q.sqrt()
                } else {
                    0.0
                }
            }
            Volume::Ellipsoid {
                offset,
                length,
                side,
                up,
            } => ellipsoid_reach(dir, offset, length, side, up),
            Volume::Superquadric {
                ahead,
                behind,
                side,
                up,
                exponent,
            } => {
                let az = if dir.z >= 0.0 { ahead } else { behind };
                let p = exponent.max(TINY);
                let q = crate::math::powf(dir.x.abs() / side.max(TINY), p)
                    + crate::math::powf(dir.y.abs() / up.max(TINY), p)
                    + crate::math::powf(dir.z.abs() / az.max(TINY), p);
                if q > 0.0 {
                    crate::math::powf(q, -1.0 / p)
                } else {
                    0.0
                }
            }
        }
    }

    /// An upper bound of the reach in every direction (for the spatial query radius).
    pub fn max_reach(&self) -> f32 {
        match *self {
            Volume::Egg {
                ahead,
                behind,
                side,
                up,
            } => ahead.max(behind).max(side).max(up),
            // The centre's distance plus the longest semi-axis.
            Volume::Ellipsoid {
                offset,
                length,
                side,
                up,
            } => offset.abs() + length.max(side).max(up),
            Volume::Superquadric {
                ahead,
                behind,
                side,
                up,
                exponent,
            } => {
                let az = ahead.max(behind);
                if exponent <= 2.0 {
                    // Inside the egg of the same axes.
                    az.max(side).max(up)
                } else {
                    // Inside the box of the same axes.
                    (az * az + side * side + up * up).sqrt()
                }
            }
        }
    }

    /// Whether a target at body-frame offset `local` is inside the volume.
    pub fn contains(&self, local: Vec3) -> bool {
        self.contains_sphere(local, 0.0)
    }

    /// Whether any part of a sphere of radius `radius` centred at body-frame offset `local` is
    /// inside, measured along the ray to its centre: `d − r ≤ reach`.
    pub fn contains_sphere(&self, local: Vec3, radius: f32) -> bool {
        let d = local.length();
        if d <= radius {
            return true;
        }
        d - radius <= self.reach(local / d)
    }
}

/// Reach of an ellipsoid centred `offset` ahead: the positive root `t` of
/// `|(t·dir − c)/a|² = 1`, `c = (0, 0, offset)`, `a = (side, up, length)`. With `u = dir/a` and
/// `w = c/a`: `t²·|u|² − 2t·(u·w) + |w|² − 1 = 0`, so
/// `t = ((u·w) + √((u·w)² − |u|²·(|w|² − 1))) / |u|²`.
fn ellipsoid_reach(dir: Vec3, offset: f32, length: f32, side: f32, up: f32) -> f32 {
    let a = Vec3::new(side.max(TINY), up.max(TINY), length.max(TINY));
    let u = dir / a;
    let w = offset / a.z;
    let uu = u.length_squared();
    let uw = u.z * w;
    let disc = uw * uw - uu * (w * w - 1.0);
    // With the body inside (`|w| < 1`, checked at load) the discriminant is positive for every
    // ray. A zero direction (0/0) or a body outside (a ray that misses: √ of a negative) gives
    // NaN, which `max` turns into 0: it reaches nowhere.
    ((uw + disc.sqrt()) / uu).max(0.0)
}

/// Whether `offset` lies within `half_angle` of `forward` (the vision cone; ±150° by default).
/// A zero offset is inside.
pub fn in_cone(forward: Vec3, offset: Vec3, half_angle: f32) -> bool {
    let d = offset.length();
    if d == 0.0 {
        return true;
    }
    forward.dot(offset) / d >= crate::math::cos(half_angle) - 1e-6
}

/// Whether any part of a sphere of radius `radius` centred at `offset` lies within `half_angle`
/// of `forward` (unit): the angle to its centre minus its angular radius `asin(r/d)` is at most
/// the half-angle (seed 001). A sphere around the eye is always inside.
pub fn sphere_in_cone(forward: Vec3, offset: Vec3, radius: f32, half_angle: f32) -> bool {
    let d = offset.length();
    if d <= radius {
        return true;
    }
    let to_centre = crate::math::acos((forward.dot(offset) / d).clamp(-1.0, 1.0));
    to_centre - crate::math::asin(radius / d) <= half_angle + 1e-6
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

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-4
    }

    #[test]
    fn ellipsoid_reaches_its_axes_and_a_diagonal() {
        // Centre 2 ahead, semi-axes 6 (z), 3 (x), 2 (y).
        let v = Volume::Ellipsoid {
            offset: 2.0,
            length: 6.0,
            side: 3.0,
            up: 2.0,
        };
        // Ahead 6 + 2, behind 6 − 2.
        assert!(close(v.reach(Vec3::Z), 8.0), "{}", v.reach(Vec3::Z));
        assert!(close(v.reach(-Vec3::Z), 4.0));
        // Sideways through the body (z = 0): 3·√(1 − (2/6)²) = 2√2 = 2.8284; up 2·√(8/9) = 1.8856.
        assert!(close(v.reach(Vec3::X), 2.828_427));
        assert!(close(v.reach(-Vec3::X), 2.828_427));
        assert!(close(v.reach(Vec3::Y), 1.885_618));
        // Ahead-left diagonal, s = 1/√2: u = (s/3, 0, s/6), w = 1/3, |u|² = 5/72, u·w = s/18,
        // t = (s/18 + √((s/18)² + (5/72)·(8/9)))/(5/72) = 4.1878 (and (t·s/3)² + ((t·s − 2)/6)² = 1).
        let d = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!(close(v.reach(d), 4.187_839), "{}", v.reach(d));
        // Up-behind diagonal: u = (0, s/2, −s/6), u·w = −s/18 → t = 1.6·√2 = 2.2627.
        let d = Vec3::new(0.0, 1.0, -1.0).normalize();
        assert!(close(v.reach(d), 2.262_742), "{}", v.reach(d));
        assert!(v.contains(Vec3::new(0.0, 0.0, 7.9)));
        assert!(!v.contains(Vec3::new(0.0, 0.0, -4.1)));
        // An upper bound: |offset| + the longest semi-axis.
        assert_eq!(v.max_reach(), 8.0);
        // Centred (offset 0) it is the plain ellipsoid: reach 6 both ways.
        let c = Volume::Ellipsoid {
            offset: 0.0,
            length: 6.0,
            side: 3.0,
            up: 2.0,
        };
        assert!(close(c.reach(-Vec3::Z), 6.0));
        assert!(close(c.reach(Vec3::X), 3.0));
    }

    #[test]
    fn superquadric_is_the_egg_at_exponent_two_blunter_above_pointed_below() {
        let sq = |exponent| Volume::Superquadric {
            ahead: 10.0,
            behind: 3.0,
            side: 5.0,
            up: 4.0,
            exponent,
        };
        for p in [1.0, 2.0, 4.0] {
            let v = sq(p);
            assert!(close(v.reach(Vec3::Z), 10.0), "p {p}");
            assert!(close(v.reach(-Vec3::Z), 3.0), "p {p}");
            assert!(close(v.reach(-Vec3::X), 5.0), "p {p}");
            assert!(close(v.reach(-Vec3::Y), 4.0), "p {p}");
        }
        // Ahead-left diagonal, s = 1/√2: ((s/5)^p + (s/10)^p)^(−1/p).
        // p = 2: 6.3246 (the egg's); p = 4: 6.9647 (blunter); p = 1: 4.7140 (pointed).
        let d = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!(close(sq(2.0).reach(d), 6.324_555));
        assert!(close(sq(4.0).reach(d), 6.964_706), "{}", sq(4.0).reach(d));
        assert!(close(sq(1.0).reach(d), 4.714_045), "{}", sq(1.0).reach(d));
        // Up-behind diagonal, ((s/4)^p + (s/3)^p)^(−1/p): p = 4: 3.9609, p = 1: 2.4244.
        let d = Vec3::new(0.0, 1.0, -1.0).normalize();
        assert!(close(sq(4.0).reach(d), 3.960_853), "{}", sq(4.0).reach(d));
        assert!(close(sq(1.0).reach(d), 2.424_366), "{}", sq(1.0).reach(d));
        // The egg's reach along a left-up-behind ray, for the same axes.
        let egg = Volume::Egg {
            ahead: 10.0,
            behind: 3.0,
            side: 5.0,
            up: 4.0,
        };
        let d = Vec3::new(1.0, 2.0, -3.0).normalize();
        assert!(close(sq(2.0).reach(d), egg.reach(d)));
        // Bounds: the longest axis up to p = 2, the box's diagonal √(10² + 5² + 4²) above.
        assert_eq!(sq(2.0).max_reach(), 10.0);
        assert!(close(sq(4.0).max_reach(), 141f32.sqrt()));
    }

    #[test]
    fn the_superquadric_exponent_defaults_to_the_egg_and_no_ray_reaches_nowhere() {
        let v: Volume =
            ron::from_str("Superquadric(ahead: 10.0, behind: 3.0, side: 5.0, up: 4.0)").unwrap();
        assert_eq!(
            v,
            Volume::Superquadric {
                ahead: 10.0,
                behind: 3.0,
                side: 5.0,
                up: 4.0,
                exponent: 2.0,
            }
        );
        // A zero direction reaches nowhere (not infinitely far).
        let ell = Volume::Ellipsoid {
            offset: 2.0,
            length: 6.0,
            side: 3.0,
            up: 2.0,
        };
        let egg = Volume::Egg {
            ahead: 10.0,
            behind: 3.0,
            side: 5.0,
            up: 4.0,
        };
        for v in [v, ell, egg] {
            assert_eq!(v.reach(Vec3::ZERO), 0.0, "{v:?}");
        }
        // A body outside its ellipsoid (refused at load): rays that miss reach nowhere.
        let outside = Volume::Ellipsoid {
            offset: 10.0,
            length: 4.0,
            side: 3.0,
            up: 2.0,
        };
        assert_eq!(outside.reach(Vec3::X), 0.0);
        assert_eq!(outside.reach(-Vec3::Z), 0.0);
    }

    #[test]
    fn a_sphere_counts_when_any_part_of_it_is_inside() {
        let egg = Volume::Egg {
            ahead: 10.0,
            behind: 3.0,
            side: 5.0,
            up: 4.0,
        };
        // Centre 12 ahead, radius 2.5: 12 − 2.5 ≤ 10; radius 1.5: 10.5 > 10.
        assert!(egg.contains_sphere(Vec3::new(0.0, 0.0, 12.0), 2.5));
        assert!(!egg.contains_sphere(Vec3::new(0.0, 0.0, 12.0), 1.5));
        // Exactly touching: 12 − 2 = 10.
        assert!(egg.contains_sphere(Vec3::new(0.0, 0.0, 12.0), 2.0));
        // A body around the eye.
        assert!(egg.contains_sphere(Vec3::new(0.0, 0.0, -1.0), 1.0));
    }

    #[test]
    fn a_large_sphere_centred_outside_the_cone_is_seen_by_its_edge() {
        // Cone of half-angle 60°; a sphere at distance 10, 70° off the heading (10° outside).
        let h = 60f32.to_radians();
        let a = 70f32.to_radians();
        let at = Vec3::new(crate::math::sin(a), 0.0, crate::math::cos(a)) * 10.0;
        assert!(!in_cone(Vec3::Z, at, h));
        // Radius 3: asin(0.3) = 17.46°, 70 − 17.46 = 52.5 ≤ 60 → seen.
        assert!(sphere_in_cone(Vec3::Z, at, 3.0, h));
        // Radius 1: asin(0.1) = 5.74°, 70 − 5.74 = 64.3 > 60 → not seen.
        assert!(!sphere_in_cone(Vec3::Z, at, 1.0, h));
        // Radius 0: the centre test.
        assert!(!sphere_in_cone(Vec3::Z, at, 0.0, h));
        assert!(sphere_in_cone(Vec3::Z, Vec3::new(0.0, 0.0, 5.0), 0.0, h));
        // Straight behind, touching the eye (d = r = 2): inside; just apart (r = 1.9): the
        // angle 180° − asin(0.95) = 108.2° > 60°.
        assert!(sphere_in_cone(Vec3::Z, Vec3::new(0.0, 0.0, -2.0), 2.0, h));
        assert!(!sphere_in_cone(Vec3::Z, Vec3::new(0.0, 0.0, -2.0), 1.9, h));
        // Behind the 150° cone (174°), radius 1 at distance 10: 174.3 − 5.74 = 168.5 > 150; with
        // radius 5: asin(0.5) = 30°, 174.3 − 30 = 144.3 ≤ 150.
        let h = 150f32.to_radians();
        let behind = Vec3::new(0.1, 0.0, -1.0).normalize() * 10.0;
        assert!(!sphere_in_cone(Vec3::Z, behind, 1.0, h));
        assert!(sphere_in_cone(Vec3::Z, behind, 5.0, h));
    }

    #[test]
    fn cone_of_150_degrees_excludes_the_blind_spot() {
        let h = 150f32.to_radians();
        assert!(in_cone(Vec3::Z, Vec3::new(1.0, 0.0, -1.0), h)); // 135°
        assert!(!in_cone(Vec3::Z, Vec3::new(0.1, 0.0, -1.0), h)); // ~174°
                                                                  // Exactly on the edge (90° off a ±90° cone) is inside, for both tests: the rounding
                                                                  // tolerance leans towards seeing.
        let edge = std::f32::consts::FRAC_PI_2;
        assert!(in_cone(Vec3::Z, Vec3::X, edge));
        assert!(sphere_in_cone(Vec3::Z, Vec3::X, 0.0, edge));
    }
}
