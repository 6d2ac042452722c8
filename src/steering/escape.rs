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

//!
//! Every constant of §4.4 is a parameter with the paper's value as its default ([`EscapeRules`]):
//! the turns π/8 (smell) and π/4 (vision), the front sector's bound π/6, the smell-mode braking
//! `Vc/2` and the speed `V_max/2` beyond vision.

use super::{seek, Kinematics, Steer};
pub use crate::params::steering::{EscapeRules, Leveling};
use crate::perception::Sectors;
use crate::perception::{Level, Sector};
use glam::Vec3;
use std::f32::consts::FRAC_PI_2;

impl EscapeRules {
    fn sectors(&self) -> Sectors {
        Sectors {
            front: self.front,
            ..Sectors::default()
        }
    }
}

/// Escape, smell mode (seed 000 §4.4): predator left-front → +`turn` (π/8), right-front →
/// −`turn`, else keep θc; predator below → +`turn`, above → −`turn`; `V = V_max` if the predator
/// is behind (|θ| > π/2), `smell_brake·Vc` (`Vc/2`) if in front.
pub fn escape_by_smell(
    bearing: f32,
    elevation: f32,
    current_speed: f32,
    v_max: f32,
    r: &EscapeRules,
) -> Steer {
    let sectors = r.sectors();
    let yaw = match sectors.horizontal(bearing) {
        Sector::LeftFront => r.turn,
        Sector::RightFront => -r.turn,
        _ => 0.0,
    };
    let pitch = match sectors.vertical(elevation) {
        Level::Below => r.turn,
        Level::Above => -r.turn,
        Level::Level => 0.0,
    };
    let speed = if bearing.abs() > FRAC_PI_2 {
        v_max
    } else {
        current_speed * r.smell_brake
    };
    Steer::Turn { yaw, pitch, speed }
}

/// Escape, vision mode (seed 000 §4.4): predator at a bearing in (−π/2, 0] → +`vision_turn`
/// (π/4), in (0, π/2) → −`vision_turn`, behind (|θ| ≥ π/2) keep θc; pitch likewise by elevation
/// (below → up, above → down); `V = V_max` if `d ≤ v_r`, else `far_speed·V_max` (`V_max/2`).
pub fn escape_by_vision(
    bearing: f32,
    elevation: f32,
    dist: f32,
    vision_radius: f32,
    v_max: f32,
    r: &EscapeRules,
) -> Steer {
    let away = |a: f32| {
        if a > -FRAC_PI_2 && a <= 0.0 {
            r.vision_turn
        } else if a > 0.0 && a < FRAC_PI_2 {
            -r.vision_turn
        } else {
            0.0
        }
    };
    let speed = if dist <= vision_radius {
        v_max
    } else {
        v_max * r.far_speed
    };
    Steer::Turn {
        yaw: away(bearing),
        pitch: away(elevation),
        speed,
    }
}

