//! Body frames and angle conventions shared by every stage (seed 002 §"Body frame").
//!
//! World up is +Y. A body frame has z forward, y dorsal (up) and x to the left. Headings are kept
//! as `(yaw, pitch)`: yaw about the world up axis, pitch about the body's lateral axis. A turn to the
//! right is a positive yaw, a turn up a positive pitch. There is never any roll, so the frame is a
//! pure function of `(yaw, pitch)` and `|pitch| < 90°` keeps the body upright ("self-balancing").

use glam::Vec3;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// World up axis.
pub const UP: Vec3 = Vec3::Y;

/// Largest pitch magnitude a body may take, just inside 90°.
pub const PITCH_LIMIT: f32 = FRAC_PI_2 - 1e-3;

/// Forward unit vector for a heading. Yaw 0 faces +Z; positive yaw turns toward −X (the right).
#[inline]
pub fn forward(yaw: f32, pitch: f32) -> Vec3 {
    let (sy, cy) = crate::math::sin_cos(yaw);
    let (sp, cp) = crate::math::sin_cos(pitch);
    Vec3::new(-sy * cp, sp, cy * cp)
}

/// Left unit vector of a body with this yaw (horizontal: no roll).
#[inline]
pub fn left(yaw: f32) -> Vec3 {
    let (sy, cy) = crate::math::sin_cos(yaw);
    Vec3::new(cy, 0.0, sy)
}

/// Dorsal (up) unit vector of a body with this heading; always within 90° of world up.
#[inline]
pub fn dorsal(yaw: f32, pitch: f32) -> Vec3 {
    forward(yaw, pitch).cross(left(yaw))
}

/// Wraps an angle into (−π, π].
#[inline]
pub fn wrap(a: f32) -> f32 {
    // Already in range (the common case): `a % TAU` would give `a` back unchanged.
    if a > -PI && a <= PI {
        return a;
    }
    if !a.is_finite() {
        return 0.0;
    }
    // `a % TAU` is exact and returns `a` itself when |a| < TAU: skip the slow `fmodf` then.
    let mut a = if a.abs() < TAU { a } else { a % TAU };
    if a <= -PI {
        a += TAU;
    } else if a > PI {
        a -= TAU;
    }
    a
}

/// `(yaw, pitch)` of a direction; a zero or non-finite direction gives `None`.
#[inline]
pub fn heading_of(dir: Vec3) -> Option<(f32, f32)> {
    let len = dir.length();
    if !len.is_finite() || len <= 1e-12 {
        return None;
    }
    let d = dir / len;
    let yaw = atan2(-d.x, d.z);
    // asin(±0) = ±0: level directions (every one in a flat world) skip the call.
    let sy = d.y.clamp(-1.0, 1.0);
    let pitch = if sy == 0.0 { sy } else { crate::math::asin(sy) };
    let pitch = pitch.clamp(-PITCH_LIMIT, PITCH_LIMIT);
    Some((yaw, pitch))
}

/// `y.atan2(x)` for finite arguments, within 5 × 10⁻⁷ rad of it (two units in the last place
/// near ±π), computed here rather than by the platform's math library: every tick turns every
/// agent through it, and the same arithmetic gives the same bits on every machine. Signed zeros
/// follow `f32::atan2`.
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    if x.is_nan() || y.is_nan() {
        return f32::NAN;
    }
    let (ax, ay) = (x.abs(), y.abs());
    if ay == 0.0 && ax == 0.0 {
        // atan2(±0, +0) = ±0, atan2(±0, −0) = ±π.
        return if x.is_sign_negative() {
            PI.copysign(y)
        } else {
            y
        };
    }
    // The angle of (|x|, |y|) in [0, π/2], from the arctangent of a ratio in [0, 1].
    let a = if ay > ax {
        FRAC_PI_2 - atan_unit(ax / ay)
    } else {
        atan_unit(ay / ax)
    };
    let a = if x.is_sign_negative() { PI - a } else { a };
    a.copysign(y)
}

