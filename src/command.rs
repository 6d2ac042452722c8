//! The steering command: what stage 5 (steering) hands to stage 6 (locomotion), and what an
//! agent's record keeps of it (its last command, its script's steering terms). It lives below
//! both stages and the world so that each reads it without importing the other.

use crate::frame::{self, Kinematics};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A steering command.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum Steer {
    /// Nothing to do: in a priority list the next entry is tried.
    #[default]
    None,
    /// Turn by `yaw` and `pitch` (rad, relative to the current heading; right and up positive)
    /// and aim for `speed`.
    Turn {
        /// Relative yaw.
        yaw: f32,
        /// Relative pitch.
        pitch: f32,
        /// Target speed.
        speed: f32,
    },
    /// Aim for this world-space velocity.
    Velocity(Vec3),
}

impl Steer {
    /// No command.
    pub const NONE: Steer = Steer::None;

    /// Keep heading and speed.
    pub fn keep(kin: &Kinematics) -> Steer {
        Steer::Turn {
            yaw: 0.0,
            pitch: 0.0,
            speed: kin.speed,
        }
    }

    /// Whether this is [`Steer::None`].
    pub fn is_none(&self) -> bool {
        matches!(self, Steer::None)
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        match *self {
            Steer::None => true,
            Steer::Turn { yaw, pitch, speed } => {
                yaw.is_finite() && pitch.is_finite() && speed.is_finite()
            }
            Steer::Velocity(v) => v.is_finite(),
        }
    }

    /// The desired world velocity this command stands for, from `kin`.
    pub fn desired_velocity(&self, kin: &Kinematics) -> Vec3 {
        match *self {
            Steer::None => kin.velocity(),
            Steer::Turn { yaw, pitch, speed } => {
                let p = (kin.pitch + pitch).clamp(-frame::PITCH_LIMIT, frame::PITCH_LIMIT);
                frame::forward(kin.yaw + yaw, p) * speed
            }
            Steer::Velocity(v) => v,
        }
    }

    /// The same command as relative turn angles and a target speed (unclamped: locomotion
    /// applies the limits). A zero desired velocity keeps the heading and stops.
    pub fn as_turn(&self, kin: &Kinematics) -> (f32, f32, f32) {
        match *self {
            Steer::None => (0.0, 0.0, kin.speed),
            Steer::Turn { yaw, pitch, speed } => (yaw, pitch, speed),
            Steer::Velocity(v) => match frame::heading_of(v) {
                Some((y, p)) => {
                    let horizontal = v.x * v.x + v.z * v.z > 1e-12;
                    let dyaw = if horizontal {
                        frame::wrap(y - kin.yaw)
                    } else {
                        0.0
                    };
                    (dyaw, p - kin.pitch, v.length())
                }
                None => (0.0, 0.0, 0.0),
            },
        }
    }
}

/// One term of a script-built steering value: evaluated natively every tick until the script
/// runs again.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Term {
    /// One of the species' named recipes, by index.
    Recipe(u16),
    /// A fixed desired velocity.
    Velocity(Vec3),
    /// A relative turn and a target speed.
    Turn(f32, f32, f32),
}
