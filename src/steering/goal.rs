//! Moving to a goal: seed 000 §4.3 (smell mode by sectors, vision mode by clamped bearing),
//! seed 003's foraging variant, and seed 002's pursuit with linear or intercept prediction.

use super::{seek, Kin, Steer};
use crate::perception::{Level, Sector};
use glam::Vec3;
use std::f32::consts::{FRAC_PI_4, FRAC_PI_8};

/// Move to goal, smell mode (`v_r < d < O_r`), seed 000 §4.3: by the sector of the target's
/// bearing θ — front keeps θc; left-front −π/8; right-front +π/8; left-rear or rear −π/4;
/// right-rear +π/4. Pitch +π/8 toward a target above, −π/8 below, keep when level. `V = V_max`.
pub fn goal_by_smell(bearing: f32, elevation: f32, v_max: f32) -> Steer {
    let yaw = match Sector::of(bearing) {
        Sector::Front => 0.0,
        Sector::LeftFront => -FRAC_PI_8,
        Sector::RightFront => FRAC_PI_8,
        Sector::LeftRear | Sector::Rear => -FRAC_PI_4,
        Sector::RightRear => FRAC_PI_4,
    };
    let pitch = match Level::of(elevation) {
        Level::Above => FRAC_PI_8,
        Level::Level => 0.0,
        Level::Below => -FRAC_PI_8,
    };
    Steer::Turn {
        yaw,
        pitch,
        speed: v_max,
    }
}

/// Move to goal, vision mode (`d < v_r`), seed 000 §4.3 and seed 003: turn toward the target by
/// its bearing clamped to ±`max_turn` (π/4: exactly by the bearing when |θ| < π/4), pitch
/// likewise; `V = V_max` while `d > d0`, `0` once `d ≤ d0` (caught).
pub fn goal_by_vision(
    bearing: f32,
    elevation: f32,
    dist: f32,
    d0: f32,
    v_max: f32,
    max_turn: f32,
) -> Steer {
    Steer::Turn {
        yaw: bearing.clamp(-max_turn, max_turn),
        pitch: elevation.clamp(-max_turn, max_turn),
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

/// How a pursuer predicts its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
pub enum Prediction {
    /// Aim at where the target is.
    None,
    /// `2·X_t − X_{t−1}` (seed 002's robust choice).
    #[default]
    Linear,
    /// The intercept point from the target's velocity.
    Intercept,
}

/// Pursuit: seek the predicted position of a target now at `now` that was at `before` one tick
/// ago (`dt` seconds).
pub fn pursue(
    kin: &Kin,
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
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_3, PI};

    fn turn(yaw: f32, pitch: f32, speed: f32) -> Steer {
        Steer::Turn { yaw, pitch, speed }
    }

    #[test]
    fn smell_mode_sectors_follow_seed_000() {
        // Front keeps heading; level keeps pitch.
        assert_eq!(goal_by_smell(0.1, 0.0, 3.0), turn(0.0, 0.0, 3.0));
        assert_eq!(
            goal_by_smell(-FRAC_PI_3, 0.0, 3.0),
            turn(-FRAC_PI_8, 0.0, 3.0)
        );
        assert_eq!(
            goal_by_smell(FRAC_PI_3, 0.0, 3.0),
            turn(FRAC_PI_8, 0.0, 3.0)
        );
        assert_eq!(goal_by_smell(-2.0, 0.0, 3.0), turn(-FRAC_PI_4, 0.0, 3.0));
        assert_eq!(goal_by_smell(2.0, 0.0, 3.0), turn(FRAC_PI_4, 0.0, 3.0));
        // Rear (|θ| > 5π/6) turns left by π/4 whichever side.
        assert_eq!(
            goal_by_smell(PI - 0.1, 0.0, 3.0),
            turn(-FRAC_PI_4, 0.0, 3.0)
        );
        assert_eq!(
            goal_by_smell(-PI + 0.1, 0.0, 3.0),
            turn(-FRAC_PI_4, 0.0, 3.0)
        );
        // Above / below.
        assert_eq!(goal_by_smell(0.0, 0.8, 3.0), turn(0.0, FRAC_PI_8, 3.0));
        assert_eq!(goal_by_smell(0.0, -0.8, 3.0), turn(0.0, -FRAC_PI_8, 3.0));
    }

    #[test]
    fn vision_mode_clamps_bearing_and_stops_on_catch() {
        assert_eq!(
            goal_by_vision(0.3, -0.1, 5.0, 0.5, 2.0, FRAC_PI_4),
            turn(0.3, -0.1, 2.0)
        );
        assert_eq!(
            goal_by_vision(1.2, 1.0, 5.0, 0.5, 2.0, FRAC_PI_4),
            turn(FRAC_PI_4, FRAC_PI_4, 2.0)
        );
        assert_eq!(
            goal_by_vision(-FRAC_PI_2, 0.0, 0.4, 0.5, 2.0, FRAC_PI_4),
            turn(-FRAC_PI_4, 0.0, 0.0)
        );
        assert!(goal_reached(0.5, 0.5));
        assert!(!goal_reached(0.51, 0.5));
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
        let k = Kin {
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
}