/// Escape with the paper's yaw rules and speeds (smell or vision mode) and the runtime's
/// pitch and speed floor: `elevation` is relative to the heading as perception gives it, `pitch`
/// the body's own; the pitch command turns (by at most the mode's step, `turn` or `vision_turn`:
/// π/8 or π/4) toward
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
    r: &EscapeRules,
    l: &Leveling,
) -> Steer {
    let paper = if vision {
        escape_by_vision(bearing, elevation, dist, vision_radius, v_max, r)
    } else {
        escape_by_smell(bearing, elevation, current_speed, v_max, r)
    };
    let Steer::Turn { mut yaw, speed, .. } = paper else {
        return paper;
    };
    // Smelt straight ahead, the paper keeps the heading, into the predator: turn away from
    // the side it lies on instead.
    if !vision && r.sectors().horizontal(bearing) == Sector::Front {
        yaw = if bearing <= 0.0 { r.turn } else { -r.turn };
    }
    let step = if vision { r.vision_turn } else { r.turn };
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
pub fn escape_done(
    kin: &Kinematics,
    bearing: f32,
    offset: Vec3,
    dist: f32,
    vision_radius: f32,
) -> bool {
    bearing.abs() > FRAC_PI_2 && offset.dot(kin.forward()) < 0.0 && dist > vision_radius
}

/// The point mirrored through the fish `x`: `X' = 2x − X` (seed 002).
pub fn mirror_point(me: Vec3, threat: Vec3) -> Vec3 {
    2.0 * me - threat
}

/// Escape by seeking the mirrored point (seed 002).
pub fn escape_mirror(kin: &Kinematics, threat: Vec3, v_max: f32) -> Steer {
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
    use std::f32::consts::{FRAC_PI_4, FRAC_PI_8};

    fn turn(yaw: f32, pitch: f32, speed: f32) -> Steer {
        Steer::Turn { yaw, pitch, speed }
    }

    fn escape_by_smell(b: f32, e: f32, vc: f32, v_max: f32) -> Steer {
        super::escape_by_smell(b, e, vc, v_max, &EscapeRules::default())
    }

    fn escape_by_vision(b: f32, e: f32, d: f32, vr: f32, v_max: f32) -> Steer {
        super::escape_by_vision(b, e, d, vr, v_max, &EscapeRules::default())
    }

    #[allow(clippy::too_many_arguments)]
    fn escape_leveled(
        vision: bool,
        b: f32,
        e: f32,
        pitch: f32,
        d: f32,
        vr: f32,
        vc: f32,
        v_max: f32,
        l: &Leveling,
    ) -> Steer {
        super::escape_leveled(
            vision,
            b,
            e,
            pitch,
            d,
            vr,
            vc,
            v_max,
            &EscapeRules::default(),
            l,
        )
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
    fn smell_mode_speed_branches() {
        // Behind (|θ| > π/2) → V_max; in front → Vc/2; exactly at π/2 counts as in front.
        assert_eq!(escape_by_smell(-2.0, 0.0, 3.0, 5.0), turn(0.0, 0.0, 5.0));
        assert_eq!(
            escape_by_smell(FRAC_PI_2, 0.0, 3.0, 5.0),
            turn(0.0, 0.0, 1.5)
        );
        assert_eq!(
            escape_by_smell(-FRAC_PI_2, 0.0, 3.0, 5.0),
            turn(0.0, 0.0, 1.5)
        );
        assert_eq!(escape_by_smell(0.0, 0.0, 3.0, 5.0), turn(0.0, 0.0, 1.5));
        // A braking factor of 0.25: 3·0.25 = 0.75.
        let r = EscapeRules {
            smell_brake: 0.25,
            ..EscapeRules::default()
        };
        assert_eq!(
            super::escape_by_smell(0.0, 0.0, 3.0, 5.0, &r),
            turn(0.0, 0.0, 0.75)
        );
        assert_eq!(
            super::escape_by_smell(2.0, 0.0, 3.0, 5.0, &r),
            turn(0.0, 0.0, 5.0)
        );
    }

    #[test]
    fn vision_mode_speed_branches() {
        // d ≤ v_r → V_max (d = v_r included); d > v_r → V_max/2.
        assert_eq!(
            escape_by_vision(2.0, -2.0, 10.0, 10.0, 4.0),
            turn(0.0, 0.0, 4.0)
        );
        assert_eq!(
            escape_by_vision(2.0, -2.0, 10.01, 10.0, 4.0),
            turn(0.0, 0.0, 2.0)
        );
        // A far speed of 0.3: 4·0.3 = 1.2.
        let r = EscapeRules {
            far_speed: 0.3,
            ..EscapeRules::default()
        };
        let s = super::escape_by_vision(2.0, 0.0, 12.0, 10.0, 4.0, &r);
        assert_eq!(s, turn(0.0, FRAC_PI_4, 4.0 * 0.3));
        // Bearing exactly 0 counts as left (turn right); ±π/2 as behind (keep).
        assert_eq!(
            escape_by_vision(0.0, FRAC_PI_2, 3.0, 10.0, 4.0),
            turn(FRAC_PI_4, 0.0, 4.0)
        );
        assert_eq!(
            escape_by_vision(-FRAC_PI_2, 1.0, 3.0, 10.0, 4.0),
            turn(0.0, -FRAC_PI_4, 4.0)
        );
    }

    #[test]
    fn escape_angles_are_parameters() {
        // turn 0.2, vision turn 0.6, front 0.3.
        let r = EscapeRules {
            turn: 0.2,
            vision_turn: 0.6,
            front: 0.3,
            ..EscapeRules::default()
        };
        // Smell: θ = −0.3 is left-front with front = 0.3 (front with π/6) → +0.2; θ = 0.29 is
        // front → keep; θ = 0.3 right-front → −0.2. Elevation −0.3 below → +0.2, 0.3 above → −0.2.
        assert_eq!(
            super::escape_by_smell(-0.3, -0.3, 2.0, 5.0, &r),
            turn(0.2, 0.2, 1.0)
        );
        assert_eq!(
            super::escape_by_smell(0.29, 0.29, 2.0, 5.0, &r),
            turn(0.0, 0.0, 1.0)
        );
        assert_eq!(
            super::escape_by_smell(0.3, 0.3, 2.0, 5.0, &r),
            turn(-0.2, -0.2, 1.0)
        );
        assert_eq!(escape_by_smell(-0.3, -0.3, 2.0, 5.0), turn(0.0, 0.0, 1.0));
        // Vision: ±0.6.
        assert_eq!(
            super::escape_by_vision(-0.5, 0.4, 3.0, 10.0, 4.0, &r),
            turn(0.6, -0.6, 4.0)
        );
        // Leveled: the smelt-ahead turn is `turn`, the pitch step `turn` (smell) or
        // `vision_turn` (vision): aim −π/4 from a predator above, by at most 0.2 / 0.6.
        let l = Leveling::default();
        let s = super::escape_leveled(false, 0.1, 0.9, 0.0, 15.0, 10.0, 2.0, 5.0, &r, &l);
        assert_eq!(s, turn(-0.2, -0.2, 2.5));
        let s = super::escape_leveled(true, 0.1, 0.9, 0.0, 5.0, 10.0, 2.0, 5.0, &r, &l);
        assert_eq!(s, turn(-0.6, -0.6, 5.0));
    }

    #[test]
    fn done_needs_the_predator_behind_in_the_vertical_plane_too() {
        // Fish pitched up by 1.2 rad: forward = (0, sin 1.2, cos 1.2) = (0, 0.932, 0.362).
        // Predator behind horizontally (θ = π) but high above: offset (0, 20, −5), d = 20.6 >
        // v_r = 10. offset·forward = 20·0.932 − 5·0.362 = 16.8 > 0: ahead in the vertical
        // plane → not done.
        let up = Kinematics {
            pos: Vec3::ZERO,
            yaw: 0.0,
            pitch: 1.2,
            speed: 1.0,
        };
        let offset = Vec3::new(0.0, 20.0, -5.0);
        let d = offset.length();
        assert!(!escape_done(&up, std::f32::consts::PI, offset, d, 10.0));
        // Level fish, same predator: offset·forward = −5 < 0 → behind in both planes → done.
        let level = Kinematics { pitch: 0.0, ..up };
        assert!(escape_done(&level, std::f32::consts::PI, offset, d, 10.0));
        // Behind in the vertical plane but beside horizontally (θ = π/2 exactly) → not done.
        assert!(!escape_done(&level, FRAC_PI_2, offset, d, 10.0));
        // Straight above a level fish (offset·forward = 0): not behind → not done.
        let above = Vec3::new(0.0, 20.0, 0.0);
        assert!(!escape_done(
            &level,
            std::f32::consts::PI,
            above,
            20.0,
            10.0
        ));
        // At d = v_r exactly → not done.
        assert!(!escape_done(
            &level,
            std::f32::consts::PI,
            offset,
            10.0,
            10.0
        ));
    }

    #[test]
    fn done_when_behind_and_out_of_sight() {
        let k = Kinematics {
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
        let k = Kinematics {
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

    #[test]
    fn level_band_edges_count_as_level() {
        // Band 0.25, body level, predator behind (θ = 2, V_max = 4): exactly ∓0.25 is level →
        // aim 0, pitch 0; beyond it the aim is ±π/4, one smell step π/8 at most.
        let l = Leveling {
            level_band: 0.25,
            ..Leveling::default()
        };
        let at = |e: f32| escape_leveled(false, 2.0, e, 0.0, 15.0, 10.0, 2.0, 4.0, &l);
        assert_eq!(at(-0.25), turn(0.0, 0.0, 4.0));
        assert_eq!(at(0.25), turn(0.0, 0.0, 4.0));
        assert_eq!(at(-0.26), turn(0.0, FRAC_PI_8, 4.0));
        assert_eq!(at(0.26), turn(0.0, -FRAC_PI_8, 4.0));
    }
}