/// `t.atan()` for `t` in [0, 1] (Cephes' single-precision `atanf`: above tan(π/8), the
/// argument is moved by π/4; a degree-9 odd polynomial does the rest).
#[inline]
fn atan_unit(t: f32) -> f32 {
    let (base, x) = if t > 0.414_213_57 {
        (FRAC_PI_4, (t - 1.0) / (t + 1.0))
    } else {
        (0.0, t)
    };
    let z = x * x;
    base + ((((8.053_744_5e-2 * z - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1)
        * z
        * x
        + x)
}

/// `x.tan()` for `x` in [−π/4, π/4], within 2 × 10⁻⁷ of it (Cephes' single-precision `tanf`
/// polynomial), computed here for the same reasons as [`atan2`].
#[inline]
pub fn tan_quarter(x: f32) -> f32 {
    let z = x * x;
    (((((9.385_402e-3 * z + 3.119_922_3e-3) * z + 2.443_013_5e-2) * z + 5.341_128e-2) * z
        + 1.333_88e-1)
        * z
        + 3.333_315_7e-1)
        * z
        * x
        + x
}

/// Horizontal bearing θ and elevation ω of `offset` (target − self) seen from a body with heading
/// `(yaw, pitch)` (seed 002 "direction adjustment"): θ is the signed angle between the forward and
/// target projections on the ground plane (right positive), ω the difference of elevations (up
/// positive). A zero offset has bearing and elevation 0.
#[inline]
pub fn bearing_elevation(yaw: f32, pitch: f32, offset: Vec3) -> (f32, f32) {
    match heading_of(offset) {
        Some((ty, tp)) => {
            let horizontal = offset.x * offset.x + offset.z * offset.z;
            let theta = if horizontal > 1e-12 {
                wrap(ty - yaw)
            } else {
                0.0
            };
            (theta, tp - pitch)
        }
        None => (0.0, 0.0),
    }
}

/// The kinematic state a primitive steers from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// Position.
    pub pos: Vec3,
    /// Yaw (rad, right positive).
    pub yaw: f32,
    /// Pitch (rad, up positive).
    pub pitch: f32,
    /// Current speed Vc.
    pub speed: f32,
}

impl Kinematics {
    /// Forward unit vector.
    #[inline]
    pub fn forward(&self) -> Vec3 {
        forward(self.yaw, self.pitch)
    }
    /// Velocity.
    #[inline]
    pub fn velocity(&self) -> Vec3 {
        self.forward() * self.speed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    // The platform's library is what is compared against.
    #[allow(clippy::disallowed_methods)]
    fn atan2_and_tan_match_the_math_library() {
        let mut rng = crate::world::Rng::new(3, 0);
        let mut worst = (0.0f32, 0.0f32);
        for k in 0..200_000 {
            // Wide magnitudes, both signs, and exact axes now and then.
            let m = 10f32.powf(rng.range(-6.0, 6.0));
            let (mut x, mut y) = (rng.range(-1.0, 1.0) * m, rng.range(-1.0, 1.0) * m);
            if k % 97 == 0 {
                x = 0.0;
            }
            if k % 89 == 0 {
                y = 0.0;
            }
            worst.0 = worst.0.max((atan2(y, x) - y.atan2(x)).abs());
            let t = rng.range(-FRAC_PI_4, FRAC_PI_4);
            worst.1 = worst.1.max((tan_quarter(t) - t.tan()).abs());
        }
        assert!(worst.0 <= 5e-7, "atan2 off by {}", worst.0);
        assert!(worst.1 <= 2e-7, "tan off by {}", worst.1);
        for (y, x) in [
            (0.0f32, 0.0f32),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, 1.0),
            (-1.0, -1.0),
        ] {
            let (a, b) = (atan2(y, x), y.atan2(x));
            assert!((a - b).abs() <= 5e-7 && a.is_sign_negative() == b.is_sign_negative());
        }
        assert!(atan2(f32::NAN, 1.0).is_nan());
        assert_eq!(tan_quarter(0.0), 0.0);
    }
    use std::f32::consts::FRAC_PI_4;

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        let (y, p) = (0.7, -0.4);
        let (f, l, u) = (forward(y, p), left(y), dorsal(y, p));
        assert!((f.length() - 1.0).abs() < 1e-6);
        assert!(f.dot(l).abs() < 1e-6 && f.dot(u).abs() < 1e-6 && l.dot(u).abs() < 1e-6);
        // x = left, y = up, z = forward: left × up = forward.
        assert!((l.cross(u) - f).length() < 1e-5);
        assert!(u.dot(UP) > 0.0, "never upside down");
        assert_eq!(l.y, 0.0, "no roll");
    }

    #[test]
    fn right_is_positive_bearing() {
        // Facing +Z, the right is −X.
        let (theta, omega) = bearing_elevation(0.0, 0.0, Vec3::new(-1.0, 0.0, 1.0));
        assert!((theta - FRAC_PI_4).abs() < 1e-6);
        assert!(omega.abs() < 1e-6);
        let (theta, _) = bearing_elevation(0.0, 0.0, Vec3::new(1.0, 0.0, 1.0));
        assert!((theta + FRAC_PI_4).abs() < 1e-6);
        let (_, omega) = bearing_elevation(0.0, 0.0, Vec3::new(0.0, 1.0, 1.0));
        assert!((omega - FRAC_PI_4).abs() < 1e-6);
    }

    #[test]
    fn wrap_stays_in_range() {
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-5);
        assert!((wrap(-3.5 * PI) - 0.5 * PI).abs() < 1e-5);
        assert_eq!(wrap(f32::NAN), 0.0);
    }
}
