//! Animation channel (seed 001 "tail animation by tweening"): five key tail poses L, ML, M, MR, R,
//! `pose = A·(1−t) + B·t` between neighboring poses with an eased `t`. The tail beats through the
//! poses at a rate that grows with speed and acceleration; a turn bends it to the turn's side
//! (left turn: L/ML/M, right turn: R/MR/M) by an amount taken from the turn angle.

pub use crate::params::locomotion::AnimParams;
use crate::world::Anim;
use std::f32::consts::{FRAC_PI_4, TAU};

/// The five key poses as bends, left negative: L, ML, M, MR, R.
pub fn key_poses(max_bend: f32) -> [f32; 5] {
    [-max_bend, -max_bend / 2.0, 0.0, max_bend / 2.0, max_bend]
}

/// Eased tween parameter: `tan(t·π/4)` maps \[0, 1\] onto \[0, 1\], slow at the start and fast at the
/// end (the paper's `tan(t)` easing, normalized).
pub fn ease(t: f32) -> f32 {
    crate::frame::tan_quarter(t.clamp(0.0, 1.0) * FRAC_PI_4)
}

/// Bend at position `s` ∈ [−1, 1] along the pose sequence L(−1) … M(0) … R(+1), tweened
/// between the two neighboring key poses.
pub fn tween(s: f32, max_bend: f32) -> f32 {
    let poses = key_poses(max_bend);
    // In [0, 4] (or NaN, which `as` maps to 0): truncation is its floor, without the library
    // call `floor` is on baseline x86-64.
    let x = (s.clamp(-1.0, 1.0) + 1.0) * 2.0;
    let i = (x as usize).min(3);
    let t = ease(x - i as f32);
    poses[i] * (1.0 - t) + poses[i + 1] * t
}

/// `phase.rem_euclid(1.0)` (0 for a non-finite phase), without the library's `fmodf` for the
/// phases a step leaves (below 2, where `phase − 1` is exact).
fn wrap_phase(phase: f32) -> f32 {
    if (0.0..1.0).contains(&phase) {
        phase
    } else if (1.0..2.0).contains(&phase) {
        phase - 1.0
    } else if phase.is_finite() {
        phase.rem_euclid(1.0)
    } else {
        0.0
    }
}

/// Advances the channel by one step: `speed` over a body of `length`, `accel` the speed change
/// per second, `dyaw` the turn applied this step (right positive) against `max_turn`.
#[allow(clippy::too_many_arguments)]
pub fn advance(
    anim: &mut Anim,
    p: &AnimParams,
    speed: f32,
    length: f32,
    accel: f32,
    dyaw: f32,
    max_turn: f32,
    dt: f32,
) {
    let rate = p.idle_rate
        + p.beats_per_length * speed.max(0.0) / length.max(1e-3)
        + p.accel_rate * accel.max(0.0);
    let phase = anim.phase + rate * dt;
    anim.phase = wrap_phase(phase);
    anim.turn = if max_turn > 0.0 {
        (dyaw / max_turn).clamp(-1.0, 1.0)
    } else {
        0.0
    };
}

/// The tail's bend (rad, negative = bent to the left) of a channel: the swim cycle's swing
/// through the key poses, and a turn holding the tail on its side (left turns tween
/// M→ML→L, right turns M→MR→R) in proportion to the turn.
pub fn bend(anim: &Anim, p: &AnimParams) -> f32 {
    let swing = tween(crate::math::sin(anim.phase * TAU), p.max_bend);
    let turn = anim.turn;
    let turn_pose = tween(turn, p.max_bend);
    let bend = swing * (1.0 - turn.abs()) + turn_pose * turn.abs();
    if bend.is_finite() {
        bend
    } else {
        0.0
    }
}

/// Agent `a`'s tail bend under its species in `set` (0 for a species `set` does not hold), as
/// a recording writes it.
pub fn bend_of(set: &crate::species::SpeciesSet, a: &crate::world::Agent) -> f32 {
    set.species
        .get(a.species.0 as usize)
        .map_or(0.0, |sp| bend(&a.anim, &sp.body.anim))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_phase_is_rem_euclid_bit_for_bit() {
        let mut x = -3.0f32;
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            2.0,
            1.0 - f32::EPSILON,
            2.0 - 2.0 * f32::EPSILON,
        ];
        while x < 5.0 {
            values.push(x);
            x += 0.000_973;
        }
        for v in values {
            assert_eq!(wrap_phase(v).to_bits(), v.rem_euclid(1.0).to_bits(), "{v}");
        }
        assert_eq!(wrap_phase(f32::NAN), 0.0);
        assert_eq!(wrap_phase(f32::INFINITY), 0.0);
    }

    #[test]
    fn tween_hits_key_poses_and_eases_between() {
        let b = 0.4;
        assert!((tween(-1.0, b) + 0.4).abs() < 1e-6);
        assert!((tween(-0.5, b) + 0.2).abs() < 1e-6);
        assert!(tween(0.0, b).abs() < 1e-6);
        assert!((tween(1.0, b) - 0.4).abs() < 1e-6);
        // Halfway from M (0) to MR (0.2): t = tan(π/8) = 0.41421 → 0.082843.
        assert!((tween(0.25, b) - 0.2 * crate::math::tan(std::f32::consts::PI / 8.0)).abs() < 1e-6);
    }

    #[test]
    fn a_full_left_turn_bends_to_l() {
        let mut a = Anim::default();
        let p = AnimParams::default();
        advance(&mut a, &p, 1.0, 1.0, 0.0, -FRAC_PI_4, FRAC_PI_4, 0.1);
        assert!((bend(&a, &p) + p.max_bend).abs() < 1e-6);
        assert!(a.phase > 0.0 && a.phase < 1.0);
    }

    #[test]
    fn faster_bodies_beat_faster() {
        let p = AnimParams::default();
        let (mut slow, mut fast) = (Anim::default(), Anim::default());
        advance(&mut slow, &p, 0.5, 1.0, 0.0, 0.0, 1.0, 0.1);
        advance(&mut fast, &p, 2.0, 1.0, 0.0, 0.0, 1.0, 0.1);
        assert!(fast.phase > slow.phase);
    }
}
