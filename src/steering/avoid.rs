//! Obstacle avoidance: the artificial potential field of seed 000 §4.1 (static) and §4.2
//! (dynamic, weighted by −cos α), and seed 001's collision prediction by the path test and
//! boundary containment.
//!
//! Every constant of the two fields is a key of [`AvoidParams`] with the paper's value as its
//! default: the margin `m0`, the turn π/8, the braking factor (`Vc/2`) and the dynamic threshold's
//! factor. The paper integrates §4.2's `M_min` over its ±150° view and gets `(1 + √3/2)`, which is
//! `1 − cos 150°`; the engine takes `1 − cos(half-angle)` of the species' own vision cone by
//! default (the same number for a 150° view), and `m_min_factor: Some(1.866)` keeps the paper's
//! fixed constant whatever the view.

use super::{Kinematics, Steer};
use crate::ctx::Ctx;
pub use crate::params::steering::{AvoidParams, PAPER_M_MIN_FACTOR};
use crate::perception::{Category, Sense, Source};
use crate::world::Aabb;
use glam::Vec3;

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
        let h = s.weight * s.size * crate::math::cos(s.bearing) / denom;
        let v = s.weight * s.size * crate::math::cos(s.elevation) / denom;
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

impl AvoidParams {
    /// Whether an obstacle at `dist` counts.
    pub fn in_range(&self, dist: f32) -> bool {
        self.range.is_none_or(|r| dist <= r)
    }

    /// The factor of the dynamic threshold `M_min` for a vision cone of this half-angle:
    /// `m_min_factor` when set, else `1 − cos(half_angle)` (seed 000 §4.2 integrates
    /// `d cos θ` from `−half_angle` to 0; for its ±150° view that is `1 + √3/2`).
    pub fn dynamic_m_min_factor(&self, vision_half_angle: f32) -> f32 {
        self.m_min_factor
            .unwrap_or_else(|| 1.0 - crate::math::cos(vision_half_angle))
    }
}

/// Dynamic `M_min = −factor·cos α/(v_r + m0)`, written with `neg_cos = −cos α` (seed 000 §4.2).
pub fn dynamic_m_min(factor: f32, neg_cos: f32, vision_radius: f32, m0: f32) -> f32 {
    factor * neg_cos / (vision_radius + m0)
}

