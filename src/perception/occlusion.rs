//! Occlusion (seed 001: "an object is visible if any part is in the field and it is not fully
//! occluded", with bounding spheres as occluders).
//!
//! **Departure, on purpose:** by default an obstacle occludes with its real shape (sphere, box,
//! upright cylinder), not with its bounding sphere. A long flat box occludes, as its bounding
//! sphere, a large volume of open water above it: a reef fish beside a 12 × 2 × 6 box (bounding
//! radius 6.8) could not see a shark in plain view 3 above it. `senses.occluders:
//! BoundingSphere` restores the paper's form ([`Occluders::BoundingSphere`]).
//!
//! **Partial occlusion** (the paper's "not fully occluded"): a target is hidden only when the
//! segment from the eye to its centre and the segments to four points of its outline are all
//! blocked. The four points lie on the target's bounding sphere, across the line of sight, at
//! both ends of two perpendicular diameters of its outline as the eye sees it.
//! Why this test: the centre's segment is tested first, one segment-against-shape test per
//! occluder as before; the four others run only for a target whose centre is hidden, which is
//! rare, so the common case costs no more than a centre-only test. A target that shows only a
//! sliver between two occluders, narrower than its radius, may still be counted hidden.
//!
//! A segment is blocked by a solid when it leaves the solid strictly between its ends: a target
//! touching or inside the solid (food on a rock) is not hidden by that solid, and an eye inside
//! a solid sees nothing beyond it.

use crate::world::Shape;
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// What an obstacle occludes with.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Occluders {
    /// The obstacle's own shape (the engine's default).
    #[default]
    Shape,
    /// Its bounding sphere (seed 001's form).
    BoundingSphere,
}

/// The solid that `shape` occludes with under `form`.
#[inline]
pub fn occluder(shape: &Shape, form: Occluders) -> Shape {
    match form {
        Occluders::Shape => *shape,
        Occluders::BoundingSphere => Shape::Sphere {
            center: shape.center(),
            radius: shape.bounding_radius(),
        },
    }
}

/// The range `[t0, t1]` of `t` where the line `from + t·seg` is inside `shape` (`None` when it
/// misses it, touches it or `seg` is zero and `from` is outside).
#[inline]
pub fn span(shape: &Shape, from: Vec3, seg: Vec3) -> Option<(f32, f32)> {
    match *shape {
        Shape::Sphere { center, radius } => {
            // |d + t·seg|² = r²: a·t² + 2b·t + c = 0.
            let d = from - center;
            let a = seg.length_squared();
            let b = d.dot(seg);
            let c = d.length_squared() - radius * radius;
            roots(a, b, c)
        }
        Shape::Box(bx) => {
            let mut t = (f32::NEG_INFINITY, f32::INFINITY);
            for axis in 0..3 {
                t = slab(t, from[axis], seg[axis], bx.min[axis], bx.max[axis])?;
            }
            Some(t)
        }
        Shape::Cylinder {
            base,
            radius,
            height,
        } => {
            let t = (f32::NEG_INFINITY, f32::INFINITY);
            let t = slab(t, from.y, seg.y, base.y, base.y + height)?;
            // The disc in the horizontal plane.
            let (dx, dz) = (from.x - base.x, from.z - base.z);
            let a = seg.x * seg.x + seg.z * seg.z;
            let b = dx * seg.x + dz * seg.z;
            let c = dx * dx + dz * dz - radius * radius;
            let (r0, r1) = roots(a, b, c)?;
            Some((t.0.max(r0), t.1.min(r1)))
        }
    }
}

/// `t` where `a·t² + 2b·t + c < 0` (`a ≥ 0`): the whole line when `a` is zero and `c < 0`.
#[inline]
fn roots(a: f32, b: f32, c: f32) -> Option<(f32, f32)> {
    if a <= 0.0 {
        return (c < 0.0).then_some((f32::NEG_INFINITY, f32::INFINITY));
    }
    let disc = b * b - a * c;
    if disc <= 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    Some(((-b - sq) / a, (-b + sq) / a))
}

/// `t` narrowed to where `o + t·s` lies strictly between `lo` and `hi`.
#[inline]
fn slab(t: (f32, f32), o: f32, s: f32, lo: f32, hi: f32) -> Option<(f32, f32)> {
    if s == 0.0 {
        return (o > lo && o < hi).then_some(t);
    }
    let (a, b) = ((lo - o) / s, (hi - o) / s);
    let (a, b) = if a < b { (a, b) } else { (b, a) };
    Some((t.0.max(a), t.1.min(b)))
}

