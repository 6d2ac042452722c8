//! Obstacle avoidance: the artificial potential field of seed 000 §4.1 (static) and §4.2
//! (dynamic, weighted by −cos α), and seed 001's collision prediction by the path test and
//! boundary containment.

use super::{Kin, Steer};
use crate::world::Aabb;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::f32::consts::FRAC_PI_8;

/// One obstacle as the pressure field sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressureSource {
    /// Distance d_i from the fish to the obstacle.
    pub dist: f32,
    /// Horizontal angle θ_i between the fish→obstacle line and the velocity (right positive).
    pub bearing: f32,
    /// Vertical angle ω_i (up positive).
    pub elevation: f32,
    /// Size S_i: the obstacle's bounding-box diagonal.
    pub size: f32,
    /// Weight of the term: 1 for static obstacles, −cos α_i for dynamic ones.
    pub weight: f32,
}

/// The four pressures of seed 000 §4.1.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pressures {
    /// Left L.
    pub left: f32,
    /// Right R.
    pub right: f32,
    /// Up U.
    pub up: f32,
    /// Down D.
    pub down: f32,
}

impl Pressures {
    /// Largest of the four.
    pub fn max(&self) -> f32 {
        self.left.max(self.right).max(self.up).max(self.down)
    }
}

/// `L = Σ S_i cos θ_i / (d_i + m0)` over obstacles on the left (R likewise on the right),
/// `U = Σ S_i cos ω_i / (d_i + m0)` over obstacles above (D likewise below), each term times its
/// weight. An obstacle exactly ahead (θ = 0) counts half to each side; exactly level half up,
/// half down.
pub fn pressures(sources: impl IntoIterator<Item = PressureSource>, m0: f32) -> Pressures {
    let mut p = Pressures::default();
    for s in sources {
        let denom = (s.dist.max(0.0) + m0).max(1e-6);
        let h = s.weight * s.size * s.bearing.cos() / denom;
        let v = s.weight * s.size * s.elevation.cos() / denom;
        if s.bearing < 0.0 {
            p.left += h;
        } else if s.bearing > 0.0 {
            p.right += h;
        } else {
            p.left += 0.5 * h;
            p.right += 0.5 * h;
        }
        if s.elevation > 0.0 {
            p.up += v;
        } else if s.elevation < 0.0 {
            p.down += v;
        } else {
            p.up += 0.5 * v;
            p.down += 0.5 * v;
        }
    }
    p
}

/// One obstacle as the front-half field sees it: the unit direction from the body to the
/// obstacle's nearest point, in the body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrontSource {
    /// Distance d_i to the obstacle's nearest point.
    pub dist: f32,
    /// Size S_i: the obstacle's bounding-box diagonal.
    pub size: f32,
    /// Component of the direction along the heading (cos of the 3D angle to the velocity).
    pub forward: f32,
    /// Component to the right of the heading.
    pub right: f32,
    /// Component along the body's dorsal (up) axis.
    pub up: f32,
}

impl FrontSource {
    /// The direction `offset` (obstacle point − body) in the frame of a body with this heading.
    pub fn new(offset: Vec3, dist: f32, size: f32, yaw: f32, pitch: f32) -> FrontSource {
        let d = offset.normalize_or_zero();
        FrontSource {
            dist,
            size,
            forward: d.dot(crate::frame::forward(yaw, pitch)),
            right: -d.dot(crate::frame::left(yaw)),
            up: d.dot(crate::frame::dorsal(yaw, pitch)),
        }
    }
}

