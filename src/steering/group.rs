//! Group motion: separation (inverse distance) and alignment (difference from the neighbors' mean
//! velocity) of seed 001, cohesion, seed 003's R–A zones and Vicsek alignment.
//!
//! Each rule reads neighborhood sums ([`GroupSum`]) that perception folds over every kin it
//! notes (`*_of`); the slice forms fold a list of neighbors the same way, for tests and tools.
//! Forces are turned into [`Steer::Velocity`]`(v + F)` by the recipe layer.

use super::Steer;
pub use crate::params::steering::Zones;
use crate::perception::group::Near;
use crate::perception::{GroupAcc, GroupQuery, GroupSum};
use crate::world::Rng;
use glam::Vec3;

/// A neighbor as the group rules see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbor {
    /// Neighbor position minus own position.
    pub offset: Vec3,
    /// Distance |offset|.
    pub dist: f32,
    /// Neighbor velocity.
    pub velocity: Vec3,
}

/// Folds `neighbors` into the sums of `q`, as perception does for every kin it notes.
pub fn fold(neighbors: &[Neighbor], q: &GroupQuery) -> GroupSum {
    let mut s = GroupAcc::default();
    for n in neighbors {
        let offset = glam::Vec3A::from(n.offset);
        let near = Near::new(
            offset,
            offset.length_squared(),
            n.velocity.into(),
            q.reads_unit(),
        );
        s.add(q, &near);
    }
    s.into()
}

/// Separation of seed 001: each neighbor pushes with `m1·k·(length·factor)/|d|` directly away
/// from it. Coincident neighbors (d = 0) are skipped: they have no direction.
pub fn separation(neighbors: &[Neighbor], m1: f32, k: f32, length: f32, factor: f32) -> Vec3 {
    let sum = fold(
        neighbors,
        &GroupQuery::Separation {
            radius: f32::INFINITY,
        },
    );
    separation_of(&sum, m1, k, length, factor)
}

/// Separation from the sums of a [`GroupQuery::Separation`]: `−m1·k·length·factor · Σ d/|d|²`.
#[inline]
pub fn separation_of(sum: &GroupSum, m1: f32, k: f32, length: f32, factor: f32) -> Vec3 {
    -sum.a * (m1 * k * length * factor)
}

/// Alignment of seed 001: `m1·k·(v_avg − v)`, proportional to the difference from the
/// neighbors' mean velocity. Zero without neighbors.
pub fn alignment(neighbors: &[Neighbor], own_velocity: Vec3, m1: f32, k: f32) -> Vec3 {
    let sum = fold(
        neighbors,
        &GroupQuery::Mean {
            radius: f32::INFINITY,
        },
    );
    alignment_of(mean(sum.b, sum.n), own_velocity, m1, k)
}

/// Alignment from the neighbors' mean velocity (`None` without neighbors).
#[inline]
pub fn alignment_of(mean_velocity: Option<Vec3>, own_velocity: Vec3, m1: f32, k: f32) -> Vec3 {
    mean_velocity.map_or(Vec3::ZERO, |avg| m1 * k * (avg - own_velocity))
}

/// Cohesion: `k·(centroid − position)`, toward the neighbors' mean position.
pub fn cohesion(neighbors: &[Neighbor], k: f32) -> Vec3 {
    let sum = fold(
        neighbors,
        &GroupQuery::Mean {
            radius: f32::INFINITY,
        },
    );
    cohesion_of(mean(sum.a, sum.n), k)
}

/// Cohesion from the neighbors' mean offset (`None` without neighbors).
#[inline]
pub fn cohesion_of(mean_offset: Option<Vec3>, k: f32) -> Vec3 {
    mean_offset.map_or(Vec3::ZERO, |c| k * c)
}

/// `sum / count`, `None` when the count is 0.
#[inline]
pub fn mean(sum: Vec3, count: u32) -> Option<Vec3> {
    (count > 0).then(|| sum / count as f32)
}

impl Zones {
    /// The neighborhood sums these zones read.
    pub fn query(&self) -> GroupQuery {
        GroupQuery::Zones {
            repulsion: self.repulsion,
            matching: self.matching,
            attraction: self.attraction,
            soft: self.soft,
        }
    }
}

/// R–A zones (seed 003): neighbors closer than `r_r` repel; between `r_r` and `r_m` the agent
/// matches their heading; between `r_m` and `r_a` it is attracted. Repulsion takes precedence:
/// while any neighbor is inside `r_r` only repulsion acts (with a soft band, once the repulsion
/// weights sum to 1; below that the other zones' unit direction fills the rest). Returns a
/// desired velocity of `speed` along the resulting direction, or [`Steer::None`] when no
/// neighbor is in any zone.
pub fn ra_zones(neighbors: &[Neighbor], zones: &Zones, speed: f32) -> Steer {
    ra_zones_of(&fold(neighbors, &zones.query()), speed)
}

