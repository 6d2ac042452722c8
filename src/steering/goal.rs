//! Moving to a goal: seed 000 §4.3 (smell mode by sectors, vision mode by clamped bearing),
//! seed 003's foraging variant, and seed 002's pursuit with linear or intercept prediction.
//!
//! Every angle of §4.3 is a parameter with the paper's value as its default ([`GoalRules`]): the
//! smell-mode turns π/8 and π/4, the sector bounds π/6 and 5π/6, the vision-mode clamp π/4. In
//! vision, seed 000 as printed keeps the heading while the target is within ±π/4 (eq. 15: `θc`
//! when `|θ_fg| < π/4`); seed 003's foraging turns exactly by the bearing there. The engine's
//! default is seed 003's form ([`VisionTurn::Bearing`]), which is also how the digest of 000
//! reads the rule (a target within the clamp is turned to, not passed by);
//! [`VisionTurn::KeepHeading`] is 000 as printed.

use super::{seek, Kinematics, Steer};
pub use crate::params::steering::{GoalRules, Prediction, VisionTurn};
pub use crate::perception::Sectors;
use crate::perception::{Level, Sector};
use glam::Vec3;
use std::f32::consts::FRAC_PI_4;

/// Move to goal, smell mode (`v_r < d < O_r`), seed 000 §4.3: by the sector of the target's
/// bearing θ — front keeps θc; left-front −`turn` (π/8); right-front +`turn`; left-rear or rear
/// −`rear_turn` (π/4); right-rear +`rear_turn`. Pitch +`turn` toward a target above, −`turn`
/// below, keep when level. `V = V_max`.
pub fn goal_by_smell(bearing: f32, elevation: f32, v_max: f32, r: &GoalRules) -> Steer {
    let yaw = match r.sectors.horizontal(bearing) {
        Sector::Front => 0.0,
        Sector::LeftFront => -r.turn,
        Sector::RightFront => r.turn,
        Sector::LeftRear | Sector::Rear => -r.rear_turn,
        Sector::RightRear => r.rear_turn,
    };
    let pitch = match r.sectors.vertical(elevation) {
        Level::Above => r.turn,
        Level::Level => 0.0,
        Level::Below => -r.turn,
    };
    Steer::Turn {
        yaw,
        pitch,
        speed: v_max,
    }
}

/// One plane of the vision-mode turn: the angle clamped to ±`max_turn`, or (keeping the
/// heading) 0 within the clamp.
fn vision_turn(angle: f32, max_turn: f32, mode: VisionTurn) -> f32 {
    match mode {
        VisionTurn::KeepHeading if angle.abs() < max_turn => 0.0,
        _ => angle.clamp(-max_turn, max_turn),
    }
}

/// Move to goal, vision mode (`d < v_r`), seed 000 §4.3 and seed 003: turn toward the target by
/// its bearing clamped to ±`max_turn` (π/4: exactly by the bearing when |θ| < π/4, or keeping
/// the heading there with [`VisionTurn::KeepHeading`]), pitch likewise; `V = V_max` while
/// `d > d0`, `0` once `d ≤ d0` (caught).
pub fn goal_by_vision(
    bearing: f32,
    elevation: f32,
    dist: f32,
    d0: f32,
    v_max: f32,
    r: &GoalRules,
) -> Steer {
    Steer::Turn {
        yaw: vision_turn(bearing, r.max_turn, r.vision),
        pitch: vision_turn(elevation, r.max_turn, r.vision),
        speed: if dist > d0 { v_max } else { 0.0 },
    }
}

/// Whether move-to-goal is done: the target is within the catch distance `d0`.
pub fn goal_reached(dist: f32, d0: f32) -> bool {
    dist <= d0
}

/// Default maximum turn per step in vision mode: π/4 (45°).
pub const DEFAULT_MAX_TURN: f32 = FRAC_PI_4;

/// Linear next-step prediction of seed 002: `X_{t+1} = 2·X_t − X_{t−1}`.
pub fn predict_linear(now: Vec3, before: Vec3) -> Vec3 {
    2.0 * now - before
}

