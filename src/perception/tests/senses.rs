//! What a sense perceives: vision cone, smell, custom volumes, occlusion by each obstacle shape.

use super::*;

#[test]
fn vision_smell_and_blind_spot() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    // Predator ahead-right within vision: bearing +π/4 (right is −X).
    w.agents.push(agent(1, 1, Vec3::new(-5.0, 0.0, 5.0), 0.0));
    // Kin straight behind within vision radius: blind spot → only smelt.
    w.agents.push(agent(2, 0, Vec3::new(0.0, 0.0, -5.0), 0.0));
    // Food at 15: smell only. Food at 25: nothing.
    w.add_food(Vec3::new(0.0, 0.0, 15.0));
    w.add_food(Vec3::new(0.0, 0.0, 25.0));
    let p = run(&w, &rel(), SenseParams::default());
    let sm = p.summaries(0);
    assert_eq!(sm[Category::Predator as usize].count, 1);
    assert_eq!(sm[Category::Predator as usize].seen, 1);
    let pred = p.percepts(0)[sm[Category::Predator as usize].nearest.unwrap() as usize];
    assert!((pred.bearing - std::f32::consts::FRAC_PI_4).abs() < 1e-5);
    assert_eq!(pred.sector(), Sector::RightFront);
    assert!((pred.dist - 50f32.sqrt()).abs() < 1e-5);
    assert_eq!(sm[Category::Kin as usize].count, 1);
    assert_eq!(
        sm[Category::Kin as usize].seen,
        0,
        "behind is the blind spot"
    );
    assert_eq!(sm[Category::Food as usize].count, 1);
    assert_eq!(sm[Category::Food as usize].seen, 0);
    assert_eq!(sm[Category::Food as usize].nearest_dist, 15.0);
    // The predator perceives both fish as food (one seen, one smelt at 11.2).
    assert_eq!(
        p.summaries(1)[Category::Food as usize].count,
        2,
        "both fish"
    );
}

/// Seed 001's "visible if any part is in the field" (`Extent::AnyPart`) against the centre
/// test: a cone of ±60°, vision 10, no smell.
#[test]
fn any_part_in_the_field_is_enough_with_any_part() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    // A predator 6 away, 70° to the right of the heading (right is −X), of size 4 × 4 × 4:
    // r = 2√3 = 3.464, asin(3.464/6) = 35.3°, 70 − 35.3 = 34.7 ≤ 60.
    let a = 70f32.to_radians();
    let mut big = agent(
        1,
        1,
        Vec3::new(-crate::math::sin(a), 0.0, crate::math::cos(a)) * 6.0,
        0.0,
    );
    big.size = Vec3::splat(4.0);
    w.agents.push(big);
    // A second one 13 straight ahead: 13 − 3.464 = 9.54 ≤ 10.
    let mut far = agent(2, 1, Vec3::new(0.0, 0.0, 13.0), 0.0);
    far.size = Vec3::splat(4.0);
    w.agents.push(far);
    // A rock of radius 3 centred 7 away, 80° to the left: its nearest point is 80° off too,
    // but asin(3/7) = 25.4°, 80 − 25.4 = 54.6 ≤ 60.
    let b = 80f32.to_radians();
    w.add_obstacle(Shape::Sphere {
        center: Vec3::new(crate::math::sin(b), 0.0, crate::math::cos(b)) * 7.0,
        radius: 3.0,
    });
    // Food (no body) 11 ahead: out of range either way.
    w.add_food(Vec3::new(0.0, 0.0, 11.0));
    let sense = SenseParams {
        vision_radius: 10.0,
        vision_half_angle: 60f32.to_radians(),
        smell_radius: 0.0,
        occlusion: false,
        ..SenseParams::default()
    };
    let centre = run(&w, &rel(), sense);
    let sm = centre.summaries(0);
    assert_eq!(sm[Category::Predator as usize].count, 0);
    assert_eq!(sm[Category::Obstacle as usize].count, 0);
    let any = run(
        &w,
        &rel(),
        SenseParams {
            extent: Extent::AnyPart,
            ..sense
        },
    );
    let sm = any.summaries(0);
    assert_eq!(sm[Category::Predator as usize].count, 2);
    assert_eq!(sm[Category::Predator as usize].seen, 2);
    assert_eq!(sm[Category::Obstacle as usize].seen, 1);
    assert_eq!(sm[Category::Food as usize].count, 0);
    // Smaller bodies (size 1 × 1 × 1, r = 0.866) stay unseen: 70 − 8.3 > 60, 13 − 0.87 > 10.
    w.agents[1].size = Vec3::ONE;
    w.agents[2].size = Vec3::ONE;
    let any = run(
        &w,
        &rel(),
        SenseParams {
            extent: Extent::AnyPart,
            ..sense
        },
    );
    assert_eq!(any.summaries(0)[Category::Predator as usize].count, 0);
}