/// The front-half field (the runtime's form of seed 000 §4.1): only obstacles ahead of the body
/// count (`forward > 0`), each with `S_i·cos α_i/(d_i + m0)`, α_i the angle between the
/// body→obstacle line and the velocity measured in 3D, to L or R by the side it lies on and to U
/// or D by whether it lies above or below the heading (half to each when exactly on the line).
/// In the heading's own horizontal plane this is the paper's `S_i cos θ_i/(d_i + m0)`; unlike the
/// paper's plane angles, it gives no horizontal pressure for an obstacle straight above or below
/// (whose θ is undefined) and none for obstacles beside or behind, which the paper leaves out by
/// integrating over the front half.
pub fn front_pressures(sources: impl IntoIterator<Item = FrontSource>, m0: f32) -> Pressures {
    const ON_LINE: f32 = 1e-4;
    let mut p = Pressures::default();
    for s in sources {
        if s.forward <= 0.0 || !s.forward.is_finite() {
            continue;
        }
        let t = s.size * s.forward / (s.dist.max(0.0) + m0).max(1e-6);
        if s.right > ON_LINE {
            p.right += t;
        } else if s.right < -ON_LINE {
            p.left += t;
        } else {
            p.left += 0.5 * t;
            p.right += 0.5 * t;
        }
        if s.up > ON_LINE {
            p.up += t;
        } else if s.up < -ON_LINE {
            p.down += t;
        } else {
            p.up += 0.5 * t;
            p.down += 0.5 * t;
        }
    }
    p
}

/// Parameters of the static-obstacle field (seed 000 §4.1); defaults follow the paper's form.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AvoidParams {
    /// Margin m0 added to every distance.
    pub m0: f32,
    /// Turn applied when one side's pressure dominates (π/8).
    pub turn: f32,
    /// Obstacles farther than this are ignored (`None`: everything in view counts, as in the
    /// paper).
    pub range: Option<f32>,
    /// Whether kin count as dynamic obstacles (schooling species leave that to separation).
    pub kin: bool,
    /// Whether the static field takes the paper's form as written: every obstacle in view
    /// counts, with its horizontal and vertical angles θ_i, ω_i ([`pressures`]). The default
    /// (`false`) is the front-half field ([`front_pressures`]): §4.1 integrates over the front
    /// half only, and an obstacle straight above or below has no horizontal angle at all.
    pub paper_field: bool,
    /// Slowest speed braking brings a body to, as a fraction of `V_max` (0: the paper's `Vc/2`
    /// applied every tick, which decays to a standstill next to any obstacle that stays in view).
    pub brake_floor: f32,
}

impl Default for AvoidParams {
    fn default() -> Self {
        AvoidParams {
            m0: 1.0,
            turn: FRAC_PI_8,
            range: None,
            kin: false,
            paper_field: false,
            brake_floor: 0.3,
        }
    }
}

impl AvoidParams {
    /// Whether an obstacle at `dist` counts.
    pub fn in_range(&self, dist: f32) -> bool {
        self.range.is_none_or(|r| dist <= r)
    }
}

/// `M_min = 1/(v_r + m0)`.
pub fn static_m_min(vision_radius: f32, m0: f32) -> f32 {
    1.0 / (vision_radius + m0)
}

/// `M_max = S_f/(V_max·Δt + m0)`.
pub fn static_m_max(fish_size: f32, v_max: f32, dt: f32, m0: f32) -> f32 {
    fish_size / (v_max * dt + m0)
}

/// The turn/pitch rule shared by §4.1 and §4.2: `θ = −π/8` if `L < R`, `+π/8` if `L > R`, keep
/// when both `≤ M_min`; `ω = +π/8` if `U < D`, `−π/8` if `U > D`, keep when both `≤ M_min`.
/// When both sides are equal and above `M_min` (an obstacle dead ahead) it turns left / up.
fn turn_rule(p: &Pressures, m_min: f32, turn: f32) -> (f32, f32) {
    let yaw = if p.left <= m_min && p.right <= m_min {
        0.0
    } else if p.left > p.right {
        turn
    } else {
        -turn
    };
    let pitch = if p.up <= m_min && p.down <= m_min {
        0.0
    } else if p.up > p.down {
        -turn
    } else {
        turn
    };
    (yaw, pitch)
}