/// Intercept point (seed 002, after Stephens): the point `P + V·t` where a pursuer at `from`
/// moving at `speed` meets a target at `P` moving with constant velocity `V`, solving
/// `|P + V·t − from| = speed·t` for the smallest `t > 0`. Falls back to `P` when there is no
/// solution (the target is faster and moving away).
pub fn intercept_point(from: Vec3, speed: f32, target: Vec3, target_vel: Vec3) -> Vec3 {
    let r = target - from;
    let a = target_vel.length_squared() - speed * speed;
    let b = 2.0 * r.dot(target_vel);
    let c = r.length_squared();
    let t = if a.abs() < 1e-9 {
        if b.abs() < 1e-9 {
            None
        } else {
            Some(-c / b)
        }
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            None
        } else {
            let sq = disc.sqrt();
            let (t1, t2) = ((-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a));
            match (t1 > 0.0, t2 > 0.0) {
                (true, true) => Some(t1.min(t2)),
                (true, false) => Some(t1),
                (false, true) => Some(t2),
                _ => None,
            }
        }
    };
    match t {
        Some(t) if t.is_finite() && t > 0.0 => target + target_vel * t,
        _ => target,
    }
}

/// Pursuit: seek the predicted position of a target now at `now` that was at `before` one tick
/// ago (`dt` seconds).
pub fn pursue(
    kin: &Kinematics,
    now: Vec3,
    before: Vec3,
    dt: f32,
    prediction: Prediction,
    v_max: f32,
) -> Steer {
    let aim = match prediction {
        Prediction::None => now,
        Prediction::Linear => predict_linear(now, before),
        Prediction::Intercept => {
            let vel = if dt > 0.0 {
                (now - before) / dt
            } else {
                Vec3::ZERO
            };
            intercept_point(kin.pos, v_max, now, vel)
        }
    };
    seek(kin, aim, v_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_3, FRAC_PI_6, FRAC_PI_8, PI};

    fn turn(yaw: f32, pitch: f32, speed: f32) -> Steer {
        Steer::Turn { yaw, pitch, speed }
    }

    fn smell(bearing: f32, elevation: f32, v_max: f32) -> Steer {
        goal_by_smell(bearing, elevation, v_max, &GoalRules::default())
    }

    fn vision(
        bearing: f32,
        elevation: f32,
        dist: f32,
        d0: f32,
        v_max: f32,
        max_turn: f32,
    ) -> Steer {
        let r = GoalRules {
            max_turn,
            ..GoalRules::default()
        };
        goal_by_vision(bearing, elevation, dist, d0, v_max, &r)
    }

    #[test]
    fn smell_mode_sectors_follow_seed_000() {
        // Front keeps heading; level keeps pitch.
        assert_eq!(smell(0.1, 0.0, 3.0), turn(0.0, 0.0, 3.0));
        assert_eq!(smell(-FRAC_PI_3, 0.0, 3.0), turn(-FRAC_PI_8, 0.0, 3.0));
        assert_eq!(smell(FRAC_PI_3, 0.0, 3.0), turn(FRAC_PI_8, 0.0, 3.0));
        assert_eq!(smell(-2.0, 0.0, 3.0), turn(-FRAC_PI_4, 0.0, 3.0));
        assert_eq!(smell(2.0, 0.0, 3.0), turn(FRAC_PI_4, 0.0, 3.0));
        // Rear (|θ| > 5π/6) turns left by π/4 whichever side.
        assert_eq!(smell(PI - 0.1, 0.0, 3.0), turn(-FRAC_PI_4, 0.0, 3.0));
        assert_eq!(smell(-PI + 0.1, 0.0, 3.0), turn(-FRAC_PI_4, 0.0, 3.0));
        // Above / below.
        assert_eq!(smell(0.0, 0.8, 3.0), turn(0.0, FRAC_PI_8, 3.0));
        assert_eq!(smell(0.0, -0.8, 3.0), turn(0.0, -FRAC_PI_8, 3.0));
    }

    #[test]
    fn vision_mode_clamps_bearing_and_stops_on_catch() {
        assert_eq!(
            vision(0.3, -0.1, 5.0, 0.5, 2.0, FRAC_PI_4),
            turn(0.3, -0.1, 2.0)
        );
        assert_eq!(
            vision(1.2, 1.0, 5.0, 0.5, 2.0, FRAC_PI_4),
            turn(FRAC_PI_4, FRAC_PI_4, 2.0)
        );
        assert_eq!(
            vision(-FRAC_PI_2, 0.0, 0.4, 0.5, 2.0, FRAC_PI_4),
            turn(-FRAC_PI_4, 0.0, 0.0)
        );
        assert!(goal_reached(0.5, 0.5));
        assert!(!goal_reached(0.51, 0.5));
    }

    #[test]
    fn default_sectors_are_perceptions() {
        // The bounds π/6 and 5π/6 give perception's own classification, boundaries included.
        let s = Sectors::default();
        let edges = [FRAC_PI_6, FRAC_PI_2, 5.0 * FRAC_PI_6, PI];
        for e in edges {
            for a in [e, -e, e - 1e-3, -e + 1e-3, e + 1e-3, -e - 1e-3, 0.0] {
                assert_eq!(s.horizontal(a), Sector::of(a), "{a}");
                assert_eq!(s.vertical(a), Level::of(a), "{a}");
            }
        }
    }

    #[test]
    fn sector_bounds_and_turns_are_parameters() {
        // front 0.3, rear 2.0, turn 0.2, rear turn 0.6, V_max 3.
        let r = GoalRules {
            turn: 0.2,
            rear_turn: 0.6,
            sectors: Sectors {
                front: 0.3,
                rear: 2.0,
            },
            ..GoalRules::default()
        };
        let yaw = |b: f32| match goal_by_smell(b, 0.0, 3.0, &r) {
            Steer::Turn { yaw, .. } => yaw,
            s => panic!("{s:?}"),
        };
        // (−0.3, 0.3) front: keep.
        assert_eq!(yaw(0.29), 0.0);
        assert_eq!(yaw(-0.29), 0.0);
        // [0.3, π/2) right-front: +0.2; (−π/2, −0.3] left-front: −0.2.
        assert_eq!(yaw(0.3), 0.2);
        assert_eq!(yaw(-0.3), -0.2);
        assert_eq!(yaw(1.5), 0.2);
        assert_eq!(yaw(-1.5), -0.2);
        // [π/2, 2.0) right-rear: +0.6; (−2.0, −π/2] left-rear: −0.6.
        assert_eq!(yaw(FRAC_PI_2), 0.6);
        assert_eq!(yaw(1.99), 0.6);
        assert_eq!(yaw(-FRAC_PI_2), -0.6);
        assert_eq!(yaw(-1.99), -0.6);
        // Beyond ±2.0: rear, −0.6 whichever side.
        assert_eq!(yaw(2.0), -0.6);
        assert_eq!(yaw(-2.0), -0.6);
        assert_eq!(yaw(3.1), -0.6);
        // Vertically ±0.3 bounds the level band; pitch ±0.2 toward the target; V = V_max.
        assert_eq!(goal_by_smell(0.0, 0.3, 3.0, &r), turn(0.0, 0.2, 3.0));
        assert_eq!(goal_by_smell(0.0, -0.3, 3.0, &r), turn(0.0, -0.2, 3.0));
        assert_eq!(goal_by_smell(0.0, 0.29, 3.0, &r), turn(0.0, 0.0, 3.0));
        assert_eq!(goal_by_smell(0.0, -0.29, 3.0, &r), turn(0.0, 0.0, 3.0));
    }

    #[test]
    fn vision_mode_catch_distance_and_foraging_turn() {
        let r = GoalRules::default();
        // d ≤ d0 → V = 0 (caught), d > d0 → V_max.
        assert_eq!(
            goal_by_vision(0.2, 0.0, 0.5, 0.5, 2.0, &r),
            turn(0.2, 0.0, 0.0)
        );
        assert_eq!(
            goal_by_vision(0.2, 0.0, 0.500_1, 0.5, 2.0, &r),
            turn(0.2, 0.0, 2.0)
        );
        // Seed 003's foraging: within ±π/4 exactly by the bearing, beyond it by ±π/4.
        assert_eq!(
            goal_by_vision(-0.7, 0.7, 3.0, 0.5, 2.0, &r),
            turn(-0.7, 0.7, 2.0)
        );
        assert_eq!(
            goal_by_vision(-0.8, 0.8, 3.0, 0.5, 2.0, &r),
            turn(-FRAC_PI_4, FRAC_PI_4, 2.0)
        );
        // Seed 000 as printed: keep the heading within ±π/4, ±π/4 beyond.
        let keep = GoalRules {
            vision: VisionTurn::KeepHeading,
            ..r
        };
        assert_eq!(
            goal_by_vision(-0.7, 0.7, 3.0, 0.5, 2.0, &keep),
            turn(0.0, 0.0, 2.0)
        );
        assert_eq!(
            goal_by_vision(0.8, -0.8, 3.0, 0.5, 2.0, &keep),
            turn(FRAC_PI_4, -FRAC_PI_4, 2.0)
        );
        assert_eq!(
            goal_by_vision(-2.0, 0.0, 0.3, 0.5, 2.0, &keep),
            turn(-FRAC_PI_4, 0.0, 0.0)
        );
        // Exactly at the clamp: turn by it.
        assert_eq!(
            goal_by_vision(FRAC_PI_4, -FRAC_PI_4, 3.0, 0.5, 2.0, &keep),
            turn(FRAC_PI_4, -FRAC_PI_4, 2.0)
        );
    }

    #[test]
    fn chase_reads_its_angles_from_data() {
        let c: crate::species::ChaseDef = crate::species::validate::ron_options()
            .from_str("(turn: 0.2, rear_turn: 0.6, front: 0.3, rear: 2.0, max_turn: 0.5, vision: KeepHeading)")
            .unwrap();
        let r = c.rules();
        assert_eq!((r.turn, r.rear_turn, r.max_turn), (0.2, 0.6, 0.5));
        assert_eq!(
            r.sectors,
            Sectors {
                front: 0.3,
                rear: 2.0
            }
        );
        assert_eq!(r.vision, VisionTurn::KeepHeading);
        // The default is the paper's, with seed 003's foraging turn in vision.
        let d: crate::species::ChaseDef = crate::species::validate::ron_options()
            .from_str("()")
            .unwrap();
        assert_eq!(d.rules(), GoalRules::default());
        assert_eq!(d.rules().vision, VisionTurn::Bearing);
    }

    #[test]
    fn linear_prediction_is_two_x_t_minus_x_t_minus_one() {
        assert_eq!(
            predict_linear(Vec3::new(3.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 2.0)),
            Vec3::new(5.0, 1.0, -2.0)
        );
    }

    #[test]
    fn intercept_point_hand_computed() {
        // Target at (10,0,0) moving +Z at 1; pursuer at origin at speed √2:
        // |(10, 0, t)| = √2·t → 100 + t² = 2t² → t = 10 → point (10, 0, 10).
        let p = intercept_point(Vec3::ZERO, 2f32.sqrt(), Vec3::new(10.0, 0.0, 0.0), Vec3::Z);
        assert!((p - Vec3::new(10.0, 0.0, 10.0)).length() < 1e-3, "{p}");
        // A faster target running away: no solution, aim at it.
        let p = intercept_point(
            Vec3::ZERO,
            1.0,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(5.0, 0.0, 0.0),
        );
        assert_eq!(p, Vec3::new(10.0, 0.0, 0.0));
    }

    #[test]
    fn pursuit_aims_at_the_prediction() {
        let k = Kinematics {
            pos: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.0,
            speed: 1.0,
        };
        let s = pursue(
            &k,
            Vec3::new(0.0, 0.0, 10.0),
            Vec3::new(-1.0, 0.0, 10.0),
            0.1,
            Prediction::Linear,
            2.0,
        );
        let Steer::Velocity(v) = s else { panic!() };
        let expect = Vec3::new(1.0, 0.0, 10.0).normalize() * 2.0;
        assert!((v - expect).length() < 1e-5);
    }

    #[test]
    fn intercept_point_branches() {
        let at_x10 = Vec3::new(10.0, 0.0, 0.0);
        // Equal speeds (a = 0): t = −c/b. Target closing at 1: b = 2·(10·−1) = −20, c = 100,
        // t = 5 → (5, 0, 0). Moving away: t = −5 < 0 → aim at it. Sideways: b = 0 → aim at it.
        let p = intercept_point(Vec3::ZERO, 1.0, at_x10, Vec3::new(-1.0, 0.0, 0.0));
        assert_eq!(p, Vec3::new(5.0, 0.0, 0.0));
        assert_eq!(intercept_point(Vec3::ZERO, 1.0, at_x10, Vec3::X), at_x10);
        assert_eq!(intercept_point(Vec3::ZERO, 1.0, at_x10, Vec3::Z), at_x10);
        // b = 2·(10·−1e−11) = −2e−10, below 1e−9: no usable solution, aim at it.
        let grazing = Vec3::new(-1e-11, 0.0, 1.0);
        assert_eq!(intercept_point(Vec3::ZERO, 1.0, at_x10, grazing), at_x10);
        // Faster target closing at 2, pursuer at 1: a = 3, b = −40, c = 100, disc = 400,
        // t = (40 ∓ 20)/6 = 10/3 or 10 → the sooner, (10 − 20/3, 0, 0).
        let p = intercept_point(Vec3::ZERO, 1.0, at_x10, Vec3::new(-2.0, 0.0, 0.0));
        assert!((p - Vec3::new(10.0 / 3.0, 0.0, 0.0)).length() < 1e-5, "{p}");
        // A standing pursuer: a = 4, disc = 1600 − 1600 = 0, t = 40/8 = 5 → the origin.
        let p = intercept_point(Vec3::ZERO, 0.0, at_x10, Vec3::new(-2.0, 0.0, 0.0));
        assert_eq!(p, Vec3::ZERO);
        // Closing at 1: a = 1, b = −20, disc = 400 − 400 = 0, t = 20/2 = 10 → the origin.
        let p = intercept_point(Vec3::ZERO, 0.0, at_x10, Vec3::new(-1.0, 0.0, 0.0));
        assert_eq!(p, Vec3::ZERO);
        // Faster target passing sideways: a = 3, b = 0, disc = −1200 < 0 → aim at it.
        let p = intercept_point(Vec3::ZERO, 1.0, at_x10, Vec3::new(0.0, 0.0, 2.0));
        assert_eq!(p, at_x10);
        // From a pursuer away from the origin: r = target − from.
        let p = intercept_point(
            Vec3::new(0.0, 0.0, 1.0),
            1.0,
            Vec3::new(10.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.0, 0.0),
        );
        assert_eq!(p, Vec3::new(5.0, 0.0, 1.0));
    }

    #[test]
    fn pursuit_by_none_and_intercept() {
        let k = Kinematics {
            pos: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.0,
            speed: 1.0,
        };
        let (now, before) = (Vec3::new(10.0, 0.0, 0.0), Vec3::new(10.0, 0.0, -0.1));
        let v = |p: Prediction, dt: f32| match pursue(&k, now, before, dt, p, 2f32.sqrt()) {
            Steer::Velocity(v) => v,
            s => panic!("{s:?}"),
        };
        // None: straight at (10, 0, 0), speed √2.
        assert!((v(Prediction::None, 0.1) - Vec3::new(2f32.sqrt(), 0.0, 0.0)).length() < 1e-5);
        // Intercept: V = (0, 0, 0.1)/0.1 = +Z at 1, pursuer at √2 → (10, 0, 10) as above,
        // direction (1, 0, 1)/√2 times √2 = (1, 0, 1).
        let i = v(Prediction::Intercept, 0.1);
        assert!((i - Vec3::new(1.0, 0.0, 1.0)).length() < 1e-4, "{i}");
        // dt = 0: no velocity estimate, aim at the target.
        let i = v(Prediction::Intercept, 0.0);
        assert!(
            (i - Vec3::new(2f32.sqrt(), 0.0, 0.0)).length() < 1e-5,
            "{i}"
        );
    }

    #[test]
    fn intercept_takes_the_sooner_root_when_nearly_as_fast() {
        // Head-on, target at 10 closing at 2: they meet at t = 10/(2 + s), at 10 − 2t.
        // s = 1.999 (a = 4 − s² ≈ 0.004): t = 10/3.999 = 2.50063 → x = 4.99875.
        let closing = Vec3::new(-2.0, 0.0, 0.0);
        let p = intercept_point(Vec3::ZERO, 1.999, Vec3::new(10.0, 0.0, 0.0), closing);
        assert!((p - Vec3::new(4.998_75, 0.0, 0.0)).length() < 1e-2, "{p}");
        // s = 0.025 (disc = 400·s² = 0.25, √disc = 0.5): t = 10/2.025 = 4.93827 → x = 0.12346.
        let p = intercept_point(Vec3::ZERO, 0.025, Vec3::new(10.0, 0.0, 0.0), closing);
        assert!((p - Vec3::new(0.123_46, 0.0, 0.0)).length() < 1e-3, "{p}");
    }
}
