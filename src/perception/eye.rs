//! The sense test of stage 2: a perceiver's eye (body frame and vision cone, computed once per
//! agent) and whether a target is seen, smelt or missed: vision sphere `v_r` within a cone or a
//! custom body-frame volume (seed 002), smell sphere `O_r` (seed 000 §1), "any part" of a body
//! in the field (seed 001), and obstacles hiding what lies fully behind them ([`occlusion`],
//! seed 001). Reads only what it is handed: no world, no index.

use super::{occlusion, volume, Extent, Sense, SenseParams};
use crate::frame;
use crate::world::Shape;
use glam::Vec3;

/// Most obstacles considered as occluders for one agent.
pub(super) const MAX_OCCLUDERS: usize = 16;

/// An unused occluder slot.
pub(super) const NO_OCCLUDER: Shape = Shape::Sphere {
    center: Vec3::ZERO,
    radius: 0.0,
};

/// A perceiver's body frame and vision cone, computed once per agent.
pub(super) struct Eye {
    pub(super) fwd: Vec3,
    left: Vec3,
    up: Vec3,
    /// Cosine bound of the vision cone (as [`volume::in_cone`] computes it).
    pub(super) cos_min: f32,
    /// Whether the cone is the whole sphere.
    pub(super) full_circle: bool,
}

/// The cosine bound of a vision cone of half-angle `half_angle`, a hair wide so that a neighbor
/// right on its edge is in.
#[inline]
pub(super) fn cos_min(half_angle: f32) -> f32 {
    crate::math::cos(half_angle) - 1e-6
}

/// Whether a cone of cosine bound `cos_min` is the whole sphere.
#[inline(always)]
pub(super) fn full_circle(cos_min: f32) -> bool {
    cos_min < -1.000_000_5
}

impl Eye {
    /// The eye of a perceiver heading `heading` (its forward unit vector) at `yaw`, with the
    /// cone's cosine bound `cos_min`. The body frame's other two axes are worked out only where
    /// a sense volume reads them ([`Eye::local`]): a `sin_cos` a perceiver otherwise spends for
    /// nothing. `frame::dorsal` is `forward × left`: both are reused (the forward vector is in
    /// the body cache).
    #[inline(always)]
    pub(super) fn new(heading: Vec3, yaw: f32, cos_min: f32, sense: &SenseParams) -> Self {
        let full_circle = full_circle(cos_min);
        let (fwd, left, up) = if sense.volume.is_none() {
            let fwd = if full_circle { Vec3::ZERO } else { heading };
            (fwd, Vec3::ZERO, Vec3::ZERO)
        } else {
            let left = frame::left(yaw);
            (heading, left, heading.cross(left))
        };
        Eye {
            fwd,
            left,
            up,
            cos_min,
            full_circle,
        }
    }

    /// `offset` in the body frame (x left, y up, z forward).
    #[inline(always)]
    pub(super) fn local(&self, offset: Vec3) -> Vec3 {
        debug_assert!(
            self.left != Vec3::ZERO,
            "an eye without a sense volume has no frame"
        );
        Vec3::new(
            offset.dot(self.left),
            offset.dot(self.up),
            offset.dot(self.fwd),
        )
    }
}

/// Decides whether a target at `offset`, of squared length `d2` and bounding radius
/// `radius()` (asked only when occluders hide its centre), is seen, smelt or missed: ranges
/// are compared squared, and the square root is taken only for a vision cone.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn sense_point(
    from: Vec3,
    offset: Vec3,
    d2: f32,
    eye: &Eye,
    sense: &SenseParams,
    occluders: &[Shape],
    radius: impl FnOnce() -> f32,
) -> Option<Sense> {
    let smell = d2 <= sense.smell_radius * sense.smell_radius;
    if sense.extent == Extent::AnyPart {
        return sense_any_part(from, offset, d2, radius(), smell, eye, sense, occluders);
    }
    let vision = d2 <= sense.vision_radius * sense.vision_radius;
    sense_with(
        from,
        offset,
        || d2.sqrt(),
        vision,
        smell,
        eye,
        sense,
        (occluders, radius),
    )
}

/// [`sense_point`] for [`Extent::AnyPart`] (seed 001): a body of bounding radius `r` is seen
/// when any part of its bounding sphere is in the field: `d − r ≤ v_r` and
/// [`volume::sphere_in_cone`], or within the volume along the ray to its centre. Smell still
/// goes by the centre.
#[allow(clippy::too_many_arguments)]
fn sense_any_part(
    from: Vec3,
    offset: Vec3,
    d2: f32,
    r: f32,
    within_smell: bool,
    eye: &Eye,
    sense: &SenseParams,
    occluders: &[Shape],
) -> Option<Sense> {
    let in_vision = match &sense.volume {
        Some(v) => v.contains_sphere(eye.local(offset), r),
        None => {
            d2.sqrt() - r <= sense.vision_radius
                && (eye.full_circle
                    || volume::sphere_in_cone(eye.fwd, offset, r, sense.vision_half_angle))
        }
    };
    if in_vision && (occluders.is_empty() || !occlusion::hidden(from, offset, || r, occluders)) {
        Some(Sense::Vision)
    } else if within_smell {
        Some(Sense::Smell)
    } else {
        None
    }
}

/// Decides whether an obstacle at `offset` (of length `offset_len`; `dist` is the distance the
/// ranges apply to, to its surface) is seen, smelt or missed: obstacles are not occluded.
#[inline(always)]
pub(super) fn sense_of(
    from: Vec3,
    offset: Vec3,
    offset_len: f32,
    dist: f32,
    eye: &Eye,
    sense: &SenseParams,
) -> Option<Sense> {
    let vision = dist <= sense.vision_radius;
    let smell = dist <= sense.smell_radius;
    sense_with(
        from,
        offset,
        || offset_len,
        vision,
        smell,
        eye,
        sense,
        (&[], || 0.0),
    )
}

/// The sense test itself, given whether the target is within the vision and smell ranges and
/// the length of `offset` (asked only for a vision cone).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sense_with(
    from: Vec3,
    offset: Vec3,
    offset_len: impl FnOnce() -> f32,
    within_vision: bool,
    within_smell: bool,
    eye: &Eye,
    sense: &SenseParams,
    (occluders, radius): (&[Shape], impl FnOnce() -> f32),
) -> Option<Sense> {
    let in_vision = match &sense.volume {
        Some(v) => v.contains(eye.local(offset)),
        // `volume::in_cone` with the cosine computed once per perceiver; a full circle (±180°,
        // bound below −1 by more than any rounding of a unit vector's dot product) needs no test.
        None => {
            within_vision
                && (eye.full_circle || {
                    let len = offset_len();
                    len == 0.0 || eye.fwd.dot(offset) / len >= eye.cos_min
                })
        }
    };
    if in_vision && (occluders.is_empty() || !occlusion::hidden(from, offset, radius, occluders)) {
        Some(Sense::Vision)
    } else if within_smell {
        Some(Sense::Smell)
    } else {
        None
    }
}