/// Avoid static obstacles (seed 000 §4.1) from the field's pressures `p` ([`pressures`] or
/// [`front_pressures`]). Returns [`Steer::None`] when the behavior is done (all four pressures
/// `≤ M_min`). Speed: `Vc/2` when any pressure exceeds `M_max`, else `Vc`; never below
/// `brake_floor·V_max`, so that a body next to an obstacle keeps the speed to leave it (the paper
/// halves the speed every step, which a field that stays above `M_max` turns into a standstill).
/// With the front-half field an obstacle level with the heading does not make the body pitch:
/// it turns, rather than climbing toward the pitch limit.
pub fn avoid_static(
    kin: &Kin,
    p: Pressures,
    vision_radius: f32,
    fish_size: f32,
    v_max: f32,
    dt: f32,
    params: &AvoidParams,
) -> Steer {
    let m_min = static_m_min(vision_radius, params.m0);
    if p.max() <= m_min {
        return Steer::None;
    }
    let m_max = static_m_max(fish_size, v_max, dt, params.m0);
    let (yaw, mut pitch) = turn_rule(&p, m_min, params.turn);
    if !params.paper_field && (p.up - p.down).abs() <= 1e-3 * p.up.max(p.down) {
        pitch = 0.0;
    }
    let speed = if p.max() > m_max {
        kin.speed / 2.0
    } else {
        kin.speed
    };
    let speed = speed.max(params.brake_floor.clamp(0.0, 1.0) * v_max);
    Steer::Turn { yaw, pitch, speed }
}

/// One moving obstacle for §4.2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingObstacle {
    /// Geometry as for the static field (weight is ignored and recomputed).
    pub source: PressureSource,
    /// The obstacle's velocity.
    pub velocity: Vec3,
}

/// `−cos α` for the angle α between two motions; 0 when either is not moving.
pub fn head_on_weight(own: Vec3, other: Vec3) -> f32 {
    match (own.try_normalize(), other.try_normalize()) {
        (Some(a), Some(b)) => -a.dot(b),
        _ => 0.0,
    }
}

/// Avoid dynamic obstacles (seed 000 §4.2): every term of §4.1 times `−cos α_i` (head-on is most
/// dangerous). `M_min = −(1 + √3/2)·cos α/(v_r + m0)` with α of the nearest obstacle,
/// `M_max = S_f/((V_max + V_min)·Δt + m0)` with `V_max`/`V_min` the fastest/slowest obstacle
/// speeds (a negative `M_min`, traffic moving away, is raised to 0). Speed: `Vc` when all pressures `≤ M_min` (then the result is [`Steer::None`]), `0` when
/// any exceeds `M_max`, else `V_min`.
pub fn avoid_dynamic(
    kin: &Kin,
    obstacles: &[MovingObstacle],
    vision_radius: f32,
    fish_size: f32,
    dt: f32,
    params: &AvoidParams,
) -> Steer {
    if obstacles.is_empty() {
        return Steer::None;
    }
    let own = kin.velocity();
    let weighted = obstacles.iter().map(|o| PressureSource {
        weight: head_on_weight(own, o.velocity),
        ..o.source
    });
    let p = pressures(weighted, params.m0);
    let nearest = obstacles
        .iter()
        .min_by(|a, b| a.source.dist.total_cmp(&b.source.dist))
        .expect("non-empty");
    let neg_cos = head_on_weight(own, nearest.velocity);
    let m_min = (1.0 + 3f32.sqrt() / 2.0) * neg_cos / (vision_radius + params.m0);
    // Sides without obstacles have pressure 0; when the nearest obstacle moves away (M_min < 0)
    // that empty side must not count as danger, so the threshold is never below 0.
    let m_min = m_min.max(0.0);
    if p.max() <= m_min {
        return Steer::None;
    }
    let (mut v_fast, mut v_slow) = (0.0f32, f32::INFINITY);
    for o in obstacles {
        let s = o.velocity.length();
        v_fast = v_fast.max(s);
        v_slow = v_slow.min(s);
    }
    let m_max = fish_size / ((v_fast + v_slow) * dt + params.m0);
    let (yaw, pitch) = turn_rule(&p, m_min, params.turn);
    let speed = if p.max() > m_max { 0.0 } else { v_slow };
    Steer::Turn { yaw, pitch, speed }
}