/// Whether `shape` blocks the segment from `from` to `from + seg`: the segment leaves the solid
/// strictly between its ends.
#[inline]
pub fn blocks(shape: &Shape, from: Vec3, seg: Vec3) -> bool {
    span(shape, from, seg).is_some_and(|(t0, t1)| t0 < t1 && t1 > 0.0 && t1 < 1.0)
}

/// Whether a target at `offset` from the eye at `from`, of bounding radius `radius()` (asked
/// only when its centre is hidden), is fully occluded by `occluders`: its centre and the four
/// extremes of its outline are all behind some occluder.
#[inline]
pub fn hidden(from: Vec3, offset: Vec3, radius: impl FnOnce() -> f32, occluders: &[Shape]) -> bool {
    let blocked = |seg: Vec3| occluders.iter().any(|s| blocks(s, from, seg));
    if !blocked(offset) {
        return false;
    }
    let r = radius();
    let Some(dir) = offset.try_normalize() else {
        return true;
    };
    if r.is_nan() || r <= 0.0 {
        return true;
    }
    let (a, b) = dir.any_orthonormal_pair();
    [a, -a, b, -b].into_iter().all(|e| blocked(offset + e * r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::Aabb;

    #[test]
    fn spans_of_a_sphere_a_box_and_a_cylinder() {
        // Sphere of radius 1 at z = 4, line along +z from the origin with seg = (0, 0, 8):
        // inside for z in (3, 5), t = 3/8 .. 5/8.
        let s = Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 4.0),
            radius: 1.0,
        };
        assert_eq!(
            span(&s, Vec3::ZERO, Vec3::new(0.0, 0.0, 8.0)),
            Some((0.375, 0.625))
        );
        // Offset by 0.6 sideways: the chord's half-length is √(1 − 0.36) = 0.8: z in 3.2 .. 4.8,
        // t = 0.4 .. 0.6.
        let (t0, t1) = span(&s, Vec3::new(0.6, 0.0, 0.0), Vec3::new(0.0, 0.0, 8.0)).unwrap();
        assert!(
            (t0 - 0.4).abs() < 1e-6 && (t1 - 0.6).abs() < 1e-6,
            "{t0} {t1}"
        );
        // Passing 1.5 to the side: no span; grazing at exactly 1: none either.
        assert_eq!(span(&s, Vec3::new(1.5, 0.0, 0.0), Vec3::Z), None);
        assert_eq!(span(&s, Vec3::new(1.0, 0.0, 0.0), Vec3::Z), None);
        // A zero segment: the whole line inside when the eye is inside, else none.
        assert_eq!(
            span(&s, Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO),
            Some((f32::NEG_INFINITY, f32::INFINITY))
        );
        assert_eq!(span(&s, Vec3::ZERO, Vec3::ZERO), None);

        // Box x 2..4, y −1..1, z −1..1; line from the origin along (8, 2, 0): x enters at
        // t = 2/8 and leaves at 4/8; y = 2t stays below 1 until t = 1/2: (0.25, 0.5).
        let b = Shape::Box(Aabb::new(
            Vec3::new(2.0, -1.0, -1.0),
            Vec3::new(4.0, 1.0, 1.0),
        ));
        assert_eq!(
            span(&b, Vec3::ZERO, Vec3::new(8.0, 2.0, 0.0)),
            Some((0.25, 0.5))
        );
        // Climbing faster, (8, 8, 0): y leaves at t = 1/8 before x enters at 2/8: empty.
        let (t0, t1) = span(&b, Vec3::ZERO, Vec3::new(8.0, 8.0, 0.0)).unwrap();
        assert!(t0 >= t1, "{t0} {t1}");
        // Parallel to a face, inside its slab / on its plane / outside: x only decides.
        assert_eq!(
            span(&b, Vec3::ZERO, Vec3::new(8.0, 0.0, 0.0)),
            Some((0.25, 0.5))
        );
        assert_eq!(span(&b, Vec3::new(0.0, 1.0, 0.0), Vec3::X), None);
        assert_eq!(span(&b, Vec3::new(0.0, -1.0, 0.0), Vec3::X), None);
        assert_eq!(span(&b, Vec3::new(0.0, 0.0, 1.5), Vec3::X), None);
        // Backwards along −x from (10, 0, 0) with seg (−10, 0, 0): x = 10 − 10t in 2..4 for
        // t in 0.6..0.8 (the slab's bounds swap).
        let (t0, t1) = span(&b, Vec3::new(10.0, 0.0, 0.0), Vec3::new(-10.0, 0.0, 0.0)).unwrap();
        assert!(
            (t0 - 0.6).abs() < 1e-6 && (t1 - 0.8).abs() < 1e-6,
            "{t0} {t1}"
        );

        // Cylinder: axis at (5, ·, 0), radius 1, y from 0 to 2. Level line at y = 1 from the
        // origin, seg (10, 0, 0): the disc spans x 4..6, t = 0.4..0.6.
        let c = Shape::Cylinder {
            base: Vec3::new(5.0, 0.0, 0.0),
            radius: 1.0,
            height: 2.0,
        };
        let (t0, t1) = span(&c, Vec3::new(0.0, 1.0, 0.0), Vec3::new(10.0, 0.0, 0.0)).unwrap();
        assert!(
            (t0 - 0.4).abs() < 1e-6 && (t1 - 0.6).abs() < 1e-6,
            "{t0} {t1}"
        );
        // Rising from y = 1 with seg (10, 2, 0): y = 1 + 2t leaves the top at t = 0.5, inside
        // the disc from 0.4: (0.4, 0.5).
        let (t0, t1) = span(&c, Vec3::new(0.0, 1.0, 0.0), Vec3::new(10.0, 2.0, 0.0)).unwrap();
        assert!(
            (t0 - 0.4).abs() < 1e-6 && (t1 - 0.5).abs() < 1e-6,
            "{t0} {t1}"
        );
        // Straight down the axis from y = 5, seg (0, −10, 0): the slab alone, y 2..0 for
        // t = 0.3..0.5.
        let (t0, t1) = span(&c, Vec3::new(5.0, 5.0, 0.0), Vec3::new(0.0, -10.0, 0.0)).unwrap();
        assert!(
            (t0 - 0.3).abs() < 1e-6 && (t1 - 0.5).abs() < 1e-6,
            "{t0} {t1}"
        );
        // Straight down beside it (1.5 from the axis): none.
        assert_eq!(
            span(&c, Vec3::new(6.5, 5.0, 0.0), Vec3::new(0.0, -10.0, 0.0)),
            None
        );
        // Straight down along its side (exactly 1 from the axis): touching is not entering.
        assert_eq!(
            span(&c, Vec3::new(6.0, 5.0, 0.0), Vec3::new(0.0, -10.0, 0.0)),
            None
        );
        // Above the top, level: none.
        assert_eq!(span(&c, Vec3::new(0.0, 3.0, 0.0), Vec3::X), None);
    }

    #[test]
    fn a_segment_is_blocked_only_when_it_leaves_the_solid_before_its_end() {
        let s = Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 4.0),
            radius: 1.0,
        };
        // Through it (exit at t = 5/8): blocked.
        assert!(blocks(&s, Vec3::ZERO, Vec3::new(0.0, 0.0, 8.0)));
        // Ending inside it (exit at t = 5/4.5 > 1) or on its far surface (exit at t = 1): not.
        assert!(!blocks(&s, Vec3::ZERO, Vec3::new(0.0, 0.0, 4.5)));
        assert!(!blocks(&s, Vec3::ZERO, Vec3::new(0.0, 0.0, 5.0)));
        // Ending before it (t from 3/2): not; the solid behind the eye (t −5/8..−3/8): not.
        assert!(!blocks(&s, Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0)));
        assert!(!blocks(&s, Vec3::ZERO, Vec3::new(0.0, 0.0, -8.0)));
        // An eye inside it looking out (t from −1/8 to 1/8): blocked.
        assert!(blocks(
            &s,
            Vec3::new(0.0, 0.0, 4.0),
            Vec3::new(0.0, 0.0, 8.0)
        ));
        // An eye on its far surface looking away (t from −1/4 to exactly 0): not blocked.
        assert!(!blocks(
            &s,
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(0.0, 0.0, 8.0)
        ));
        // Box x 2..4, y −1..1: a line that climbs over it (x enters at t = 1/4 after y leaves
        // at 1/8) and one through its edge (x enters and y leaves both at t = 1/4): not blocked.
        let b = Shape::Box(Aabb::new(
            Vec3::new(2.0, -1.0, -1.0),
            Vec3::new(4.0, 1.0, 1.0),
        ));
        assert!(!blocks(&b, Vec3::ZERO, Vec3::new(8.0, 8.0, 0.0)));
        assert!(!blocks(&b, Vec3::ZERO, Vec3::new(8.0, 4.0, 0.0)));
        assert!(blocks(&b, Vec3::ZERO, Vec3::new(8.0, 2.0, 0.0)));
    }

    #[test]
    fn a_target_is_hidden_only_when_its_centre_and_outline_are() {
        let from = Vec3::ZERO;
        // A rock of radius 2 at z = 5; a target of radius 0.5 at z = 10: the rim points are
        // 0.5 off the axis, their segments pass the rock's centre plane at 0.25 < 2: hidden.
        let rock = [Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 2.0,
        }];
        let far = Vec3::new(0.0, 0.0, 10.0);
        assert!(hidden(from, far, || 0.5, &rock));
        // A target of radius 6 at the same place sticks out: its rim points are 6 off the axis,
        // their segments pass the rock's centre at 5·6/√136 = 2.57 (> 2).
        assert!(!hidden(from, far, || 6.0, &rock));
        // A point target (radius 0) behind the rock: hidden; beside it: seen, and its radius
        // is not even asked.
        assert!(hidden(from, far, || 0.0, &rock));
        assert!(!hidden(
            from,
            Vec3::new(5.0, 0.0, 10.0),
            || panic!("asked"),
            &rock
        ));
        // A thin pole (radius 0.1) across the line of sight hides the centre only: each
        // rim point (1 off) clears it in one direction at least.
        let pole = [Shape::Cylinder {
            base: Vec3::new(0.0, -10.0, 5.0),
            radius: 0.1,
            height: 20.0,
        }];
        assert!(occluders_block_centre(&pole, far));
        assert!(!hidden(from, far, || 1.0, &pole));
        // No occluder: seen.
        assert!(!hidden(from, far, || 1.0, &[]));
        // A target of radius 3.9 there: its outline points' lines of sight pass the rock's
        // centre at 5·3.9/√(3.9² + 10²) = 1.82 (< 2): hidden. An undefined radius counts as a
        // point.
        assert!(hidden(from, far, || 3.9, &rock));
        assert!(hidden(from, far, || f32::NAN, &rock));
        // Seen from here along +z, the outline points lie along ±x and ±y. A slab covering the
        // centre and every side but −x (x from −0.2), then every side but −y: seen each time.
        let all_but = |lo: Vec3| {
            [Shape::Box(Aabb::new(
                Vec3::new(lo.x, lo.y, 4.0),
                Vec3::new(5.0, 5.0, 6.0),
            ))]
        };
        let no_minus_x = all_but(Vec3::new(-0.2, -5.0, 0.0));
        let no_minus_y = all_but(Vec3::new(-5.0, -0.2, 0.0));
        assert!(occluders_block_centre(&no_minus_x, far));
        assert!(!hidden(from, far, || 1.0, &no_minus_x));
        assert!(!hidden(from, far, || 1.0, &no_minus_y));
        // Covering all four sides as well: hidden.
        let all = all_but(Vec3::new(-5.0, -5.0, 0.0));
        assert!(hidden(from, far, || 1.0, &all));
    }

    fn occluders_block_centre(occ: &[Shape], to: Vec3) -> bool {
        occ.iter().any(|s| blocks(s, Vec3::ZERO, to))
    }

    #[test]
    fn the_papers_form_occludes_with_the_bounding_sphere() {
        let b = Shape::Box(Aabb::new(Vec3::ZERO, Vec3::new(4.0, 2.0, 4.0)));
        assert_eq!(occluder(&b, Occluders::Shape), b);
        // Centre (2, 1, 2), radius √(16 + 4 + 16)/2 = 3.
        assert_eq!(
            occluder(&b, Occluders::BoundingSphere),
            Shape::Sphere {
                center: Vec3::new(2.0, 1.0, 2.0),
                radius: 3.0
            }
        );
    }
}
