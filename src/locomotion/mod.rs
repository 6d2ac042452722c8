//! Stage 6 of the tick: locomotion. Turns a steering command into motion under the body's
//! limits, self-balancing as in seed 002 (yaw about world up, pitch about the body's lateral axis,
//! |pitch| < 90°, never any roll), either kinematically or with seed 001's rigid-body forces, and
//! advances the animation channel ([`anim`]).
//!
//! Kinematic turning follows seed 002's per-step limit (`max_turn`, 45° per step) when
//! `response` is 0: the command's turn is applied at once, up to the limit, every tick. That form
//! depends on the tick length (the same command turns twice as fast at half the step) and turns
//! any command that alternates from one tick to the next into a zig-zag between the limits. The
//! default adds a turn-rate response: a command's relative turn is closed in about `response`
//! seconds (turn rate = turn / `response`), the rate itself follows that aim with the time
//! constant `smoothing` (so commands that alternate tick to tick average out instead of reaching
//! the body),
//! and `max_turn` is read as the turn of one [`REFERENCE_STEP`]. Speed follows its target the
//! same way, within `max_accel`.

pub mod anim;
mod rigid;
pub mod solid;

pub use crate::params::locomotion::{BodyLimits, Mode, RigidParams};

use crate::frame;
use crate::steering::{Kinematics, Steer};
use glam::Vec3;

/// The step of seed 002's per-step turn limit when a body turns at a rate: `max_turn` per
/// 0.05 s (the scenarios' default tick).
pub const REFERENCE_STEP: f32 = 0.05;

impl BodyLimits {
    /// Pitch limit actually applied.
    pub fn pitch_limit(&self) -> f32 {
        self.max_pitch.abs().min(frame::PITCH_LIMIT)
    }
}

/// The moving part of a body, updated by [`step`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Motion {
    /// Position.
    pub pos: Vec3,
    /// Yaw.
    pub yaw: f32,
    /// Pitch.
    pub pitch: f32,
    /// Speed.
    pub speed: f32,
    /// Yaw rate (rigid-body mode).
    pub yaw_rate: f32,
    /// Pitch rate (rigid-body mode).
    pub pitch_rate: f32,
}

/// What a step did, for the animation channel.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepInfo {
    /// Yaw change applied this step.
    pub dyaw: f32,
    /// Speed change this step.
    pub dspeed: f32,
    /// Forward unit vector of the new heading (`frame::forward`).
    pub forward: Vec3,
}

/// The kinematic mode's response factors `1 − exp(−dt/τ)` of a body and a step: of the turn
/// (`response`), of its rate (`smoothing`) and of the speed. They depend on the species, the
/// behavior's response and `dt` alone, so a pass over many agents works them out once
/// ([`Gains::get`]) instead of three exponentials an agent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// What they were worked out for: the bits of `dt`, `response`, `smoothing` and
    /// `speed_response`.
    key: GainsKey,
    kr: f32,
    ks: f32,
}

type GainsKey = (u32, u32, u32, Option<u32>);

impl Gains {
    /// The factors of `limits` over a step of `dt`.
    pub fn of(limits: &BodyLimits, dt: f32) -> Self {
        let k = 1.0 - crate::math::exp(-dt / limits.response);
        let kr = if limits.smoothing > 0.0 {
            1.0 - crate::math::exp(-dt / limits.smoothing)
        } else {
            1.0
        };
        let ks = match limits.speed_response {
            Some(t) if t > 0.0 => 1.0 - crate::math::exp(-dt / t),
            Some(_) => 1.0,
            None => k,
        };
        Gains {
            key: Self::key(limits, dt),
            kr,
            ks,
        }
    }

    fn key(limits: &BodyLimits, dt: f32) -> GainsKey {
        (
            dt.to_bits(),
            limits.response.to_bits(),
            limits.smoothing.to_bits(),
            limits.speed_response.map(f32::to_bits),
        )
    }

    /// The factors of `limits` over `dt`, from `memo` when it holds them (it then holds these).
    #[inline]
    pub fn get(memo: &mut Option<Gains>, limits: &BodyLimits, dt: f32) -> Gains {
        match *memo {
            Some(g) if g.key == Self::key(limits, dt) => g,
            _ => *memo.insert(Self::of(limits, dt)),
        }
    }
}

