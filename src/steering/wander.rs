//! Wandering (seed 002): random yaw and pitch increments under the balance limits. The pitch
//! increment is biased back toward level so that a wandering body never drifts to the pitch
//! limit.

use super::Steer;
pub use crate::params::steering::WanderParams;

/// A wander step from two uniform numbers `u` in [0, 1).
pub fn wander(pitch: f32, v_max: f32, params: &WanderParams, u: (f32, f32)) -> Steer {
    Steer::Turn {
        yaw: params.yaw_jitter * (2.0 * u.0 - 1.0),
        pitch: params.pitch_jitter * (2.0 * u.1 - 1.0) - params.level_bias * pitch,
        speed: params.cruise * v_max,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn increments_are_bounded_and_level_seeking() {
        let p = WanderParams::default();
        let Steer::Turn { yaw, pitch, speed } = wander(0.0, 2.0, &p, (1.0, 0.5)) else {
            panic!()
        };
        assert!((yaw - 0.3).abs() < 1e-6 && pitch.abs() < 1e-6 && (speed - 1.0).abs() < 1e-6);
        // Pitched up with neutral noise: pulled down by 10% of the pitch.
        let Steer::Turn { pitch, .. } = wander(0.5, 2.0, &p, (0.5, 0.5)) else {
            panic!()
        };
        assert!((pitch + 0.05).abs() < 1e-6);
    }
}
