//! Locomotion's parameter types (stage 6), as species files write them: how a species moves
//! (kinematic, or seed 001's rigid body and its force constants), the body limits (seed 002) and
//! the tail animation's constants (seed 001). Pure data: the motion itself, and these types' own
//! methods, stay in [`crate::locomotion`], which re-exports each type under its old path.

use serde::{Deserialize, Serialize};
use std::f32::consts::FRAC_PI_4;

/// How a species moves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum Mode {
    /// Heading and speed follow the command directly, within the turn and speed limits.
    #[default]
    Kinematic,
    /// Seed 001: tail thrust, port/starboard and up/down thrusts, fluid drag.
    RigidBody(RigidParams),
}

/// Body limits (seed 002: 45° maximum turn per step by default).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BodyLimits {
    /// Largest speed V_max.
    pub max_speed: f32,
    /// Smallest speed V_min (0 lets it stop).
    pub min_speed: f32,
    /// Largest yaw or pitch change per step (rad).
    pub max_turn: f32,
    /// Largest pitch magnitude (rad), capped just inside 90°.
    pub max_pitch: f32,
    /// Largest change of speed per second.
    pub max_accel: f32,
    /// Time (s) in which a kinematic body closes a commanded turn or speed change; 0 applies
    /// each tick's command at once (the paper's per-step form, see [`crate::locomotion`]).
    pub response: f32,
    /// Time (s) in which a kinematic body closes a commanded speed change, when it differs from
    /// `response` (a schooling fish that turns gently but still bursts away; default: `response`).
    pub speed_response: Option<f32>,
    /// Time constant (s) with which the turn rate follows its aim (0: at once). What keeps
    /// commands that alternate tick to tick from reaching the body; more lag makes schools
    /// that align by following each other's headings slower to agree.
    pub smoothing: f32,
}

impl Default for BodyLimits {
    fn default() -> Self {
        BodyLimits {
            max_speed: 2.0,
            min_speed: 0.0,
            max_turn: FRAC_PI_4,
            max_pitch: 80f32.to_radians(),
            max_accel: 4.0,
            response: 0.25,
            speed_response: None,
            smoothing: 0.25,
        }
    }
}

/// Force constants of the rigid-body mode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RigidParams {
    /// Body mass.
    pub mass: f32,
    /// Largest tail thrust (forward force).
    pub max_thrust: f32,
    /// Tail thrust gain per unit of missing speed.
    pub thrust_gain: f32,
    /// Quadratic fluid drag coefficient: `Fa = −drag·v·|v|`.
    pub drag: f32,
    /// Largest port/starboard (yaw) thrust torque.
    pub max_yaw_torque: f32,
    /// Largest up/down (pitch) thrust torque.
    pub max_pitch_torque: f32,
    /// Torque gain per radian of heading error.
    pub turn_gain: f32,
    /// Angular damping (torque per rad/s).
    pub angular_damping: f32,
    /// Moment of inertia about both turning axes.
    pub inertia: f32,
}

impl Default for RigidParams {
    fn default() -> Self {
        RigidParams {
            mass: 1.0,
            max_thrust: 8.0,
            thrust_gain: 6.0,
            drag: 0.5,
            max_yaw_torque: 20.0,
            max_pitch_torque: 10.0,
            turn_gain: 30.0,
            angular_damping: 6.0,
            inertia: 1.0,
        }
    }
}

/// Animation constants.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AnimParams {
    /// Bend of the extreme poses L and R (rad).
    pub max_bend: f32,
    /// Tail beats per second at rest (idle fanning).
    pub idle_rate: f32,
    /// Extra beats per body length travelled.
    pub beats_per_length: f32,
    /// Extra beats per second per unit of acceleration (the tail beats while accelerating).
    pub accel_rate: f32,
}

impl Default for AnimParams {
    fn default() -> Self {
        AnimParams {
            max_bend: 0.5,
            idle_rate: 0.3,
            beats_per_length: 0.8,
            accel_rate: 0.5,
        }
    }
}
