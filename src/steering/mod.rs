//! Stage 5 of the tick: steering. Small pure functions that turn percepts into a [`Steer`]
//! command, and the two ways to combine them (strict priority and weighted blending).
//!
//! One file per family of primitives, each citing its source:
//! - [`avoid`]: avoid static / dynamic obstacle by pressures (seed 000 §4.1, §4.2), collision
//!   prediction by the path test and boundary containment (seed 001);
//! - [`goal`]: move to goal in smell and vision mode (seed 000 §4.3, seed 003 foraging), seek,
//!   flee, arrive, pursuit with linear or intercept prediction (seed 002);
//! - [`escape`]: escape in smell and vision mode and its completion test (seed 000 §4.4), escape
//!   by seeking the mirrored point (seed 002);
//! - [`group`]: separation, alignment, cohesion (seed 001), R–A zones and Vicsek alignment
//!   (seed 003);
//! - [`wander`]: random yaw/pitch increments inside the balance limits (seed 002).

pub mod avoid;
pub mod escape;
pub mod goal;
pub mod group;
pub mod recipe;
pub mod wander;

#[cfg(test)]
mod props;

use glam::Vec3;

pub use crate::command::{Steer, Term};
pub use crate::frame::Kinematics;

/// Strict priority: the first command that is not [`Steer::None`] wins.
pub fn first_of(cmds: impl IntoIterator<Item = Steer>) -> Steer {
    cmds.into_iter()
        .find(|c| !c.is_none())
        .unwrap_or(Steer::None)
}

/// Weighted blending (seed 003's weighted constraints): each command is turned into a steering
/// vector `desired − current`, the vectors are summed with their weights and added to the current
/// velocity. Commands that are [`Steer::None`] or have a zero weight do not count; with none left
/// the result is [`Steer::None`]. A single command with weight 1 gives back its own velocity.
pub fn blend(kin: &Kinematics, cmds: impl IntoIterator<Item = (f32, Steer)>) -> Steer {
    blend_from(kin.velocity(), kin, cmds)
}

/// [`blend`] around a known current velocity (`kin.velocity()`).
pub fn blend_from(
    current: Vec3,
    kin: &Kinematics,
    cmds: impl IntoIterator<Item = (f32, Steer)>,
) -> Steer {
    let mut b = Blend::new(current, kin);
    for (w, c) in cmds {
        b.add(w, c);
    }
    b.finish()
}

/// A [`blend`] in progress: commands go in one at a time with [`Blend::add`].
#[derive(Debug, Clone, Copy)]
pub struct Blend<'a> {
    current: Vec3,
    kin: &'a Kinematics,
    sum: Vec3,
    any: bool,
}

impl<'a> Blend<'a> {
    /// Nothing blended yet, around the current velocity `current` (`kin.velocity()`).
    #[inline]
    pub fn new(current: Vec3, kin: &'a Kinematics) -> Self {
        Blend {
            current,
            kin,
            sum: Vec3::ZERO,
            any: false,
        }
    }

    /// Adds command `c` with weight `w` (ignored if it is [`Steer::None`] or the weight is zero
    /// or not finite).
    #[inline]
    pub fn add(&mut self, w: f32, c: Steer) {
        if c.is_none() || w == 0.0 || !w.is_finite() {
            return;
        }
        self.any = true;
        self.sum += w * (c.desired_velocity(self.kin) - self.current);
    }

    /// The blended command.
    #[inline]
    pub fn finish(self) -> Steer {
        if self.any {
            Steer::Velocity(self.current + self.sum)
        } else {
            Steer::None
        }
    }
}

/// Seek: full speed toward `target`.
pub fn seek(kin: &Kinematics, target: Vec3, max_speed: f32) -> Steer {
    match (target - kin.pos).try_normalize() {
        Some(d) => Steer::Velocity(d * max_speed),
        None => Steer::None,
    }
}

/// Flee: full speed away from `threat`.
pub fn flee(kin: &Kinematics, threat: Vec3, max_speed: f32) -> Steer {
    match (kin.pos - threat).try_normalize() {
        Some(d) => Steer::Velocity(d * max_speed),
        None => Steer::Turn {
            yaw: 0.0,
            pitch: 0.0,
            speed: max_speed,
        },
    }
}

/// Arrive: seek that slows down linearly inside `slow_radius` and stops on the target.
pub fn arrive(kin: &Kinematics, target: Vec3, max_speed: f32, slow_radius: f32) -> Steer {
    let off = target - kin.pos;
    let d = off.length();
    if d < 1e-6 {
        return Steer::Velocity(Vec3::ZERO);
    }
    let speed = if slow_radius > 0.0 && d < slow_radius {
        max_speed * d / slow_radius
    } else {
        max_speed
    };
    Steer::Velocity(off / d * speed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kin() -> Kinematics {
        Kinematics {
            pos: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.0,
            speed: 1.0,
        }
    }

    #[test]
    fn blend_of_one_command_with_weight_one_is_that_command() {
        let k = kin();
        let v = Vec3::new(1.0, 0.0, 2.0);
        assert_eq!(blend(&k, [(1.0, Steer::Velocity(v))]), Steer::Velocity(v));
    }

    #[test]
    fn blend_sums_steering_vectors() {
        let k = kin(); // velocity (0,0,1)
        let a = Steer::Velocity(Vec3::new(1.0, 0.0, 1.0)); // steering (1,0,0)
        let b = Steer::Velocity(Vec3::new(0.0, 1.0, 1.0)); // steering (0,1,0)
        assert_eq!(
            blend(&k, [(2.0, a), (0.5, b), (3.0, Steer::None)]),
            Steer::Velocity(Vec3::new(2.0, 0.5, 1.0))
        );
        assert_eq!(blend(&k, [(0.0, a)]), Steer::None);
    }

    #[test]
    fn priority_takes_the_first_non_empty() {
        let t = Steer::Turn {
            yaw: 0.1,
            pitch: 0.0,
            speed: 1.0,
        };
        assert_eq!(first_of([Steer::None, t, Steer::Velocity(Vec3::X)]), t);
        assert_eq!(first_of([Steer::None]), Steer::None);
    }

    #[test]
    fn velocity_to_turn_round_trip() {
        let k = Kinematics {
            pos: Vec3::ZERO,
            yaw: 0.3,
            pitch: 0.1,
            speed: 2.0,
        };
        let t = Steer::Turn {
            yaw: 0.4,
            pitch: -0.2,
            speed: 3.0,
        };
        let v = Steer::Velocity(t.desired_velocity(&k));
        let (y, p, s) = v.as_turn(&k);
        assert!((y - 0.4).abs() < 1e-5 && (p + 0.2).abs() < 1e-5 && (s - 3.0).abs() < 1e-5);
    }

    #[test]
    fn arrive_slows_inside_radius() {
        let k = kin();
        let Steer::Velocity(v) = arrive(&k, Vec3::new(0.0, 0.0, 5.0), 4.0, 10.0) else {
            panic!()
        };
        assert!((v.length() - 2.0).abs() < 1e-6);
        assert_eq!(seek(&k, k.pos, 1.0), Steer::None);
    }
}
