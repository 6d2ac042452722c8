//! Rigid-body locomotion of seed 001: tail thrust along the body, port/starboard thrusts turning
//! about world up, up/down thrusts pitching about the lateral axis, and fluid drag. Balance is
//! kept as in seed 002: no roll, pitch clamped by the caller.

use super::Motion;
use crate::frame;
use crate::params::locomotion::RigidParams;

/// One rigid-body step toward a heading change `(dyaw, dpitch)` and a target speed. Turning per
/// step is still capped by `max_turn`.
pub(super) fn step(
    m: &mut Motion,
    p: &RigidParams,
    dyaw: f32,
    dpitch: f32,
    target: f32,
    max_turn: f32,
    dt: f32,
) {
    let mass = p.mass.max(1e-3);
    let inertia = p.inertia.max(1e-3);
    let thrust = (p.thrust_gain * (target - m.speed) * mass).clamp(0.0, p.max_thrust.max(0.0));
    let drag = -p.drag * m.speed * m.speed.abs();
    // Without thrust below the target, a slower target is reached by drag plus a braking share.
    let brake = if target < m.speed {
        -(p.thrust_gain * (m.speed - target) * mass).min(p.max_thrust)
    } else {
        0.0
    };
    m.speed += (thrust + drag + brake) / mass * dt;
    // Braking decays geometrically and would never quite reach a stop: snap the last millimetre
    // per second to zero when the command is to stop.
    if target <= 0.0 && m.speed.abs() < 1e-3 {
        m.speed = 0.0;
    }
    let yaw_torque = (p.turn_gain * dyaw - p.angular_damping * m.yaw_rate)
        .clamp(-p.max_yaw_torque, p.max_yaw_torque);
    let pitch_torque = (p.turn_gain * dpitch - p.angular_damping * m.pitch_rate)
        .clamp(-p.max_pitch_torque, p.max_pitch_torque);
    m.yaw_rate += yaw_torque / inertia * dt;
    m.pitch_rate += pitch_torque / inertia * dt;
    let lim = if dt > 0.0 { max_turn / dt } else { 0.0 };
    m.yaw_rate = m.yaw_rate.clamp(-lim, lim);
    m.pitch_rate = m.pitch_rate.clamp(-lim, lim);
    if !(m.yaw_rate.is_finite() && m.pitch_rate.is_finite()) {
        m.yaw_rate = 0.0;
        m.pitch_rate = 0.0;
    }
    m.yaw = frame::wrap(m.yaw + m.yaw_rate * dt);
    m.pitch += m.pitch_rate * dt;
}

#[cfg(test)]
mod tests {
    use super::super::{step as loco_step, BodyLimits, Mode};
    use super::*;
    use crate::steering::Steer;
    use glam::Vec3;

    #[test]
    fn thrust_accelerates_and_drag_limits_speed() {
        // One step from rest toward 2 m/s: thrust = min(6·2·1, 8) = 8, drag 0 → Δv = 8·0.1 = 0.8.
        let mut m = Motion::default();
        let mode = Mode::RigidBody(RigidParams::default());
        let l = BodyLimits::default();
        loco_step(
            &mut m,
            Steer::Turn {
                yaw: 0.0,
                pitch: 0.0,
                speed: 2.0,
            },
            &l,
            &mode,
            Vec3::ZERO,
            0.1,
            &mut None,
        );
        assert!((m.speed - 0.8).abs() < 1e-6, "{}", m.speed);
        for _ in 0..200 {
            loco_step(
                &mut m,
                Steer::Turn {
                    yaw: 0.0,
                    pitch: 0.0,
                    speed: 2.0,
                },
                &l,
                &mode,
                Vec3::ZERO,
                0.1,
                &mut None,
            );
        }
        // Equilibrium below the target: thrust 6·(2−v) = drag 0.5·v² → v² + 12v − 24 = 0 → v ≈ 1.7460.
        assert!((m.speed - 1.7460).abs() < 0.01, "{}", m.speed);
    }

    #[test]
    fn braking_to_a_stop_reaches_zero() {
        let mut m = Motion {
            speed: 0.8,
            ..Default::default()
        };
        let mode = Mode::RigidBody(RigidParams::default());
        let stop = Steer::Turn {
            yaw: 0.0,
            pitch: 0.0,
            speed: 0.0,
        };
        let mut ticks = 0;
        while m.speed > 0.0 && ticks < 200 {
            loco_step(
                &mut m,
                stop,
                &BodyLimits::default(),
                &mode,
                Vec3::ZERO,
                0.05,
                &mut None,
            );
            ticks += 1;
        }
        assert_eq!(m.speed, 0.0, "stopped after {ticks} ticks");
        assert!(ticks < 60, "{ticks}");
    }

    #[test]
    fn port_thrust_turns_gradually() {
        let mut m = Motion {
            speed: 1.0,
            ..Default::default()
        };
        let mode = Mode::RigidBody(RigidParams::default());
        loco_step(
            &mut m,
            Steer::Turn {
                yaw: 0.5,
                pitch: 0.0,
                speed: 1.0,
            },
            &BodyLimits::default(),
            &mode,
            Vec3::ZERO,
            0.1,
            &mut None,
        );
        // torque = min(30·0.5, 20) = 15 → rate 1.5 rad/s → yaw 0.15 after one step.
        assert!((m.yaw - 0.15).abs() < 1e-6, "{}", m.yaw);
    }
}