/// Seed 001's path test: with `a` = obstacle centre − position, `p` its projection on the
/// look-ahead vector `v`, `b = a − p`, a hit is predicted when `p` points ahead, `|p| < |v|` and
/// `|b| < r`. Returns the lateral offset `b` of the predicted hit.
pub fn path_test(pos: Vec3, look_ahead: Vec3, center: Vec3, radius: f32) -> Option<Vec3> {
    let len2 = look_ahead.length_squared();
    if len2.is_nan() || len2 <= 1e-12 {
        return None;
    }
    let a = center - pos;
    let t = a.dot(look_ahead) / len2;
    if t <= 0.0 {
        return None;
    }
    let p = look_ahead * t;
    let b = a - p;
    (p.length() < look_ahead.length() && b.length() < radius).then_some(b)
}

/// Collision prediction (seed 001): tests every obstacle's bounding sphere against the path
/// `speed·horizon` ahead and, for the nearest predicted hit, steers sideways away from it (away
/// from `b`; straight ahead hits turn to the left). `obstacles` yields `(centre, radius)`.
pub fn predict_collision(
    kin: &Kin,
    obstacles: impl IntoIterator<Item = (Vec3, f32)>,
    horizon: f32,
    max_speed: f32,
) -> Steer {
    let fwd = kin.forward();
    let look = fwd * kin.speed.max(0.1 * max_speed) * horizon;
    let mut best: Option<(f32, Vec3)> = None;
    for (c, r) in obstacles {
        if let Some(b) = path_test(kin.pos, look, c, r) {
            let along = (c - kin.pos).dot(fwd);
            if best.is_none_or(|(d, _)| along < d) {
                best = Some((along, b));
            }
        }
    }
    let Some((_, b)) = best else {
        return Steer::None;
    };
    let away = match (-b).try_normalize() {
        Some(d) => d,
        None => crate::frame::left(kin.yaw),
    };
    Steer::Velocity((fwd + away).normalize_or_zero() * kin.speed.max(0.1 * max_speed))
}

/// Boundary containment (seed 001: "the world boundary is avoided the same way"): when the point
/// `horizon` seconds ahead leaves `bounds` shrunk by `margin`, steer toward the nearest point
/// inside it.
pub fn contain(kin: &Kin, bounds: &Aabb, margin: f32, horizon: f32, max_speed: f32) -> Steer {
    contain_facing(kin, kin.forward(), bounds, margin, horizon, max_speed)
}