#[test]
fn obstacles_occlude_what_is_behind_them() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    w.add_food(Vec3::new(0.0, 0.0, 8.0));
    w.add_obstacle(Shape::Sphere {
        center: Vec3::new(0.0, 0.0, 4.0),
        radius: 1.0,
    });
    let p = run(&w, &rel(), SenseParams::default());
    let sm = p.summaries(0);
    assert_eq!(sm[Category::Food as usize].count, 1);
    assert_eq!(
        sm[Category::Food as usize].seen,
        0,
        "hidden by the rock, still smelt"
    );
    assert_eq!(sm[Category::Obstacle as usize].count, 1);
    assert!((sm[Category::Obstacle as usize].nearest_dist - 3.0).abs() < 1e-6);
}

/// A reef fish at (0, 0, −3) heading +z, 3 in front of a 12 × 2 × 6 box (x −6..6, y −1..1,
/// z 2..8; centre (0, 0, 5), bounding radius √184/2 = 6.78: the fish is 8 from its centre,
/// outside it), with vision 20 and smell 30.
fn beside_a_box() -> (World, SenseParams) {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::new(0.0, 0.0, -3.0), 0.0));
    w.add_obstacle(Shape::Box(Aabb::new(
        Vec3::new(-6.0, -1.0, 2.0),
        Vec3::new(6.0, 1.0, 8.0),
    )));
    let sense = SenseParams {
        vision_radius: 20.0,
        smell_radius: 30.0,
        ..SenseParams::default()
    };
    (w, sense)
}

#[test]
fn a_shark_above_a_box_is_seen_past_its_real_shape() {
    let (mut w, sense) = beside_a_box();
    // The shark at (0, 4, 12): the line of sight rises 4 over 15, at the box's front face
    // (z = 2, 5 along) it is 4·5/15 = 1.33 high, above the top (1); it passes the box's
    // centre at 8·4/√241 = 2.06 (< 6.78) and the shark is √(16 + 49) = 8.06 from that
    // centre (> 6.78): the bounding sphere would hide it.
    w.agents.push(agent(1, 1, Vec3::new(0.0, 4.0, 12.0), 0.0));
    let p = run(&w, &rel(), sense);
    let pred = p.summaries(0)[Category::Predator as usize];
    assert_eq!((pred.count, pred.seen), (1, 1), "seen above the box");
    // The box itself: 5 ahead (front face at z = 2).
    let obs = p.summaries(0)[Category::Obstacle as usize];
    assert!((obs.nearest_dist - 5.0).abs() < 1e-6);
    // The paper's form: the bounding sphere hides it (still smelt at 15.5 < 30).
    let paper = SenseParams {
        occluders: Occluders::BoundingSphere,
        ..sense
    };
    let p = run(&w, &rel(), paper);
    let pred = p.summaries(0)[Category::Predator as usize];
    assert_eq!(
        (pred.count, pred.seen),
        (1, 0),
        "the bounding sphere hides it"
    );
    // Occlusion off: seen either way.
    let off = SenseParams {
        occlusion: false,
        ..paper
    };
    let pred = run(&w, &rel(), off).summaries(0)[Category::Predator as usize];
    assert_eq!((pred.count, pred.seen), (1, 1));
}