/// R–A zones from the sums of a [`GroupQuery::Zones`].
#[inline]
pub fn ra_zones_of(sum: &GroupSum, speed: f32) -> Steer {
    let dir = if sum.n > 0 && sum.w >= 1.0 {
        sum.a
    } else if sum.n > 0 || sum.m > 0 {
        let rest = (sum.b + sum.c).normalize_or_zero();
        sum.a + (1.0 - sum.w) * rest
    } else {
        return Steer::None;
    };
    match dir.try_normalize() {
        Some(d) => Steer::Velocity(d * speed),
        None => Steer::None,
    }
}

/// Vicsek alignment (seed 003): the new heading is the average of the own and the neighbors'
/// headings (neighbors within `r_n`, headings from the previous step, so the update is
/// synchronous), plus uniform angular noise `noise·(u − 0.5)` on yaw and pitch; fixed `speed`.
/// `u` are two uniform numbers in [0, 1).
pub fn vicsek(
    own_forward: Vec3,
    neighbors: &[Neighbor],
    radius: f32,
    speed: f32,
    noise: f32,
    u: (f32, f32),
) -> Steer {
    let sum = fold(neighbors, &GroupQuery::Headings { radius });
    vicsek_of(own_forward, &sum, speed, noise, u)
}

/// Vicsek alignment from the sums of a [`GroupQuery::Headings`].
pub fn vicsek_of(
    own_forward: Vec3,
    sum: &GroupSum,
    speed: f32,
    noise: f32,
    u: (f32, f32),
) -> Steer {
    let dir = (own_forward.normalize_or_zero() + sum.a)
        .try_normalize()
        .unwrap_or(own_forward);
    let Some((yaw, pitch)) = crate::frame::heading_of(dir) else {
        return Steer::None;
    };
    let yaw = yaw + noise * (u.0 - 0.5);
    let pitch =
        (pitch + noise * (u.1 - 0.5)).clamp(-crate::frame::PITCH_LIMIT, crate::frame::PITCH_LIMIT);
    Steer::Velocity(crate::frame::forward(yaw, pitch) * speed)
}