/// Advances `m` by one step of `dt` under `cmd`, with the world `current` added to the motion.
/// Non-finite commands are treated as "keep heading and speed". The response factors come from
/// `gains` when it holds those of `limits` and `dt` (see [`Gains::get`]; `&mut None`: worked
/// out afresh).
pub fn step(
    m: &mut Motion,
    cmd: Steer,
    limits: &BodyLimits,
    mode: &Mode,
    current: Vec3,
    dt: f32,
    gains: &mut Option<Gains>,
) -> StepInfo {
    let kin = Kinematics {
        pos: m.pos,
        yaw: m.yaw,
        pitch: m.pitch,
        speed: m.speed,
    };
    let (mut dyaw, mut dpitch, mut target) = if cmd.is_finite() {
        cmd.as_turn(&kin)
    } else {
        (0.0, 0.0, m.speed)
    };
    if !(dyaw.is_finite() && dpitch.is_finite() && target.is_finite()) {
        (dyaw, dpitch, target) = (0.0, 0.0, m.speed);
    }
    let turn = limits.max_turn.abs();
    let vmax = limits.max_speed.max(0.0);
    let vmin = limits.min_speed.clamp(0.0, vmax);
    let target = target.clamp(vmin, vmax);
    let before = m.speed;
    match mode {
        Mode::Kinematic if limits.response > 0.0 && dt > 0.0 => {
            let tau = limits.response;
            let Gains { kr, ks, .. } = Gains::get(gains, limits, dt);
            let max_rate = turn / REFERENCE_STEP;
            let plim = limits.pitch_limit();
            m.yaw_rate += ((dyaw / tau).clamp(-max_rate, max_rate) - m.yaw_rate) * kr;
            m.pitch_rate += ((dpitch / tau).clamp(-max_rate, max_rate) - m.pitch_rate) * kr;
            m.yaw = frame::wrap(m.yaw + m.yaw_rate * dt);
            m.pitch += m.pitch_rate * dt;
            // A body held at its pitch limit keeps no rate pushing into it.
            if m.pitch.abs() >= plim && m.pitch_rate * m.pitch > 0.0 {
                m.pitch_rate = 0.0;
            }
            let dv = ((target - m.speed) * ks).clamp(-limits.max_accel * dt, limits.max_accel * dt);
            m.speed += dv;
        }
        Mode::Kinematic => {
            m.yaw = frame::wrap(m.yaw + dyaw.clamp(-turn, turn));
            m.pitch += dpitch.clamp(-turn, turn);
            let dv = (target - m.speed).clamp(-limits.max_accel * dt, limits.max_accel * dt);
            m.speed += dv;
            m.yaw_rate = 0.0;
            m.pitch_rate = 0.0;
        }
        Mode::RigidBody(p) => rigid::step(m, p, dyaw, dpitch, target, turn, dt),
    }
    let plim = limits.pitch_limit();
    m.pitch = m.pitch.clamp(-plim, plim);
    m.speed = m.speed.clamp(vmin, vmax);
    if !m.speed.is_finite() {
        m.speed = 0.0;
    }
    let applied = frame::wrap(m.yaw - kin.yaw);
    let forward = frame::forward(m.yaw, m.pitch);
    let v = forward * m.speed
        + if current.is_finite() {
            current
        } else {
            Vec3::ZERO
        };
    m.pos += v * dt;
    StepInfo {
        dyaw: applied,
        dspeed: m.speed - before,
        forward,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f32::consts::FRAC_PI_4;

    #[test]
    fn remembered_gains_move_a_body_as_fresh_ones_do() {
        // One memo across bodies, behaviors' responses and steps, as a worker keeps it: each
        // step is the step worked out afresh, bit for bit.
        let base = BodyLimits::default();
        let bodies = [
            base,
            BodyLimits {
                response: 0.4,
                ..base
            },
            BodyLimits {
                smoothing: 0.0,
                ..base
            },
            BodyLimits {
                speed_response: Some(0.7),
                ..base
            },
            BodyLimits {
                speed_response: Some(0.0),
                ..base
            },
        ];
        // Every body after every body, at the same step and another: a memo that missed one
        // of the four things the factors depend on would hand one the other's.
        let mut memo = None;
        let (mut a, mut b) = (Motion::default(), Motion::default());
        let mut k = 0;
        for first in &bodies {
            for second in &bodies {
                for dt in [0.05, 0.025] {
                    for (limits, dt) in [(first, 0.05), (second, dt)] {
                        let cmd = Steer::Velocity(Vec3::new(1.0 - k as f32 * 0.01, 0.2, 1.0));
                        let m = Mode::Kinematic;
                        let fresh = step(&mut a, cmd, limits, &m, Vec3::ZERO, dt, &mut None);
                        let kept = step(&mut b, cmd, limits, &m, Vec3::ZERO, dt, &mut memo);
                        assert_eq!(fresh, kept, "step {k}");
                        assert_eq!(a, b, "step {k}");
                        k += 1;
                    }
                }
            }
        }
        assert!(a.yaw_rate != 0.0 && a.speed > 0.0);
    }

    #[test]
    fn turn_is_clamped_to_45_degrees_per_step() {
        let mut m = Motion {
            speed: 1.0,
            ..Default::default()
        };
        let l = BodyLimits {
            response: 0.0,
            ..BodyLimits::default()
        };
        step(
            &mut m,
            Steer::Turn {
                yaw: 2.0,
                pitch: -2.0,
                speed: 1.0,
            },
            &l,
            &Mode::Kinematic,
            Vec3::ZERO,
            0.1,
            &mut None,
        );
        assert!((m.yaw - FRAC_PI_4).abs() < 1e-6);
        assert!((m.pitch + FRAC_PI_4).abs() < 1e-6);
        // Moved 0.1 along the new forward.
        assert!((m.pos - frame::forward(m.yaw, m.pitch) * 0.1).length() < 1e-6);
    }

    #[test]
    fn speed_follows_target_within_acceleration() {
        let mut m = Motion::default();
        let l = BodyLimits {
            response: 0.0,
            ..BodyLimits::default()
        }; // 4 units/s², V_max 2
        step(
            &mut m,
            Steer::Turn {
                yaw: 0.0,
                pitch: 0.0,
                speed: 10.0,
            },
            &l,
            &Mode::Kinematic,
            Vec3::ZERO,
            0.1,
            &mut None,
        );
        assert!((m.speed - 0.4).abs() < 1e-6);
        for _ in 0..20 {
            step(
                &mut m,
                Steer::Turn {
                    yaw: 0.0,
                    pitch: 0.0,
                    speed: 10.0,
                },
                &l,
                &Mode::Kinematic,
                Vec3::ZERO,
                0.1,
                &mut None,
            );
        }
        assert_eq!(m.speed, 2.0);
    }

    /// Yaw after `seconds` of a command, re-issued every tick, at tick length `dt`.
    fn yaw_after(cmd: impl Fn(usize) -> f32, l: &BodyLimits, dt: f32, seconds: f32) -> Vec<f32> {
        let mut m = Motion {
            speed: 1.0,
            ..Default::default()
        };
        let n = (seconds / dt).round() as usize;
        (0..n)
            .map(|k| {
                let c = Steer::Turn {
                    yaw: cmd(k),
                    pitch: 0.0,
                    speed: 1.0,
                };
                step(&mut m, c, l, &Mode::Kinematic, Vec3::ZERO, dt, &mut None);
                m.yaw
            })
            .collect()
    }

    #[test]
    fn turn_rate_response_does_not_depend_on_the_tick_length() {
        // +π/8 every tick for 1 s: the paper's form turns 20·π/8 at 20 Hz and 40·π/8 at 40 Hz;
        // with a response of 0.25 s the body turns at about (π/8)/0.25 = 1.57 rad/s either way.
        let l = BodyLimits::default();
        let a = *yaw_after(|_| std::f32::consts::FRAC_PI_8, &l, 0.05, 1.0)
            .last()
            .unwrap();
        let b = *yaw_after(|_| std::f32::consts::FRAC_PI_8, &l, 0.025, 1.0)
            .last()
            .unwrap();
        assert!((a - b).abs() < 0.05 * b, "{a} {b}");
        assert!(a > 1.1 && a < 1.6, "{a}");
        let paper = BodyLimits { response: 0.0, ..l };
        // 0.05 rad a tick: 1 rad in 20 ticks, 2 rad in 40 (no wrap past π).
        let a = yaw_after(|_| 0.05, &paper, 0.05, 1.0);
        let b = yaw_after(|_| 0.05, &paper, 0.025, 1.0);
        assert!((b.last().unwrap() / a.last().unwrap() - 2.0).abs() < 1e-3);
    }

    #[test]
    fn alternating_commands_do_not_reach_the_body_as_a_zig_zag() {
        // ±0.5 rad alternating every tick: the paper's form swings the heading by 0.5 each tick,
        // the response keeps the body within a few hundredths of a radian of straight.
        let alt = |k: usize| if k.is_multiple_of(2) { 0.5 } else { -0.5 };
        let l = BodyLimits::default();
        let swing = |ys: &[f32]| {
            ys.windows(2)
                .map(|w| (w[1] - w[0]).abs())
                .fold(0.0, f32::max)
        };
        let smooth = yaw_after(alt, &l, 0.05, 2.0);
        let paper = yaw_after(alt, &BodyLimits { response: 0.0, ..l }, 0.05, 2.0);
        assert!(swing(&paper) > 0.49);
        assert!(swing(&smooth) < 0.1, "{}", swing(&smooth));
        assert!(smooth.iter().all(|y| y.abs() < 0.1));
    }

    #[test]
    fn current_drifts_the_body() {
        let mut m = Motion::default();
        step(
            &mut m,
            Steer::None,
            &BodyLimits::default(),
            &Mode::Kinematic,
            Vec3::new(1.0, 0.0, 0.0),
            0.5,
            &mut None,
        );
        assert_eq!(m.pos, Vec3::new(0.5, 0.0, 0.0));
    }

    fn finite() -> impl Strategy<Value = f32> {
        prop_oneof![
            -1e6f32..1e6,
            Just(0.0f32),
            Just(f32::MAX),
            Just(f32::MIN),
            Just(1e-30f32)
        ]
    }

    fn any_cmd() -> impl Strategy<Value = Steer> {
        prop_oneof![
            Just(Steer::None),
            (finite(), finite(), finite()).prop_map(|(yaw, pitch, speed)| Steer::Turn {
                yaw,
                pitch,
                speed
            }),
            (finite(), finite(), finite())
                .prop_map(|(x, y, z)| Steer::Velocity(Vec3::new(x, y, z))),
            Just(Steer::Velocity(Vec3::ZERO)),
            Just(Steer::Velocity(Vec3::Y)),
            Just(Steer::Turn {
                yaw: f32::NAN,
                pitch: 0.0,
                speed: 1.0
            }),
        ]
    }

    proptest! {
        #[test]
        fn balance_and_limits_hold_for_any_command(
            cmds in proptest::collection::vec(any_cmd(), 1..40),
            rigid in any::<bool>(),
            yaw0 in -3.0f32..3.0, pitch0 in -1.5f32..1.5, speed0 in 0.0f32..2.0,
        ) {
            let l = BodyLimits::default();
            let mode = if rigid { Mode::RigidBody(RigidParams::default()) } else { Mode::Kinematic };
            let mut m = Motion { yaw: yaw0, pitch: pitch0.clamp(-l.pitch_limit(), l.pitch_limit()), speed: speed0, ..Default::default() };
            for c in cmds {
                let before = m;
                let info = step(&mut m, c, &l, &mode, Vec3::ZERO, 0.05, &mut None);
                prop_assert!(m.pos.is_finite() && m.yaw.is_finite() && m.pitch.is_finite() && m.speed.is_finite());
                prop_assert!(m.pitch.abs() < std::f32::consts::FRAC_PI_2, "pitch {}", m.pitch);
                prop_assert!(m.speed >= 0.0 && m.speed <= l.max_speed);
                prop_assert!(info.dyaw.abs() <= l.max_turn + 1e-5, "turn {}", info.dyaw);
                prop_assert!((m.pitch - before.pitch).abs() <= l.max_turn + 1e-5);
                // No roll: the body's left axis stays horizontal and its up stays above the horizon.
                prop_assert_eq!(frame::left(m.yaw).y, 0.0);
                prop_assert!(frame::dorsal(m.yaw, m.pitch).y > 0.0);
            }
        }
    }
}