#[test]
fn a_fish_behind_the_box_is_hidden_by_its_real_shape() {
    let (mut w, sense) = beside_a_box();
    // Kin at (0, 0, 12): the line of sight runs through the box along its axis; the outline
    // points (0.53 across: size 0.2 × 0.3 × 1, diagonal 1.06) do too.
    w.agents.push(agent(1, 0, Vec3::new(0.0, 0.0, 12.0), 0.0));
    let kin = run(&w, &rel(), sense).summaries(0)[Category::Kin as usize];
    assert_eq!((kin.count, kin.seen), (1, 0), "behind the box: smelt only");
}

#[test]
fn a_target_behind_a_rock_is_hidden_unless_it_sticks_out() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    // A rock of radius 1 at z = 4; a predator at z = 8, radius 0.53: its outline points'
    // lines of sight pass the rock's centre at 4·0.53/8 ≈ 0.27 (< 1): hidden.
    w.add_obstacle(Shape::Sphere {
        center: Vec3::new(0.0, 0.0, 4.0),
        radius: 1.0,
    });
    w.agents.push(agent(1, 1, Vec3::new(0.0, 0.0, 8.0), 0.0));
    let pred = run(&w, &rel(), SenseParams::default()).summaries(0)[Category::Predator as usize];
    assert_eq!((pred.count, pred.seen), (1, 0), "hidden by the rock");
    // A big one there (size 4 × 4 × 4: radius 2√3 = 3.46) sticks out: its outline points'
    // lines of sight pass the rock's centre at about 4·3.46/√(64 + 12) = 1.59 (> 1).
    w.agents[1].size = Vec3::splat(4.0);
    let pred = run(&w, &rel(), SenseParams::default()).summaries(0)[Category::Predator as usize];
    assert_eq!((pred.count, pred.seen), (1, 1), "partly in view");
}

#[test]
fn a_cylinder_is_perceived_at_its_surface_and_occludes() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    // A pillar of radius 1 around (0, ·, 4), from y = −5 to 5: its surface 3 ahead.
    w.add_obstacle(Shape::Cylinder {
        base: Vec3::new(0.0, -5.0, 4.0),
        radius: 1.0,
        height: 10.0,
    });
    w.add_food(Vec3::new(0.0, 0.0, 8.0));
    // Higher, at y = 6: the line of sight crosses the axis 3 high, below the top (5): hidden.
    w.add_food(Vec3::new(0.0, 6.0, 8.0));
    // Beside it (x = 3 at z = 8: 1.5 off the axis at z = 4): seen.
    w.add_food(Vec3::new(3.0, 0.0, 8.0));
    let p = run(&w, &rel(), SenseParams::default());
    let sm = p.summaries(0);
    let obs = sm[Category::Obstacle as usize];
    assert!((obs.nearest_dist - 3.0).abs() < 1e-6);
    let food = sm[Category::Food as usize];
    assert_eq!((food.count, food.seen), (3, 1));
}

#[test]
fn custom_volume_replaces_the_vision_sphere() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    w.agents.push(agent(1, 0, Vec3::new(0.0, 0.0, 14.0), 0.0)); // ahead, inside the egg
    w.agents.push(agent(2, 0, Vec3::new(0.0, 0.0, -4.0), 0.0)); // behind, outside
    let sense = SenseParams {
        volume: Some(Volume::Egg {
            ahead: 15.0,
            behind: 3.0,
            side: 5.0,
            up: 5.0,
        }),
        smell_radius: 0.0,
        ..Default::default()
    };
    let p = run(&w, &rel(), sense);
    let sm = p.summaries(0)[Category::Kin as usize];
    assert_eq!((sm.count, sm.seen), (1, 1));
}