/// Group escape by density (seed 003 (1)): a fish slower than `below` re-draws its speed
/// uniformly in [V_min, V_max] (`v_min`, `v_max`) and keeps its heading; a faster one is left
/// alone ([`Steer::None`], and no draw is taken from `rng`).
pub fn disperse(speed: f32, below: f32, v_min: f32, v_max: f32, rng: &mut Rng) -> Steer {
    if speed < below {
        Steer::Turn {
            yaw: 0.0,
            pitch: 0.0,
            speed: rng.range(v_min, v_max),
        }
    } else {
        Steer::None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nb(offset: Vec3, velocity: Vec3) -> Neighbor {
        Neighbor {
            offset,
            dist: offset.length(),
            velocity,
        }
    }

    #[test]
    fn separation_is_inverse_distance() {
        // m1=2, k=0.5, length=1, factor=3 → magnitude 3/|d|: neighbor at +X 2 away → (−1.5,0,0).
        let f = separation(
            &[nb(Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO)],
            2.0,
            0.5,
            1.0,
            3.0,
        );
        assert!((f - Vec3::new(-1.5, 0.0, 0.0)).length() < 1e-6);
        // Halving the distance doubles the push.
        let g = separation(
            &[nb(Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO)],
            2.0,
            0.5,
            1.0,
            3.0,
        );
        assert!((g.length() - 2.0 * f.length()).abs() < 1e-6);
        // Coincident neighbors give no NaN.
        assert_eq!(
            separation(&[nb(Vec3::ZERO, Vec3::ZERO)], 1.0, 1.0, 1.0, 1.0),
            Vec3::ZERO
        );
    }

    #[test]
    fn separation_scales_with_every_factor() {
        // m1·k·length·factor = 2·1.5·0.5·4 = 6; neighbor at (0,3,0): d/|d|² = (0,1/3,0) → (0,−2,0).
        let f = separation(
            &[nb(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO)],
            2.0,
            1.5,
            0.5,
            4.0,
        );
        assert!((f - Vec3::new(0.0, -2.0, 0.0)).length() < 1e-6, "{f}");
    }

    #[test]
    fn no_neighbors_no_alignment_or_cohesion() {
        assert_eq!(mean(Vec3::ONE, 0), None);
        assert_eq!(alignment(&[], Vec3::Z, 1.0, 1.0), Vec3::ZERO);
        assert_eq!(cohesion(&[], 1.0), Vec3::ZERO);
    }

    #[test]
    fn alignment_is_difference_from_mean_velocity() {
        let n = [
            nb(Vec3::X, Vec3::new(2.0, 0.0, 0.0)),
            nb(Vec3::Z, Vec3::new(0.0, 0.0, 2.0)),
        ];
        // mean (1,0,1); own (0,0,1) → m1·k·(1,0,0) with m1=1, k=0.5.
        let f = alignment(&n, Vec3::Z, 1.0, 0.5);
        assert!((f - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
    }

    #[test]
    fn cohesion_points_to_centroid() {
        let n = [
            nb(Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO),
            nb(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO),
        ];
        assert_eq!(cohesion(&n, 1.0), Vec3::new(1.0, 0.0, 2.0));
    }

    #[test]
    fn zones_repulsion_takes_precedence() {
        let z = Zones {
            repulsion: 1.0,
            matching: 3.0,
            attraction: 6.0,
            soft: 0.0,
        };
        // One neighbor inside r_r at +X, one far away at −X: pure repulsion → −X.
        let n = [
            nb(Vec3::new(0.5, 0.0, 0.0), Vec3::Z),
            nb(Vec3::new(-5.0, 0.0, 0.0), Vec3::Z),
        ];
        assert_eq!(
            ra_zones(&n, &z, 2.0),
            Steer::Velocity(Vec3::new(-2.0, 0.0, 0.0))
        );
        // Matching zone neighbor heading +Z and attraction zone neighbor at +X:
        // direction normalize((0,0,1) + (1,0,0)).
        let n = [
            nb(Vec3::new(0.0, 2.0, 0.0), Vec3::Z),
            nb(Vec3::new(5.0, 0.0, 0.0), Vec3::ZERO),
        ];
        let Steer::Velocity(v) = ra_zones(&n, &z, 1.0) else {
            panic!()
        };
        assert!((v - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-6);
        // Nobody within r_a.
        assert_eq!(
            ra_zones(&[nb(Vec3::new(9.0, 0.0, 0.0), Vec3::Z)], &z, 1.0),
            Steer::None
        );
    }

    #[test]
    fn two_repelling_neighbors_still_ignore_the_matching_zone() {
        let z = Zones {
            repulsion: 1.0,
            matching: 3.0,
            attraction: 6.0,
            soft: 0.0,
        };
        // Two inside r_r (w = 2): a = −(0.5,0,0)/0.5 − (0,0.5,0)/0.5 = (−1,−1,0). The matched
        // neighbor at 2 must not enter as (1 − w)·Z = −Z.
        let n = [
            nb(Vec3::new(0.5, 0.0, 0.0), Vec3::Z),
            nb(Vec3::new(0.0, 0.5, 0.0), Vec3::Z),
            nb(Vec3::new(2.0, 0.0, 0.0), Vec3::Z),
        ];
        let Steer::Velocity(v) = ra_zones(&n, &z, 1.0) else {
            panic!()
        };
        assert!(
            (v - Vec3::new(-1.0, -1.0, 0.0).normalize()).length() < 1e-6,
            "{v}"
        );
    }

    #[test]
    fn default_zones_nest_with_a_half_soft_band() {
        let z = Zones::default();
        assert_eq!(
            (z.repulsion, z.matching, z.attraction, z.soft),
            (1.0, 4.0, 10.0, 0.5)
        );
    }

    #[test]
    fn soft_zones_weigh_repulsion_by_depth() {
        let z = Zones {
            repulsion: 1.0,
            matching: 3.0,
            attraction: 6.0,
            soft: 0.5,
        };
        // A neighbor at +X, 0.75 inside r_r = 1 with a band of 0.5: w = (1 − 0.75)/0.5 = 0.5. It
        // repels with 0.5·(−X) and is matched (heading +Z) with the other 0.5; the rest
        // direction normalize(0.5·Z) = Z fills 1 − w: dir = (−0.5, 0, 0.5).
        let n = [nb(Vec3::new(0.75, 0.0, 0.0), Vec3::Z)];
        let Steer::Velocity(v) = ra_zones(&n, &z, 1.0) else {
            panic!()
        };
        assert!(
            (v - Vec3::new(-1.0, 0.0, 1.0).normalize()).length() < 1e-6,
            "{v}"
        );
        // At the edge of r_r it does not repel at all: the heading is the neighbor's.
        let n = [nb(Vec3::new(0.999_999, 0.0, 0.0), Vec3::Z)];
        let Steer::Velocity(v) = ra_zones(&n, &z, 1.0) else {
            panic!()
        };
        assert!((v - Vec3::Z).length() < 1e-4, "{v}");
        // Deeper than the band: pure repulsion, as in the hard zone.
        let n = [nb(Vec3::new(0.4, 0.0, 0.0), Vec3::Z)];
        assert_eq!(
            ra_zones(&n, &z, 2.0),
            Steer::Velocity(Vec3::new(-2.0, 0.0, 0.0))
        );
    }

    #[test]
    fn vicsek_averages_headings() {
        // Own +Z, one neighbor heading +X within r_n, one heading −Z outside: mean of +Z and +X.
        let n = [
            nb(Vec3::new(1.0, 0.0, 0.0), Vec3::X * 3.0),
            nb(Vec3::new(9.0, 0.0, 0.0), -Vec3::Z),
        ];
        let Steer::Velocity(v) = vicsek(Vec3::Z, &n, 2.0, 1.5, 0.0, (0.5, 0.5)) else {
            panic!()
        };
        assert!(
            (v - Vec3::new(1.0, 0.0, 1.0).normalize() * 1.5).length() < 1e-5,
            "{v}"
        );
    }
    #[test]
    fn vicsek_noise_is_uniform_in_plus_minus_half_eta() {
        // Alone, heading +Z (yaw 0, pitch 0), η = 0.8: u = (1, 0) turns yaw by 0.8·(1 − 0.5) =
        // +0.4 and pitch by 0.8·(0 − 0.5) = −0.4; forward(0.4, −0.4) = (−sin0.4·cos0.4,
        // sin(−0.4), cos0.4·cos0.4) = (−0.358683, −0.389418, 0.848353), times speed 2.
        let Steer::Velocity(v) = vicsek(Vec3::Z, &[], 2.0, 2.0, 0.8, (1.0, 0.0)) else {
            panic!()
        };
        let want = Vec3::new(-0.717356, -0.778837, 1.69671);
        assert!((v - want).length() < 1e-5, "{v}");
        // u = 0.5 is no noise at all.
        let Steer::Velocity(v) = vicsek(Vec3::Z, &[], 2.0, 1.0, 0.8, (0.5, 0.5)) else {
            panic!()
        };
        assert!((v - Vec3::Z).length() < 1e-6, "{v}");
        // With a neighbor heading +X: the mean heading normalize(Z + X) has yaw −π/4; η = 1,
        // u.0 = 0.75 adds 0.25 → yaw −0.535398, level; forward = (sin 0.535398, 0,
        // cos 0.535398) = (0.509994, 0, 0.860188), times speed 1.5.
        let n = [nb(Vec3::new(1.0, 0.0, 0.0), Vec3::X)];
        let Steer::Velocity(v) = vicsek(Vec3::Z, &n, 2.0, 1.5, 1.0, (0.75, 0.5)) else {
            panic!()
        };
        let want = Vec3::new(0.765275, 0.0, 1.2901);
        assert!((v - want).length() < 1e-5, "{v}");
    }

    #[test]
    fn disperse_redraws_the_speed_in_vmin_vmax() {
        // V_min = 0.4, V_max = 3.2, v_d = 0.96: a fish at 0.5 re-draws; the draw is
        // V_min + (V_max − V_min)·u with u the stream's next number.
        let mut rng = Rng::new(7, 3);
        let u = {
            let mut copy = rng;
            copy.next_f32()
        };
        let Steer::Turn { yaw, pitch, speed } = disperse(0.5, 0.96, 0.4, 3.2, &mut rng) else {
            panic!()
        };
        assert_eq!((yaw, pitch), (0.0, 0.0));
        assert!(
            (speed - (0.4 + 2.8 * u)).abs() < 1e-6,
            "{speed} for u = {u}"
        );
        // Over many draws the speeds cover [0.4, 3.2] and stay in it.
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for _ in 0..2000 {
            let Steer::Turn { speed, .. } = disperse(0.0, 0.96, 0.4, 3.2, &mut rng) else {
                panic!()
            };
            lo = lo.min(speed);
            hi = hi.max(speed);
        }
        assert!(
            (0.4..0.45).contains(&lo) && (3.15..=3.2).contains(&hi),
            "{lo}..{hi}"
        );
        // At or above v_d: nothing, and no draw taken.
        let before = rng;
        assert_eq!(disperse(0.96, 0.96, 0.4, 3.2, &mut rng), Steer::None);
        assert_eq!(rng, before);
    }
}
