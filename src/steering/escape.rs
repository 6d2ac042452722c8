//! Escaping a predator: seed 000 §4.4 (smell and vision modes, completion test) and seed 002's
//! escape by seeking the point mirrored through the fish.
//!
//! The paper's two modes are kept as written ([`escape_by_smell`], [`escape_by_vision`]). The
//! runtime applies them through [`escape_leveled`], which adds two things the per-step rules need
//! when they run every tick: the pitch rule aims at an absolute pitch (up to `max_pitch`, level
//! when the predator is within `level_band` of the horizontal) instead of adding ±π/8 or ±π/4
//! every step, which climbs to the pitch limit whenever the predator stays below; fleeing
//! from a predator ahead never slows below `speed_floor·V_max` (the paper's `Vc/2` every step
//! decays to a standstill in front of the predator); and a predator smelt straight ahead, for
//! which the paper keeps the heading, is turned away from by π/8.

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

/// The runtime's additions to the paper's escape (see the module header).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leveling {
    /// A predator whose elevation above the horizontal is within this band counts as level.
    pub level_band: f32,
    /// Largest pitch escape aims for.
    pub max_pitch: f32,
    /// Slowest escape speed, as a fraction of `V_max`.
    pub speed_floor: f32,
}

impl Default for Leveling {
    fn default() -> Self {
        Leveling {
            level_band: std::f32::consts::FRAC_PI_6,
            max_pitch: FRAC_PI_4,
            speed_floor: 0.5,
        }
    }
}

/// Escape with the paper's yaw rules and speeds (smell or vision mode) and the runtime's
/// pitch and speed floor: `elevation` is relative to the heading as perception gives it, `pitch`
/// the body's own; the pitch command turns (by at most the mode's step, π/8 or π/4) toward
/// `+max_pitch` from a predator below the band, `−max_pitch` from one above it, level otherwise.
#[allow(clippy::too_many_arguments)]
pub fn escape_leveled(
    vision: bool,
    bearing: f32,
    elevation: f32,
    pitch: f32,
    dist: f32,
    vision_radius: f32,
    current_speed: f32,
    v_max: f32,
    l: &Leveling,
) -> Steer {
    let paper = if vision {
        escape_by_vision(bearing, elevation, dist, vision_radius, v_max)
    } else {
        escape_by_smell(bearing, elevation, current_speed, v_max)
    };
    let Steer::Turn { mut yaw, speed, .. } = paper else {
        return paper;
    };
    // Smelt straight ahead, the paper keeps the heading, into the predator: turn away from
    // the side it lies on instead.
    if !vision && Sector::of(bearing) == Sector::Front {
        yaw = if bearing <= 0.0 {
            FRAC_PI_8
        } else {
            -FRAC_PI_8
        };
    }
    let step = if vision { FRAC_PI_4 } else { FRAC_PI_8 };
    let absolute = elevation + pitch;
    let aim = if absolute < -l.level_band {
        l.max_pitch
    } else if absolute > l.level_band {
        -l.max_pitch
    } else {
        0.0
    };
    Steer::Turn {
        yaw,
        pitch: (aim - pitch).clamp(-step, step),
        speed: speed.max(l.speed_floor.clamp(0.0, 1.0) * v_max),
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
    fn leveled_escape_flees_level_from_a_level_predator() {
        let l = Leveling::default();
        // Level predator on the left-front, in sight, body level: the paper pitches +π/4 every
        // step; leveled, the pitch stays 0 and the yaw is the paper's.
        assert_eq!(
            escape_by_vision(-0.5, -0.01, 3.0, 10.0, 4.0),
            turn(FRAC_PI_4, FRAC_PI_4, 4.0)
        );
        assert_eq!(
            escape_leveled(true, -0.5, -0.01, 0.0, 3.0, 10.0, 1.0, 4.0, &l),
            turn(FRAC_PI_4, 0.0, 4.0)
        );
        // Same predator, body pitched up 0.6: level again by at most π/4 (−0.6).
        let Steer::Turn { pitch, .. } =
            escape_leveled(true, -0.5, -0.61, 0.6, 3.0, 10.0, 1.0, 4.0, &l)
        else {
            panic!()
        };
        assert!((pitch + 0.6).abs() < 1e-6);
        // Predator well below, body already at +π/4: keep that pitch (the paper would add π/4).
        let Steer::Turn { pitch, .. } =
            escape_leveled(true, 0.5, -1.6, FRAC_PI_4, 3.0, 10.0, 1.0, 4.0, &l)
        else {
            panic!()
        };
        assert!(pitch.abs() < 1e-6);
        // Smelt straight ahead: the paper keeps the heading; leveled, it turns away by π/8
        // (right from one a hair to the left, left from one a hair to the right).
        assert_eq!(escape_by_smell(-0.1, 0.0, 2.0, 5.0), turn(0.0, 0.0, 1.0));
        assert_eq!(
            escape_leveled(false, -0.1, 0.0, 0.0, 15.0, 10.0, 2.0, 5.0, &l),
            turn(FRAC_PI_8, 0.0, 2.5)
        );
        assert_eq!(
            escape_leveled(false, 0.1, 0.0, 0.0, 15.0, 10.0, 2.0, 5.0, &l),
            turn(-FRAC_PI_8, 0.0, 2.5)
        );
        // Smell mode, predator ahead: the paper's Vc/2 = 0.25, floored at 0.5·V_max = 2.
        assert_eq!(
            escape_leveled(false, -1.0, 0.0, 0.0, 15.0, 10.0, 0.5, 4.0, &l),
            turn(FRAC_PI_8, 0.0, 2.0)
        );
        // Predator above (absolute elevation 0.9) in smell mode: pitch down by π/8 at most.
        assert_eq!(
            escape_leveled(false, 2.5, 0.9, 0.0, 15.0, 10.0, 2.0, 5.0, &l),
            turn(0.0, -FRAC_PI_8, 5.0)
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