/// [`contain`] for a body whose forward vector (`kin.forward()`) is already known.
pub fn contain_facing(
    kin: &Kin,
    forward: Vec3,
    bounds: &Aabb,
    margin: f32,
    horizon: f32,
    max_speed: f32,
) -> Steer {
    let inner = Aabb {
        min: bounds.min + Vec3::splat(margin),
        max: bounds.max - Vec3::splat(margin),
    };
    let inner = if inner.min.cmple(inner.max).all() {
        inner
    } else {
        Aabb::new(bounds.center(), bounds.center())
    };
    let ahead = kin.pos + forward * kin.speed.max(0.1 * max_speed) * horizon;
    if inner.contains(ahead) && inner.contains(kin.pos) {
        return Steer::None;
    }
    // Steer from the predicted point back toward the inside, keeping some forward motion.
    let back = inner.closest_point(ahead) - ahead;
    let inward = (inner.closest_point(kin.pos) - kin.pos) + back;
    match (forward * 0.5 + inward.normalize_or_zero()).try_normalize() {
        Some(d) => Steer::Velocity(d * max_speed),
        None => Steer::Velocity((inner.center() - kin.pos).normalize_or_zero() * max_speed),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::{FRAC_PI_3, FRAC_PI_4};

    fn kin(speed: f32) -> Kin {
        Kin {
            pos: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.0,
            speed,
        }
    }

    /// The paper's form: the plane-angle field, `Vc/2` without a floor.
    fn paper() -> AvoidParams {
        AvoidParams {
            paper_field: true,
            brake_floor: 0.0,
            ..AvoidParams::default()
        }
    }

    fn src(dist: f32, bearing: f32, elevation: f32, size: f32) -> PressureSource {
        PressureSource {
            dist,
            bearing,
            elevation,
            size,
            weight: 1.0,
        }
    }

    #[test]
    fn pressures_match_hand_computation() {
        // Seed 000 §4.1: S=2, d=3, m0=1, θ=+π/3 (right), ω=+π/4 (above):
        // R = 2·cos(π/3)/(3+1) = 0.25, U = 2·cos(π/4)/4 = 0.353553.
        let p = pressures([src(3.0, FRAC_PI_3, FRAC_PI_4, 2.0)], 1.0);
        assert!((p.right - 0.25).abs() < 1e-6);
        assert!((p.up - 0.353_553_4).abs() < 1e-6);
        assert_eq!(p.left, 0.0);
        assert_eq!(p.down, 0.0);
    }

    #[test]
    fn avoid_static_turns_away_and_halves_speed() {
        // Obstacle on the right, close: R = 2·cos(π/3)/(0.5+1) = 0.6667 > M_max.
        // M_min = 1/(10+1) = 0.0909; M_max = S_f/(V_max·dt + m0) = 0.5/(2·0.1+1) = 0.4167.
        let s = avoid_static(
            &kin(2.0),
            pressures([src(0.5, FRAC_PI_3, 0.0, 2.0)], 1.0),
            10.0,
            0.5,
            2.0,
            0.1,
            &paper(),
        );
        // L < R → θ = −π/8 (turn left). Level obstacle: U = D = 0.6667 (half each) > M_min,
        // equal → pitch up by π/8.
        assert_eq!(
            s,
            Steer::Turn {
                yaw: -FRAC_PI_8,
                pitch: FRAC_PI_8,
                speed: 1.0
            }
        );
    }

    #[test]
    fn avoid_static_is_done_below_m_min() {
        // Far obstacle: R = 1·cos(π/3)/(50+1) = 0.0098 < M_min = 1/11.
        let s = avoid_static(
            &kin(1.0),
            pressures([src(50.0, FRAC_PI_3, 0.2, 1.0)], 1.0),
            10.0,
            0.5,
            2.0,
            0.1,
            &paper(),
        );
        assert_eq!(s, Steer::None);
    }

    #[test]
    fn avoid_static_keeps_speed_between_thresholds() {
        // L = 1·cos(−π/4)/(4+1) = 0.1414: above M_min (0.0909), below M_max (0.4167).
        let s = avoid_static(
            &kin(2.0),
            pressures([src(4.0, -FRAC_PI_4, -0.7, 1.0)], 1.0),
            10.0,
            0.5,
            2.0,
            0.1,
            &paper(),
        );
        // L > R → +π/8 (turn right); below: D = cos(0.7)/5 = 0.153 > M_min, U = 0 → pitch up.
        assert_eq!(
            s,
            Steer::Turn {
                yaw: FRAC_PI_8,
                pitch: FRAC_PI_8,
                speed: 2.0
            }
        );
    }

    fn front(dist: f32, dir: Vec3, size: f32) -> FrontSource {
        let d = dir.normalize();
        FrontSource {
            dist,
            size,
            right: d.x,
            up: d.y,
            forward: d.z,
        }
    }

    #[test]
    fn front_field_matches_the_paper_in_the_heading_plane() {
        // Level obstacle at θ = +π/3 (right), S = 2, d = 3, m0 = 1: R = 2·cos(π/3)/4 = 0.25, and
        // being level it counts half up, half down.
        let (s, c) = FRAC_PI_3.sin_cos();
        let p = front_pressures([front(3.0, Vec3::new(s, 0.0, c), 2.0)], 1.0);
        assert!((p.right - 0.25).abs() < 1e-6, "{p:?}");
        assert_eq!(p.left, 0.0);
        assert!((p.up - 0.125).abs() < 1e-6 && (p.down - 0.125).abs() < 1e-6);
        // Above and ahead at ω = π/4, on the heading's vertical plane: U = 2·cos(π/4)/4.
        let p = front_pressures([front(3.0, Vec3::new(0.0, 1.0, 1.0), 2.0)], 1.0);
        assert!((p.up - 0.353_553_4).abs() < 1e-6 && p.down == 0.0);
        assert!((p.left - 0.176_776_7).abs() < 1e-6 && (p.right - 0.176_776_7).abs() < 1e-6);
    }

    #[test]
    fn front_field_ignores_obstacles_beside_behind_above_and_below() {
        let m0 = 1.0;
        for dir in [
            Vec3::X,
            -Vec3::X,
            -Vec3::Z,
            Vec3::Y,
            -Vec3::Y,
            Vec3::new(1.0, -1.0, -0.2),
        ] {
            let p = front_pressures([front(0.5, dir, 4.0)], m0);
            assert_eq!(p, Pressures::default(), "{dir}");
        }
    }

    #[test]
    fn front_source_reads_the_body_frame() {
        // Heading yaw = π/2 faces −X (a right turn from +Z); an obstacle at −X is dead ahead,
        // one at +Z is on the left, one at +Y is above.
        let f = FrontSource::new(-Vec3::X, 1.0, 1.0, std::f32::consts::FRAC_PI_2, 0.0);
        assert!((f.forward - 1.0).abs() < 1e-6 && f.right.abs() < 1e-6 && f.up.abs() < 1e-6);
        let f = FrontSource::new(Vec3::Z, 1.0, 1.0, std::f32::consts::FRAC_PI_2, 0.0);
        assert!((f.right + 1.0).abs() < 1e-6 && f.forward.abs() < 1e-6);
        let f = FrontSource::new(Vec3::Y, 1.0, 1.0, std::f32::consts::FRAC_PI_2, 0.0);
        assert!((f.up - 1.0).abs() < 1e-6);
    }

    #[test]
    fn braking_keeps_a_floor_and_a_level_obstacle_makes_no_pitch() {
        // Dead ahead, level, close: every pressure above M_max. The paper halves Vc (0.2 → 0.1);
        // the floor keeps 0.3·V_max = 0.6; equal U and D give no pitch, equal L and R turn left.
        let p = front_pressures([front(0.2, Vec3::Z, 2.0)], 1.0);
        let s = avoid_static(&kin(0.2), p, 10.0, 0.5, 2.0, 0.1, &AvoidParams::default());
        assert_eq!(
            s,
            Steer::Turn {
                yaw: -FRAC_PI_8,
                pitch: 0.0,
                speed: 0.6
            }
        );
        let s = avoid_static(&kin(0.2), p, 10.0, 0.5, 2.0, 0.1, &paper());
        assert_eq!(
            s,
            Steer::Turn {
                yaw: -FRAC_PI_8,
                pitch: FRAC_PI_8,
                speed: 0.1
            }
        );
    }

    #[test]
    fn dynamic_weighting_is_minus_cos_alpha() {
        assert!((head_on_weight(Vec3::Z, -Vec3::Z) - 1.0).abs() < 1e-6);
        assert!((head_on_weight(Vec3::Z, Vec3::Z) + 1.0).abs() < 1e-6);
        assert!(head_on_weight(Vec3::Z, Vec3::X).abs() < 1e-6);
        assert_eq!(head_on_weight(Vec3::Z, Vec3::ZERO), 0.0);
    }

    #[test]
    fn avoid_dynamic_head_on_stops() {
        // Head-on (α = π → −cos α = 1) obstacle at θ = +π/3, d = 1, S = 2, m0 = 1:
        // R = 2·0.5/2 = 0.5. M_min = (1+√3/2)·1/(10+1) = 0.16964. Obstacle speed 1 →
        // V_max = V_min = 1, M_max = 0.5/((1+1)·0.1+1) = 0.41667 < 0.5 → speed 0; L < R → left.
        let o = MovingObstacle {
            source: src(1.0, FRAC_PI_3, 0.0, 2.0),
            velocity: -Vec3::Z,
        };
        let s = avoid_dynamic(&kin(1.0), &[o], 10.0, 0.5, 0.1, &AvoidParams::default());
        let Steer::Turn { yaw, speed, .. } = s else {
            panic!("{s:?}")
        };
        assert_eq!(yaw, -FRAC_PI_8);
        assert_eq!(speed, 0.0);
    }

    #[test]
    fn avoid_dynamic_ignores_same_direction_traffic() {
        // Same direction: −cos α = −1, R = −0.5, M_min = −0.16964 raised to 0; all ≤ 0 → done.
        let o = MovingObstacle {
            source: src(1.0, FRAC_PI_3, 0.0, 2.0),
            velocity: Vec3::Z,
        };
        let s = avoid_dynamic(&kin(1.0), &[o], 10.0, 0.5, 0.1, &AvoidParams::default());
        assert_eq!(s, Steer::None);
    }

    #[test]
    fn path_test_matches_seed_001() {
        // Obstacle 5 ahead, 0.5 to the side, radius 1, look-ahead 10 → hit with b = (0.5,0,0).
        let b = path_test(
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, 10.0),
            Vec3::new(0.5, 0.0, 5.0),
            1.0,
        );
        assert_eq!(b, Some(Vec3::new(0.5, 0.0, 0.0)));
        // Beyond the look-ahead: |p| = 12 > |v| = 10.
        assert_eq!(
            path_test(
                Vec3::ZERO,
                Vec3::new(0.0, 0.0, 10.0),
                Vec3::new(0.0, 0.0, 12.0),
                1.0
            ),
            None
        );
        // Too far sideways: |b| = 2 > r = 1.
        assert_eq!(
            path_test(
                Vec3::ZERO,
                Vec3::new(0.0, 0.0, 10.0),
                Vec3::new(2.0, 0.0, 5.0),
                1.0
            ),
            None
        );
        // Behind.
        assert_eq!(
            path_test(
                Vec3::ZERO,
                Vec3::new(0.0, 0.0, 10.0),
                Vec3::new(0.0, 0.0, -5.0),
                1.0
            ),
            None
        );
    }

    #[test]
    fn predicted_collision_steers_away_from_the_side_of_the_obstacle() {
        // Obstacle slightly to the left (+X is left): steer toward −X.
        let s = predict_collision(&kin(1.0), [(Vec3::new(0.3, 0.0, 3.0), 1.0)], 5.0, 1.0);
        let Steer::Velocity(v) = s else { panic!() };
        assert!(v.x < 0.0 && v.z > 0.0);
    }

    #[test]
    fn containment_turns_back_inside() {
        let b = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
        let mut k = kin(1.0);
        assert_eq!(contain(&k, &b, 1.0, 1.0, 1.0), Steer::None);
        k.pos = Vec3::new(0.0, 0.0, 8.5);
        let Steer::Velocity(v) = contain(&k, &b, 1.0, 1.0, 1.0) else {
            panic!()
        };
        assert!(v.z < 0.0);
    }
}