/// Dynamic `M_max = S_f/((V_max + V_min)·Δt + m0)`, `V_max`/`V_min` the fastest and slowest
/// obstacle speeds (seed 000 §4.2).
pub fn dynamic_m_max(fish_size: f32, v_fast: f32, v_slow: f32, dt: f32, m0: f32) -> f32 {
    fish_size / ((v_fast + v_slow) * dt + m0)
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
/// `≤ M_min`). Speed: `brake·Vc` (the paper's `Vc/2`) when any pressure exceeds `M_max`, else
/// `Vc`; never below
/// `brake_floor·V_max`, so that a body next to an obstacle keeps the speed to leave it (the paper
/// halves the speed every step, which a field that stays above `M_max` turns into a standstill).
/// With the front-half field an obstacle level with the heading does not make the body pitch:
/// it turns, rather than climbing toward the pitch limit.
pub fn avoid_static(
    kin: &Kinematics,
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
        kin.speed * params.brake
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
/// dangerous). `M_min = −factor·cos α/(v_r + m0)` with α of the nearest obstacle and `factor`
/// from [`AvoidParams::dynamic_m_min_factor`] for a vision cone of `vision_half_angle` (the
/// paper's `1 + √3/2` for ±150°), `M_max = S_f/((V_max + V_min)·Δt + m0)` with `V_max`/`V_min`
/// the fastest/slowest obstacle speeds (a negative `M_min`, traffic moving away, is raised to 0).
/// Speed: `Vc` when all pressures `≤ M_min` (then the result is [`Steer::None`]), `0` when any
/// exceeds `M_max`, else `V_min`.
pub fn avoid_dynamic(
    kin: &Kinematics,
    obstacles: &[MovingObstacle],
    vision_radius: f32,
    vision_half_angle: f32,
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
    let factor = params.dynamic_m_min_factor(vision_half_angle);
    let m_min = dynamic_m_min(factor, neg_cos, vision_radius, params.m0);
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
    let m_max = dynamic_m_max(fish_size, v_fast, v_slow, dt, params.m0);
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

/// Collision prediction (seed 001): tests every obstacle's bounding sphere, its radius grown by
/// `margin`, against the path `speed·horizon` ahead and, for the nearest predicted hit, steers
/// sideways away from it (away from `b`; straight ahead hits turn to the left). `obstacles`
/// yields `(centre, radius)`.
pub fn predict_collision(
    kin: &Kinematics,
    obstacles: impl IntoIterator<Item = (Vec3, f32)>,
    horizon: f32,
    margin: f32,
    max_speed: f32,
) -> Steer {
    let fwd = kin.forward();
    let look = fwd * kin.speed.max(0.1 * max_speed) * horizon;
    let mut best: Option<(f32, Vec3)> = None;
    for (c, r) in obstacles {
        if let Some(b) = path_test(kin.pos, look, c, r + margin) {
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
pub fn contain(
    kin: &Kinematics,
    bounds: &Aabb,
    margin: f32,
    horizon: f32,
    max_speed: f32,
) -> Steer {
    contain_facing(kin, kin.forward(), bounds, margin, horizon, max_speed)
}

/// [`contain`] for a body whose forward vector (`kin.forward()`) is already known.
pub fn contain_facing(
    kin: &Kinematics,
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

/// The agent's percepts as avoidance inputs.
impl Ctx<'_> {
    /// Seen static obstacles within `params.range` as pressure sources.
    pub fn static_sources<'p>(
        &'p self,
        params: &'p AvoidParams,
    ) -> impl Iterator<Item = PressureSource> + 'p {
        self.percepts
            .iter()
            .filter(move |p| {
                p.category() == Category::Obstacle
                    && p.sense() == Sense::Vision
                    && params.in_range(p.dist)
            })
            .map(|p| PressureSource {
                dist: p.dist,
                bearing: p.bearing,
                elevation: p.elevation,
                size: p.size,
                weight: 1.0,
            })
    }
    /// The static-obstacle field of the seen obstacles within `params.range`: the front-half
    /// field, or the paper's plane-angle field when `params.paper_field`.
    pub fn static_pressures(&self, params: &AvoidParams) -> Pressures {
        if params.paper_field {
            return pressures(self.static_sources(params), params.m0);
        }
        let (yaw, pitch) = (self.agent.yaw, self.agent.pitch);
        let seen = self.percepts.iter().filter(|p| {
            p.category() == Category::Obstacle
                && p.sense() == Sense::Vision
                && params.in_range(p.dist)
        });
        front_pressures(
            seen.map(|p| FrontSource::new(p.offset, p.dist, p.size, yaw, pitch)),
            params.m0,
        )
    }
    /// Seen agents within `params.range` as moving obstacles (seed 000 §4.2: the whole ±150°
    /// field counts); kin only when `params.kin`.
    pub fn moving_obstacles(&self, params: &AvoidParams, out: &mut Vec<MovingObstacle>) {
        out.clear();
        for p in self.percepts {
            let kin = matches!(p.category(), Category::Kin | Category::Mate);
            if kin && !params.kin || !params.in_range(p.dist) {
                continue;
            }
            if let (Source::Agent(j), Sense::Vision) = (p.source(), p.sense()) {
                let j = j as usize;
                let (Some(radius), Some(velocity)) =
                    (self.perception.radius(j), self.perception.velocity(j))
                else {
                    continue;
                };
                out.push(MovingObstacle {
                    source: PressureSource {
                        dist: (p.dist - radius - self.agent.radius()).max(0.0),
                        bearing: p.bearing,
                        elevation: p.elevation,
                        size: p.size,
                        weight: 1.0,
                    },
                    velocity,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_3, FRAC_PI_4, FRAC_PI_6, FRAC_PI_8, PI};

    /// The paper's ±150° view.
    const VIEW_150: f32 = 5.0 * FRAC_PI_6;

    fn kin(speed: f32) -> Kinematics {
        Kinematics {
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
        let (s, c) = crate::math::sin_cos(FRAC_PI_3);
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
        let s = avoid_dynamic(
            &kin(1.0),
            &[o],
            10.0,
            VIEW_150,
            0.5,
            0.1,
            &AvoidParams::default(),
        );
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
        let s = avoid_dynamic(
            &kin(1.0),
            &[o],
            10.0,
            VIEW_150,
            0.5,
            0.1,
            &AvoidParams::default(),
        );
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
        let s = predict_collision(&kin(1.0), [(Vec3::new(0.3, 0.0, 3.0), 1.0)], 5.0, 0.0, 1.0);
        let Steer::Velocity(v) = s else { panic!() };
        assert!(v.x < 0.0 && v.z > 0.0);
    }

    #[test]
    fn static_thresholds_hand_computed() {
        // M_min = 1/(v_r + m0) = 1/(6 + 2) = 0.125.
        assert_eq!(static_m_min(6.0, 2.0), 0.125);
        // M_max = S_f/(V_max·Δt + m0) = 3/(4·0.5 + 1) = 1.
        assert_eq!(static_m_max(3.0, 4.0, 0.5, 1.0), 1.0);
        // 2/(3·0.25 + 0.5) = 2/1.25 = 1.6.
        assert!((static_m_max(2.0, 3.0, 0.25, 0.5) - 1.6).abs() < 1e-6);
    }

    #[test]
    fn dynamic_thresholds_hand_computed() {
        // M_min = factor·(−cos α)/(v_r + m0) = 2·0.5/(3 + 1) = 0.25.
        assert_eq!(dynamic_m_min(2.0, 0.5, 3.0, 1.0), 0.25);
        // Paper: (1 + √3/2)·1/(10 + 1) = 0.169638.
        assert!((dynamic_m_min(PAPER_M_MIN_FACTOR, 1.0, 10.0, 1.0) - 0.169_638_7).abs() < 1e-6);
        // M_max = S_f/((V_max + V_min)·Δt + m0) = 0.5/((3 + 1)·0.1 + 1) = 0.5/1.4 = 0.357143.
        assert!((dynamic_m_max(0.5, 3.0, 1.0, 0.1, 1.0) - 0.357_142_87).abs() < 1e-6);
        // 3/((2 + 0.5)·2 + 1) = 3/6 = 0.5.
        assert_eq!(dynamic_m_max(3.0, 2.0, 0.5, 2.0, 1.0), 0.5);
    }

    #[test]
    fn dynamic_m_min_factor_is_one_minus_cos_of_the_view() {
        let p = AvoidParams::default();
        // 1 − cos 150° = 1 + √3/2 = 1.866025.
        assert!((p.dynamic_m_min_factor(VIEW_150) - PAPER_M_MIN_FACTOR).abs() < 1e-6);
        assert!((PAPER_M_MIN_FACTOR - (1.0 + 3f32.sqrt() / 2.0)).abs() < 1e-7);
        // 1 − cos 90° = 1; 1 − cos 180° = 2; 1 − cos 60° = 0.5.
        assert!((p.dynamic_m_min_factor(FRAC_PI_2) - 1.0).abs() < 1e-6);
        assert!((p.dynamic_m_min_factor(PI) - 2.0).abs() < 1e-6);
        assert!((p.dynamic_m_min_factor(FRAC_PI_3) - 0.5).abs() < 1e-6);
        // The paper's fixed constant whatever the view.
        let fixed = AvoidParams {
            m_min_factor: Some(PAPER_M_MIN_FACTOR),
            ..p
        };
        assert_eq!(fixed.dynamic_m_min_factor(FRAC_PI_2), PAPER_M_MIN_FACTOR);
    }

    /// A head-on obstacle (velocity −Z against the fish's +Z) at θ = +π/3, level, size 2.
    fn head_on(dist: f32, speed: f32) -> MovingObstacle {
        MovingObstacle {
            source: src(dist, FRAC_PI_3, 0.0, 2.0),
            velocity: -Vec3::Z * speed,
        }
    }

    #[test]
    fn avoid_dynamic_m_min_brackets_the_pressure() {
        // v_r = 10, m0 = 1, −cos α = 1. With S = 2 at θ = π/3, level: R = 2·cos(π/3)/(d + 1)
        // = 1/(d + 1), U = D = ½·2·1/(d + 1) = 1/(d + 1); the largest is 1/(d + 1).
        // 150° view: M_min = 1.866/11 = 0.16964.
        let p = AvoidParams::default();
        let k = kin(1.0);
        // d = 5: 1/6 = 0.16667 ≤ 0.16964 → done.
        assert_eq!(
            avoid_dynamic(&k, &[head_on(5.0, 1.0)], 10.0, VIEW_150, 0.5, 0.1, &p),
            Steer::None
        );
        // d = 4.5: 1/5.5 = 0.18182 > M_min → avoid.
        assert!(!avoid_dynamic(&k, &[head_on(4.5, 1.0)], 10.0, VIEW_150, 0.5, 0.1, &p).is_none());
        // A 90° view: factor 1 − cos 90° = 1, M_min = 1/11 = 0.0909 < 0.16667 → avoid at d = 5.
        assert!(!avoid_dynamic(&k, &[head_on(5.0, 1.0)], 10.0, FRAC_PI_2, 0.5, 0.1, &p).is_none());
        // ... unless the paper's fixed constant is asked for.
        let fixed = AvoidParams {
            m_min_factor: Some(PAPER_M_MIN_FACTOR),
            ..p
        };
        assert_eq!(
            avoid_dynamic(&k, &[head_on(5.0, 1.0)], 10.0, FRAC_PI_2, 0.5, 0.1, &fixed),
            Steer::None
        );
    }

    #[test]
    fn avoid_dynamic_speed_branches_follow_m_max_and_the_slowest_obstacle() {
        // Two obstacles: the nearest head-on at speed 1 (V_min), a farther one crossing at speed
        // 3 (V_max; −cos α = 0, so it adds no pressure). S_f = 0.5, Δt = 0.1, m0 = 1:
        // M_max = 0.5/((3 + 1)·0.1 + 1) = 0.357143; M_min = 1.866/11 = 0.16964.
        let cross = MovingObstacle {
            source: src(8.0, -FRAC_PI_4, 0.0, 2.0),
            velocity: Vec3::X * 3.0,
        };
        let p = AvoidParams::default();
        let k = kin(1.0);
        // d = 1.7: pressure 1/2.7 = 0.37037 > M_max → stop (V = 0). L = 0 < R → left; U = D
        // = 0.37 > M_min, equal → up.
        let s = avoid_dynamic(
            &k,
            &[head_on(1.7, 1.0), cross],
            10.0,
            VIEW_150,
            0.5,
            0.1,
            &p,
        );
        assert_eq!(
            s,
            Steer::Turn {
                yaw: -FRAC_PI_8,
                pitch: FRAC_PI_8,
                speed: 0.0
            }
        );
        // d = 2: 1/3 = 0.33333, between M_min and M_max → V_min = 1 (the slowest obstacle's
        // speed, not the fastest's 3 nor the fish's 1.5). U = D = 0.333 > M_min → up.
        let s = avoid_dynamic(
            &kin(1.5),
            &[head_on(2.0, 1.0), cross],
            10.0,
            VIEW_150,
            0.5,
            0.1,
            &p,
        );
        assert_eq!(
            s,
            Steer::Turn {
                yaw: -FRAC_PI_8,
                pitch: FRAC_PI_8,
                speed: 1.0
            }
        );
        // A pressure equal to M_max is not above it: d = 1 gives U = D = ½·2/2 = 0.5 (R =
        // cos(π/3) ≤ 0.5); S_f = 1, Δt = 0.5, one obstacle at speed 1: M_max = 1/((1 + 1)·0.5
        // + 1) = 0.5 → V_min = 1, not 0.
        let s = avoid_dynamic(&k, &[head_on(1.0, 1.0)], 10.0, VIEW_150, 1.0, 0.5, &p);
        assert_eq!(
            s,
            Steer::Turn {
                yaw: -FRAC_PI_8,
                pitch: FRAC_PI_8,
                speed: 1.0
            }
        );
        // With only the slow obstacle, M_max = 0.5/((1 + 1)·0.1 + 1) = 0.41667 > 0.37037: the
        // fast one's speed is what made d = 1.7 a stop.
        let s = avoid_dynamic(&k, &[head_on(1.7, 1.0)], 10.0, VIEW_150, 0.5, 0.1, &p);
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
    fn avoid_dynamic_sums_a_crowd_and_takes_m_min_from_the_nearest() {
        // Three predators coming head-on (−cos α = 1), S = 2, m0 = 1, v_r = 10:
        // A at d = 3, θ = −π/3 (left), ω = +π/4 (above): L += 2·0.5/4 = 0.25, U += 2·0.7071/4
        // = 0.35355; B at d = 7, θ = −π/6 (left), level: L += 2·0.8660/8 = 0.21651, U, D +=
        // ½·2/8 = 0.125; C at d = 1, θ = +π/2 (right), level: R += 2·cos(π/2)/2 = 0, U, D += ½·2/2
        // = 0.5. L = 0.46651 > R = 0 → turn right; U = 0.97855 > D = 0.625 → pitch down.
        let m = |dist, bearing, elevation| MovingObstacle {
            source: src(dist, bearing, elevation, 2.0),
            velocity: -Vec3::Z,
        };
        let crowd = [
            m(3.0, -FRAC_PI_3, FRAC_PI_4),
            m(7.0, -FRAC_PI_6, 0.0),
            m(1.0, FRAC_PI_2, 0.0),
        ];
        let weighted = crowd.iter().map(|o| o.source);
        let p = pressures(weighted, 1.0);
        assert!((p.left - 0.466_506_3).abs() < 1e-5, "{p:?}");
        assert!(p.right.abs() < 1e-6);
        assert!((p.up - 0.978_553_4).abs() < 1e-5 && (p.down - 0.625).abs() < 1e-6);
        // Largest 0.9786 > M_max = 0.5/(2·0.1 + 1) = 0.41667 → stop.
        let s = avoid_dynamic(
            &kin(1.0),
            &crowd,
            10.0,
            VIEW_150,
            0.5,
            0.1,
            &AvoidParams::default(),
        );
        assert_eq!(
            s,
            Steer::Turn {
                yaw: FRAC_PI_8,
                pitch: -FRAC_PI_8,
                speed: 0.0
            }
        );
        // The nearest moving away (same direction, −cos α = −1) sets M_min < 0, raised to 0:
        // every positive pressure counts. Its own term is negative on the right.
        let mut away = crowd;
        away[2].velocity = Vec3::Z;
        let s = avoid_dynamic(
            &kin(1.0),
            &away,
            10.0,
            VIEW_150,
            0.5,
            0.1,
            &AvoidParams::default(),
        );
        let Steer::Turn { yaw, .. } = s else {
            panic!("{s:?}")
        };
        assert_eq!(yaw, FRAC_PI_8);
    }

    #[test]
    fn avoid_static_speed_branches() {
        // Obstacle on the right at θ = π/3, level, S = 2, m0 = 1; v_r = 10 (M_min = 0.0909);
        // S_f = 0.5, V_max = 2, Δt = 0.1 (M_max = 0.41667). Paper field: R = U = D = 1/(d + 1).
        let run = |d: f32, vc: f32, p: &AvoidParams| {
            avoid_static(
                &kin(vc),
                pressures([src(d, FRAC_PI_3, 0.0, 2.0)], p.m0),
                10.0,
                0.5,
                2.0,
                0.1,
                p,
            )
        };
        let speed = |s: Steer| match s {
            Steer::Turn { speed, .. } => speed,
            _ => panic!("{s:?}"),
        };
        // d = 1: 0.5 > M_max → brake·Vc = 0.5·1.6 = 0.8.
        assert_eq!(speed(run(1.0, 1.6, &paper())), 0.8);
        // A braking factor of 0.25: 0.4.
        let quarter = AvoidParams {
            brake: 0.25,
            ..paper()
        };
        assert_eq!(speed(run(1.0, 1.6, &quarter)), 0.4);
        // d = 2: 1/3 ≤ M_max → Vc.
        assert_eq!(speed(run(2.0, 1.6, &quarter)), 1.6);
        // A pressure equal to M_max is not above it: d = 1 gives U = D = ½·2/2 = 0.5, and
        // S_f = 1, V_max = 2, Δt = 0.5 give M_max = 1/(2·0.5 + 1) = 0.5 → Vc.
        let s = avoid_static(
            &kin(1.6),
            pressures([src(1.0, FRAC_PI_3, 0.0, 2.0)], 1.0),
            10.0,
            1.0,
            2.0,
            0.5,
            &paper(),
        );
        assert_eq!(speed(s), 1.6);
        // d = 10: 1/11 = M_min exactly → done.
        assert_eq!(run(10.0, 1.6, &paper()), Steer::None);
        // d = 9: 0.1 > M_min → turn left and up (U = D), speed Vc.
        assert_eq!(
            run(9.0, 1.6, &paper()),
            Steer::Turn {
                yaw: -FRAC_PI_8,
                pitch: FRAC_PI_8,
                speed: 1.6
            }
        );
    }

    #[test]
    fn obstacles_behind_and_straight_above_do_not_make_a_body_avoid() {
        // Front-half field (the default): a rock straight above (0.3 away), one straight below
        // and one behind give no pressure, so avoid_static is done at once.
        let rocks = [
            front(0.3, Vec3::Y, 4.0),
            front(0.3, -Vec3::Y, 4.0),
            front(0.3, -Vec3::Z, 4.0),
            front(0.3, Vec3::new(0.5, 0.0, -1.0), 4.0),
        ];
        let p = front_pressures(rocks, 1.0);
        assert_eq!(
            avoid_static(&kin(1.0), p, 10.0, 0.5, 2.0, 0.1, &AvoidParams::default()),
            Steer::None
        );
        // Adding a rock ahead-right (d = 3, S = 2, forward component cos(π/3)) gives only its
        // own terms: R = 2·0.5/4 = 0.25, U = D = 0.125 (level, half each).
        let (sn, cs) = crate::math::sin_cos(FRAC_PI_3);
        let more = rocks
            .iter()
            .copied()
            .chain([front(3.0, Vec3::new(sn, 0.0, cs), 2.0)]);
        let p = front_pressures(more, 1.0);
        assert!((p.right - 0.25).abs() < 1e-6 && p.left == 0.0, "{p:?}");
        assert!((p.up - 0.125).abs() < 1e-6 && (p.down - 0.125).abs() < 1e-6);
        // Paper's plane-angle field: a rock behind on the right (θ = 5π/6, level, d = 1, S = 2)
        // gives R = 2·cos(5π/6)/2 = −0.866 and U = D = ½·2·1/2 = 0.5. L = 0 and R < 0 are both
        // ≤ M_min → keep the heading; U = D > M_min → up. Straight above (θ = 0, ω = π/2):
        // L = R = ½·2/2 = 0.5, U = 2·cos(π/2)/2 ≈ 0 → left by the tie rule, no pitch.
        let p = pressures([src(1.0, 5.0 * FRAC_PI_6, 0.0, 2.0)], 1.0);
        assert!((p.right + 0.866_025_4).abs() < 1e-6 && (p.up - 0.5).abs() < 1e-6);
        let s = avoid_static(&kin(1.0), p, 10.0, 0.5, 2.0, 0.1, &paper());
        let Steer::Turn { yaw, pitch, .. } = s else {
            panic!("{s:?}")
        };
        assert_eq!((yaw, pitch), (0.0, FRAC_PI_8));
        let p = pressures([src(1.0, 0.0, FRAC_PI_2, 2.0)], 1.0);
        assert!((p.left - 0.5).abs() < 1e-6 && (p.right - 0.5).abs() < 1e-6);
        assert!(p.up.abs() < 1e-6 && p.down == 0.0);
        let s = avoid_static(&kin(1.0), p, 10.0, 0.5, 2.0, 0.1, &paper());
        let Steer::Turn { yaw, pitch, .. } = s else {
            panic!("{s:?}")
        };
        assert_eq!((yaw, pitch), (-FRAC_PI_8, 0.0));
    }

    #[test]
    fn predicted_collision_uses_the_margin() {
        // Obstacle 3 ahead, 1.5 to the left (+X), radius 1; look-ahead 1·5 = 5: b = (1.5, 0, 0).
        // |b| = 1.5 > 1 → no hit without a margin; with margin 0.6 the radius is 1.6 > 1.5 → hit,
        // steer away from b: (fwd + (−1, 0, 0)) normalized at speed 1 = (−0.7071, 0, 0.7071).
        let o = [(Vec3::new(1.5, 0.0, 3.0), 1.0)];
        assert_eq!(predict_collision(&kin(1.0), o, 5.0, 0.0, 1.0), Steer::None);
        assert_eq!(predict_collision(&kin(1.0), o, 5.0, 0.4, 1.0), Steer::None);
        let Steer::Velocity(v) = predict_collision(&kin(1.0), o, 5.0, 0.6, 1.0) else {
            panic!()
        };
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert!((v - Vec3::new(-h, 0.0, h)).length() < 1e-6, "{v}");
        // Of two predicted hits the nearer one decides: one on the right (−X) at 2 ahead, one on
        // the left at 4 ahead → steer left (+X), at the body's speed 1 (above the floor
        // 0.1·V_max = 0.2).
        let two = [
            (Vec3::new(1.0, 0.0, 4.0), 1.5),
            (Vec3::new(-0.5, 0.0, 2.0), 1.0),
        ];
        let Steer::Velocity(v) = predict_collision(&kin(1.0), two, 5.0, 0.0, 2.0) else {
            panic!()
        };
        assert!((v - Vec3::new(h, 0.0, h)).length() < 1e-6, "{v}");
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

    #[test]
    fn pressures_split_a_source_dead_ahead_and_level() {
        // S = 2, d = 3, m0 = 1, θ = ω = 0: each term 2·cos 0/4 = 0.5, half to each side.
        let p = pressures([src(3.0, 0.0, 0.0, 2.0)], 1.0);
        let quarter = Pressures {
            left: 0.25,
            right: 0.25,
            up: 0.25,
            down: 0.25,
        };
        assert_eq!(p, quarter);
    }

    #[test]
    fn front_field_sides_and_the_on_line_band() {
        // S = 2, forward = 0.5, d = 3, m0 = 1: t = 2·0.5/4 = 0.25.
        let fs = |right: f32, up: f32| FrontSource {
            dist: 3.0,
            size: 2.0,
            forward: 0.5,
            right,
            up,
        };
        let p = |left, right, up, down| Pressures {
            left,
            right,
            up,
            down,
        };
        assert_eq!(
            front_pressures([fs(-0.5, -0.5)], 1.0),
            p(0.25, 0.0, 0.0, 0.25)
        );
        assert_eq!(
            front_pressures([fs(0.5, 0.5)], 1.0),
            p(0.0, 0.25, 0.25, 0.0)
        );
        // Two on the left and below add up.
        let two = front_pressures([fs(-0.5, -0.5), fs(-0.5, -0.5)], 1.0);
        assert_eq!(two, p(0.5, 0.0, 0.0, 0.5));
        // Exactly ±1e-4 off the line is on it: half of t to each side.
        for e in [1e-4, -1e-4] {
            assert_eq!(
                front_pressures([fs(e, e)], 1.0),
                p(0.125, 0.125, 0.125, 0.125)
            );
        }
    }

    #[test]
    fn range_counts_up_to_its_limit() {
        assert!(AvoidParams::default().in_range(1e9));
        let p = AvoidParams {
            range: Some(5.0),
            ..AvoidParams::default()
        };
        assert!(p.in_range(5.0));
        assert!(!p.in_range(5.1));
    }

    #[test]
    fn front_field_pitches_when_up_and_down_differ() {
        // v_r = 999, m0 = 1: M_min = 0.001. U = 0.02, D = 0.015: |U − D| = 0.005 > 1e-3·0.02,
        // so not level: U > D → pitch −π/8; R > L → yaw −π/8.
        let p = Pressures {
            left: 0.0,
            right: 0.02,
            up: 0.02,
            down: 0.015,
        };
        let s = avoid_static(&kin(2.0), p, 999.0, 0.5, 2.0, 0.1, &AvoidParams::default());
        let Steer::Turn { yaw, pitch, .. } = s else {
            panic!("{s:?}")
        };
        assert_eq!((yaw, pitch), (-FRAC_PI_8, -FRAC_PI_8));
    }

    #[test]
    fn path_test_from_an_offset_position_and_at_its_edges() {
        // From (1, 2, 3) along (0, 0, 10), centre (1.5, 2, 8): a = (0.5, 0, 5), t = 50/100 = 0.5,
        // p = (0, 0, 5), b = (0.5, 0, 0), |b| < 1 → a hit 0.5 to the side.
        let hit = path_test(
            Vec3::new(1.0, 2.0, 3.0),
            10.0 * Vec3::Z,
            Vec3::new(1.5, 2.0, 8.0),
            1.0,
        );
        assert_eq!(hit, Some(Vec3::new(0.5, 0.0, 0.0)));
        // Centre exactly at the tip: |p| = |v|, not strictly inside the path.
        assert_eq!(
            path_test(Vec3::ZERO, 10.0 * Vec3::Z, 10.0 * Vec3::Z, 1.0),
            None
        );
        // Grazing: |b| = 1 = r is not inside either.
        let graze = Vec3::new(1.0, 0.0, 5.0);
        assert_eq!(path_test(Vec3::ZERO, 10.0 * Vec3::Z, graze, 1.0), None);
        // A look-ahead with |v|² = 1e-14 ≤ 1e-12 tests nothing, even with the centre on it.
        let tiny = Vec3::new(0.0, 0.0, 1e-7);
        assert_eq!(path_test(Vec3::ZERO, tiny, 0.5 * tiny, 1.0), None);
    }

    #[test]
    fn predicted_collision_look_ahead_speed_and_ties() {
        // Vc = 0.5 below 0.1·V_max = 2: the look-ahead is 2·5 = 10 along +Z and the command's
        // speed is 2. Hit at z = 9, b = (0.5, 0, 0) → (fwd − X)/√2·2 = (−√2, 0, √2).
        let hit = |obstacles: &[(Vec3, f32)]| {
            predict_collision(&kin(0.5), obstacles.iter().copied(), 5.0, 0.0, 20.0)
        };
        let Steer::Velocity(v) = hit(&[(Vec3::new(0.5, 0.0, 9.0), 1.0)]) else {
            panic!()
        };
        let r2 = 2f32.sqrt();
        assert!((v - Vec3::new(-r2, 0.0, r2)).length() < 1e-5, "{v}");
        // Beyond the look-ahead: nothing.
        assert_eq!(hit(&[(Vec3::new(0.5, 0.0, 11.0), 1.0)]), Steer::None);
        // Two hits equally far ahead: the first listed wins, here on the right → turn left.
        let Steer::Velocity(v) = hit(&[
            (Vec3::new(-0.5, 0.0, 5.0), 1.0),
            (Vec3::new(0.5, 0.0, 5.0), 1.0),
        ]) else {
            panic!()
        };
        assert!((v - Vec3::new(r2, 0.0, r2)).length() < 1e-5, "{v}");
    }
}
