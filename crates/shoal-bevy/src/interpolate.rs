//! Transforms between ticks: each frame an agent's [`Transform`] is its previous tick's pose
//! blended toward the last one by how far the fixed clock has run into the next tick (the
//! render trails the simulation by up to one tick, and motion looks smooth at any frame rate).
//! Also keeps the fixed clock's step equal to the simulation's `dt`. Reads [`ShoalSim`] and the
//! agents' [`SimPose`]; writes their `Transform`s and `Time<Fixed>`.

use crate::agents::SimPose;
use crate::sim::ShoalSim;
use bevy::prelude::*;

/// Whether transforms blend between ticks (set by [`crate::ShoalPlugin`]).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq)]
pub struct Interpolation(pub bool);

/// Sets each agent's translation and rotation (its scale is the app's) from its [`SimPose`].
pub(crate) fn interpolate(
    on: Res<Interpolation>,
    fixed: Res<Time<Fixed>>,
    mut agents: Query<(&SimPose, &mut Transform)>,
) {
    let t = if on.0 {
        fixed.overstep_fraction().clamp(0.0, 1.0)
    } else {
        1.0
    };
    for (pose, mut tr) in &mut agents {
        let p = pose.previous.lerp(&pose.current, t);
        tr.translation = p.translation;
        tr.rotation = p.rotation;
    }
}

/// Keeps `Time<Fixed>`'s step at the simulation's `dt`, so that one run of `FixedUpdate` is one
/// tick of simulated time.
pub(crate) fn match_timestep(
    sim: Option<Res<ShoalSim>>,
    mut fixed: ResMut<Time<Fixed>>,
    mut applied: Local<Option<f32>>,
) {
    let Some(sim) = sim else { return };
    let dt = sim.sim().world.dt;
    if *applied != Some(dt) && dt.is_finite() && dt > 0.0 {
        // The decimal the scenario states (0.05), not the f32's binary value widened
        // (0.0500000007…): a timestep a nanosecond longer than 50 ms would make a 50-ms frame
        // miss its tick.
        let seconds = dt.to_string().parse::<f64>().unwrap_or(dt as f64);
        fixed.set_timestep(std::time::Duration::from_secs_f64(seconds));
        *applied = Some(dt);
    }
}
