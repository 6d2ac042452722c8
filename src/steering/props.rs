//! Property tests: every primitive returns a finite command for any finite input, including
//! coincident positions and zero velocities.

use super::avoid::{self, AvoidParams, MovingObstacle, PressureSource};
use super::group::{self, Neighbor, Zones};
use super::wander::{self, WanderParams};
use super::{arrive, blend, escape, flee, goal, seek, Kinematics, Steer};
use crate::world::Aabb;
use glam::Vec3;
use proptest::prelude::*;

fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![-1e4f32..1e4, Just(0.0f32), Just(1e-20f32), Just(-1e-20f32)]
}

fn vec3() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z)),
        Just(Vec3::ZERO)
    ]
}

fn angle() -> impl Strategy<Value = f32> {
    -10.0f32..10.0
}

fn kin() -> impl Strategy<Value = Kinematics> {
    (
        vec3(),
        angle(),
        -1.5f32..1.5,
        prop_oneof![0.0f32..10.0, Just(0.0)],
    )
        .prop_map(|(pos, yaw, pitch, speed)| Kinematics {
            pos,
            yaw,
            pitch,
            speed,
        })
}

fn finite(s: Steer) -> bool {
    s.is_finite()
}

proptest! {
    #[test]
    fn goal_and_escape_primitives_are_finite(k in kin(), t in vec3(), b in angle(), e in angle(), d in 0.0f32..100.0, vmax in 0.0f32..10.0) {
        prop_assert!(finite(seek(&k, t, vmax)));
        prop_assert!(finite(seek(&k, k.pos, vmax)));
        prop_assert!(finite(flee(&k, t, vmax)));
        prop_assert!(finite(flee(&k, k.pos, vmax)));
        prop_assert!(finite(arrive(&k, t, vmax, 2.0)));
        prop_assert!(finite(arrive(&k, k.pos, vmax, 0.0)));
        let g = goal::GoalRules::default();
        let r = escape::EscapeRules::default();
        prop_assert!(finite(goal::goal_by_smell(b, e, vmax, &g)));
        prop_assert!(finite(goal::goal_by_vision(b, e, d, 0.5, vmax, &g)));
        prop_assert!(finite(escape::escape_by_smell(b, e, k.speed, vmax, &r)));
        prop_assert!(finite(escape::escape_by_vision(b, e, d, 10.0, vmax, &r)));
        prop_assert!(finite(escape::escape_mirror(&k, t, vmax)));
        prop_assert!(finite(escape::escape_mirror(&k, k.pos, vmax)));
        for p in [goal::Prediction::None, goal::Prediction::Linear, goal::Prediction::Intercept] {
            prop_assert!(finite(goal::pursue(&k, t, t, 0.05, p, vmax)));
            prop_assert!(finite(goal::pursue(&k, k.pos, t, 0.0, p, vmax)));
        }
        let ip = goal::intercept_point(k.pos, vmax, t, Vec3::ZERO);
        prop_assert!(ip.is_finite());
    }

    #[test]
    fn avoidance_is_finite(k in kin(), srcs in proptest::collection::vec((0.0f32..50.0, angle(), angle(), 0.0f32..20.0, vec3()), 0..8)) {
        let p = AvoidParams::default();
        let statics: Vec<PressureSource> = srcs.iter().map(|s| PressureSource { dist: s.0, bearing: s.1, elevation: s.2, size: s.3, weight: 1.0 }).collect();
        prop_assert!(finite(avoid::avoid_static(&k, avoid::pressures(statics.iter().copied(), p.m0), 10.0, 1.0, 2.0, 0.05, &p)));
        let moving: Vec<MovingObstacle> = srcs.iter().map(|s| MovingObstacle { source: PressureSource { dist: s.0, bearing: s.1, elevation: s.2, size: s.3, weight: 1.0 }, velocity: s.4 }).collect();
        prop_assert!(finite(avoid::avoid_dynamic(&k, &moving, 10.0, 2.618, 1.0, 0.05, &p)));
        let spheres = srcs.iter().map(|s| (s.4, s.3));
        prop_assert!(finite(avoid::predict_collision(&k, spheres, 1.5, 0.5, 2.0)));
        let b = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
        prop_assert!(finite(avoid::contain(&k, &b, 2.0, 1.0, 2.0)));
        prop_assert!(finite(avoid::contain(&k, &b, 50.0, 1.0, 2.0)));
    }

    #[test]
    fn group_rules_are_finite(k in kin(), nbs in proptest::collection::vec((vec3(), vec3()), 0..10), u in (0.0f32..1.0, 0.0f32..1.0)) {
        let n: Vec<Neighbor> = nbs.iter().map(|(o, v)| Neighbor { offset: *o, dist: o.length(), velocity: *v }).collect();
        prop_assert!(group::separation(&n, 1.0, 1.0, 1.0, 1.0).is_finite());
        prop_assert!(group::alignment(&n, k.velocity(), 1.0, 1.0).is_finite());
        prop_assert!(group::cohesion(&n, 1.0).is_finite());
        prop_assert!(finite(group::ra_zones(&n, &Zones::default(), 1.0)));
        prop_assert!(finite(group::vicsek(k.forward(), &n, 5.0, 1.0, 0.3, u)));
        prop_assert!(finite(wander::wander(k.pitch, 2.0, &WanderParams::default(), u)));
        let cmds = [(1.0, seek(&k, k.pos + Vec3::X, 1.0)), (0.5, Steer::Velocity(Vec3::ZERO)), (2.0, Steer::None)];
        prop_assert!(finite(blend(&k, cmds)));
    }
}
