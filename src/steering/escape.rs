//! Escaping a predator: seed 000 §4.4 (smell and vision modes, completion test) and seed 002's
//! escape by seeking the point mirrored through the fish.

use super::{seek, Kin, Steer};
use crate::perception::{Level, Sector};
use glam::Vec3;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, FRAC_PI_8};

/// Escape, smell mode (seed 000 §4.4): predator left-front → +π/8, right-front → −π/8, else keep
/// θc; predator below → +π/8, above → −π/8; `V = V_max` if the predator is behind (|θ| > π/2),
/// `Vc/2` if in front.
pub fn escape_by_smell(bearing: f32, elevation: f32, current_speed: f32, v_max: f32) -> Steer {
    let yaw = match Sector::of(bearing) {
        Sector::LeftFront => FRAC_PI_8,
        Sector::RightFront => -FRAC_PI_8,
        _ => 0.0,
    };
    let pitch = match Level::of(elevation) {
        Level::Below => FRAC_PI_8,
        Level::Above => -FRAC_PI_8,
        Level::Level => 0.0,
    };
    let speed = if bearing.abs() > FRAC_PI_2 {
        v_max
    } else {
        current_speed / 2.0
    };
    Steer::Turn { yaw, pitch, speed }
}

/// Escape, vision mode (seed 000 §4.4): predator at a bearing in (−π/2, 0] → +π/4, in (0, π/2)
/// → −π/4, behind (|θ| ≥ π/2) keep θc; pitch likewise by elevation (below → up, above → down);
/// `V = V_max` if `d ≤ v_r`, else `V_max/2`.
pub fn escape_by_vision(
    bearing: f32,
    elevation: f32,
    dist: f32,
    vision_radius: f32,
    v_max: f32,
) -> Steer {
    let away = |a: f32| {
        if a > -FRAC_PI_2 && a <= 0.0 {
            FRAC_PI_4
        } else if a > 0.0 && a < FRAC_PI_2 {
            -FRAC_PI_4
        } else {
            0.0
        }
    };
    let speed = if dist <= vision_radius {
        v_max
    } else {
        v_max / 2.0
    };
    Steer::Turn {
        yaw: away(bearing),
        pitch: away(elevation),
        speed,
    }
}

/// Escape is done (seed 000 §4.4) when the predator is behind in both planes — horizontally
/// |θ| > π/2, and in the body's vertical plane behind the fish (offset · forward < 0) — and
/// farther than `v_r`.
pub fn escape_done(kin: &Kin, bearing: f32, offset: Vec3, dist: f32, vision_radius: f32) -> bool {
    bearing.abs() > FRAC_PI_2 && offset.dot(kin.forward()) < 0.0 && dist > vision_radius
}

/// The point mirrored through the fish `x`: `X' = 2x − X` (seed 002).
pub fn mirror_point(me: Vec3, threat: Vec3) -> Vec3 {
    2.0 * me - threat
}

/// Escape by seeking the mirrored point (seed 002).
pub fn escape_mirror(kin: &Kin, threat: Vec3, v_max: f32) -> Steer {
    let target = mirror_point(kin.pos, threat);
    match seek(kin, target, v_max) {
        Steer::None => Steer::Turn {
            yaw: 0.0,
            pitch: 0.0,
            speed: v_max,
        },
        s => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn turn(yaw: f32, pitch: f32, speed: f32) -> Steer {
        Steer::Turn { yaw, pitch, speed }
    }

    #[test]
    fn smell_mode_turns_away_by_pi_over_8() {
        // Predator left-front, level, in front → right by π/8, Vc/2.
        assert_eq!(
            escape_by_smell(-1.0, 0.0, 2.0, 5.0),
            turn(FRAC_PI_8, 0.0, 1.0)
        );
        // Right-front and below → left and up.
        assert_eq!(
            escape_by_smell(1.0, -0.9, 2.0, 5.0),
            turn(-FRAC_PI_8, FRAC_PI_8, 1.0)
        );
        // Behind and above → keep, down, V_max.
        assert_eq!(
            escape_by_smell(2.5, 0.9, 2.0, 5.0),
            turn(0.0, -FRAC_PI_8, 5.0)
        );
    }

    #[test]
    fn vision_mode_turns_away_by_pi_over_4() {
        assert_eq!(
            escape_by_vision(-0.5, 0.0, 3.0, 10.0, 4.0),
            turn(FRAC_PI_4, FRAC_PI_4, 4.0)
        );
        assert_eq!(
            escape_by_vision(0.5, 0.3, 3.0, 10.0, 4.0),
            turn(-FRAC_PI_4, -FRAC_PI_4, 4.0)
        );
        assert_eq!(
            escape_by_vision(2.0, -0.3, 12.0, 10.0, 4.0),
            turn(0.0, FRAC_PI_4, 2.0)
        );
    }

    #[test]
    fn done_when_behind_and_out_of_sight() {
        let k = Kin {
            pos: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.0,
            speed: 1.0,
        };
        let behind = Vec3::new(0.0, 0.0, -12.0);
        assert!(escape_done(&k, std::f32::consts::PI, behind, 12.0, 10.0));
        assert!(!escape_done(
            &k,
            std::f32::consts::PI,
            behind * 0.5,
            6.0,
            10.0
        ));
        let ahead = Vec3::new(0.0, 0.0, 12.0);
        assert!(!escape_done(&k, 0.0, ahead, 12.0, 10.0));
    }

    #[test]
    fn mirror_point_is_two_x_minus_predator() {
        assert_eq!(
            mirror_point(Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 0.0, 3.0)),
            Vec3::new(-2.0, 4.0, 3.0)
        );
        let k = Kin {
            pos: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.0,
            speed: 1.0,
        };
        let Steer::Velocity(v) = escape_mirror(&k, Vec3::new(3.0, 0.0, 0.0), 2.0) else {
            panic!()
        };
        assert!((v - Vec3::new(-2.0, 0.0, 0.0)).length() < 1e-6);
    }
}
