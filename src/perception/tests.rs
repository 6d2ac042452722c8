//! Unit tests of the stage: senses, occlusion, slots and summaries, injection, and the walks
//! (kin kernel, plain and general, grid and agent order) agreeing bit for bit.

use super::*;
use crate::world::{Aabb, Agent, AgentId, Anim, Attributes, Drives, Mind, Rng, Shape, SpeciesId};

pub(crate) fn agent(id: u32, species: u16, pos: Vec3, yaw: f32) -> Agent {
    Agent {
        id: AgentId(id),
        species: SpeciesId(species),
        pos,
        prev_pos: pos,
        yaw,
        pitch: 0.0,
        speed: 1.0,
        yaw_rate: 0.0,
        pitch_rate: 0.0,
        size: Vec3::new(0.2, 0.3, 1.0),
        drives: Drives::default(),
        attrs: Attributes::default(),
        mind: Mind::new(0, 1, 0),
        anim: Anim::default(),
        rng: Rng::new(0, id as u64),
        memory: Vec::new(),
        inbox: None,
        heard_event: None,
        forward_cache: crate::world::ForwardCache::NONE,
    }
}

fn run(world: &World, rel: &Relations, sense: SenseParams) -> Perception {
    let mut ag = Grid::new();
    ag.rebuild(
        world.bounds,
        sense.query_radius(),
        world.agents.iter().map(|a| a.pos),
    );
    let mut fg = Grid::new();
    fg.rebuild(
        world.bounds,
        sense.query_radius(),
        world.food.iter().map(|f| f.pos),
    );
    let mut p = Perception::new();
    p.run(world, &ag, &fg, &[sense, sense], rel);
    p
}

/// A point drawn uniformly in the cube `[-half, half]³`.
fn random_point(rng: &mut Rng, half: f32) -> Vec3 {
    Vec3::new(
        rng.range(-half, half),
        rng.range(-half, half),
        rng.range(-half, half),
    )
}

fn rel() -> Relations {
    let mut r = Relations::new(2);
    r.set(0, 0, Some(Category::Kin));
    r.set(0, 1, Some(Category::Predator));
    r.set(1, 0, Some(Category::Food));
    r.set_eats_items(0, true);
    r
}

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
    let mut big = agent(1, 1, Vec3::new(-a.sin(), 0.0, a.cos()) * 6.0, 0.0);
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
        center: Vec3::new(b.sin(), 0.0, b.cos()) * 7.0,
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

#[test]
fn injected_percepts_replace_an_agents_and_rebuild_its_summaries() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    w.add_food(Vec3::new(0.0, 0.0, 3.0));
    let mut p = run(&w, &rel(), SenseParams::default());
    assert_eq!(p.summaries(0)[Category::Food as usize].count, 1);
    let fed = |category, sense, offset: Vec3| Percept {
        source: Source::Injected,
        category,
        sense,
        offset,
        dist: offset.length(),
        bearing: 0.0,
        elevation: 0.0,
        size: 1.0,
    };
    p.inject(
        0,
        Vec3::new(1.0, 0.0, 0.0),
        &[
            fed(Category::Predator, Sense::Smell, Vec3::new(0.0, 0.0, 12.0)),
            fed(Category::Mate, Sense::Vision, Vec3::new(0.0, 0.0, 2.0)),
            fed(Category::Kin, Sense::Vision, Vec3::new(0.0, 0.0, 4.0)),
        ],
    );
    let sm = p.summaries(0);
    assert_eq!(p.percepts(0).len(), 3);
    assert_eq!(
        sm[Category::Food as usize].count,
        0,
        "the real food is gone"
    );
    let pred = sm[Category::Predator as usize];
    assert_eq!((pred.count, pred.seen, pred.nearest_dist), (1, 0, 12.0));
    // A mate also counts as kin, as perception does it.
    let kin = sm[Category::Kin as usize];
    assert_eq!((kin.count, kin.seen, kin.nearest_dist), (2, 2, 2.0));
    assert_eq!(kin.nearest, Some(1));
    assert_eq!(kin.centroid, Vec3::new(1.0, 0.0, 3.0));
}

#[test]
fn keeps_the_nearest_when_crowded_but_counts_all() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    for k in 0..40 {
        w.agents.push(agent(
            k + 1,
            0,
            Vec3::new(0.0, 0.0, 0.2 + k as f32 * 0.2),
            0.0,
        ));
    }
    let p = run(&w, &rel(), SenseParams::default());
    assert_eq!(p.percepts(0).len(), DEFAULT_PERCEPTS);
    assert_eq!(p.summaries(0)[Category::Kin as usize].count, 40);
    let maxd = p.percepts(0).iter().map(|q| q.dist).fold(0.0, f32::max);
    assert!((maxd - 0.2 * DEFAULT_PERCEPTS as f32).abs() < 1e-4);
    // A species may keep more.
    let more = SenseParams {
        max_percepts: 20,
        ..SenseParams::default()
    };
    assert_eq!(run(&w, &rel(), more).percepts(0).len(), 20);
}

#[test]
fn the_nearest_of_each_category_survives_a_crowd() {
    // 30 kin within 6 m, then food at 7 m and a predator at 8 m: the 16 slots would hold
    // only kin by distance, but the nearest food and predator replace the farthest kin.
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 2);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    for k in 0..30 {
        w.agents.push(agent(
            k + 1,
            0,
            Vec3::new(0.0, 0.0, 0.2 * (k + 1) as f32),
            0.0,
        ));
    }
    w.agents.push(agent(31, 1, Vec3::new(0.0, 0.0, 8.0), 0.0));
    w.add_food(Vec3::new(0.0, 0.0, 7.0));
    let p = run(&w, &rel(), SenseParams::default());
    let kept = p.percepts(0);
    assert_eq!(kept.len(), DEFAULT_PERCEPTS);
    let sm = p.summaries(0);
    for (c, d) in [
        (Category::Food, 7.0),
        (Category::Predator, 8.0),
        (Category::Kin, 0.2),
    ] {
        let near = &kept[sm[c as usize].nearest.expect("kept") as usize];
        assert_eq!(near.category, c);
        assert!((near.dist - d).abs() < 1e-5, "{c:?} {}", near.dist);
    }
    // They took the places of the two farthest kin: the nearest 14 kin stay (0.2 … 2.8 m).
    let far_kin = kept
        .iter()
        .filter(|q| q.category == Category::Kin)
        .map(|q| q.dist)
        .fold(0.0, f32::max);
    assert!((far_kin - 2.8).abs() < 1e-5, "{far_kin}");
    assert_eq!(
        kept.iter().filter(|q| q.category == Category::Kin).count(),
        14
    );
}

#[test]
fn group_sums_cover_every_kin_perceived_and_need_no_slots() {
    // 40 kin around the perceiver, a predator among them; a species reading only group
    // rules keeps no percept, and its sums are those of the whole neighbor list.
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 3);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    let mut rng = Rng::new(4, 0);
    for k in 0..40 {
        let pos = random_point(&mut rng, 6.0);
        let mut a = agent(k + 1, 0, pos, rng.range(-3.0, 3.0));
        a.speed = rng.range(0.0, 2.0);
        w.agents.push(a);
    }
    w.agents.push(agent(41, 1, Vec3::new(1.0, 0.0, 0.0), 0.0));
    let sense = SenseParams {
        vision_half_angle: std::f32::consts::PI,
        ..SenseParams::default()
    };
    let mut groups = GroupQueries::new();
    let queries = [
        GroupQuery::Separation { radius: 3.0 },
        GroupQuery::Mean { radius: 5.0 },
        GroupQuery::Zones {
            repulsion: 1.0,
            matching: 3.0,
            attraction: 6.0,
            soft: 0.5,
        },
        GroupQuery::Headings { radius: 4.0 },
    ];
    for q in queries {
        groups.insert(q);
    }
    let reads = Reads {
        percepts: false,
        agent_percepts: false,
        bearing_range: Some(0.0),
        groups,
        headings: true,
    };
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, 3.0, w.agents.iter().map(|a| a.pos));
    let mut p = Perception::new();
    p.run_selective(
        &w,
        &ag,
        &Grid::new(),
        &[sense, sense],
        &rel(),
        &[reads, reads],
    );
    assert!(p.percepts(0).is_empty());
    assert_eq!(p.summaries(0)[Category::Kin as usize].count, 40);
    // The same sums from the full neighbor list, in the index's order.
    let mut neighbors = Vec::new();
    ag.for_each_within(Vec3::ZERO, sense.query_radius(), |j, pos, d2| {
        if j != 0 && j != 41 {
            let a = &w.agents[j as usize];
            neighbors.push(crate::steering::group::Neighbor {
                offset: pos,
                dist: d2.sqrt(),
                velocity: a.velocity(),
            });
        }
    });
    assert_eq!(neighbors.len(), 40);
    for (k, q) in queries.iter().enumerate() {
        let want = crate::steering::group::fold(&neighbors, q);
        assert_eq!(p.group_sums(0)[k], want, "{q:?}");
        assert!(want.n + want.m > 0, "{q:?} sums something");
    }
}
#[test]
fn injected_percepts_keep_the_nearest_of_each_category() {
    // Ten kin fed within 3 m and a predator at 9 m to an agent keeping 8 percepts: like
    // perception, the predator (the only one of its category) must stay among the kept.
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    let sense = SenseParams {
        max_percepts: 8,
        ..SenseParams::default()
    };
    let mut p = run(&w, &rel(), sense);
    let fed = |category, offset: Vec3| Percept {
        source: Source::Injected,
        category,
        sense: Sense::Vision,
        offset,
        dist: offset.length(),
        bearing: 0.0,
        elevation: 0.0,
        size: 1.0,
    };
    let mut feed: Vec<Percept> = (0..10)
        .map(|k| fed(Category::Kin, Vec3::new(0.0, 0.0, 0.3 * (k + 1) as f32)))
        .collect();
    feed.push(fed(Category::Predator, Vec3::new(0.0, 0.0, 9.0)));
    p.inject(0, Vec3::ZERO, &feed);
    let sm = p.summaries(0);
    assert_eq!(sm[Category::Predator as usize].count, 1);
    assert_eq!(p.percepts(0).len(), 8);
    let k = sm[Category::Predator as usize]
        .nearest
        .expect("the predator is kept") as usize;
    assert_eq!(p.percepts(0)[k].category, Category::Predator);
    let kin = sm[Category::Kin as usize].nearest.expect("kin kept") as usize;
    assert!((p.percepts(0)[kin].dist - 0.3).abs() < 1e-6);
}

#[test]
fn injecting_into_an_agent_without_slots_does_not_panic() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, 5.0, w.agents.iter().map(|a| a.pos));
    let reads = Reads {
        percepts: false,
        ..Reads::default()
    };
    let mut p = Perception::new();
    let sense = SenseParams::default();
    p.run_selective(
        &w,
        &ag,
        &Grid::new(),
        &[sense, sense],
        &rel(),
        &[reads, reads],
    );
    let fed = Percept {
        source: Source::Injected,
        category: Category::Food,
        sense: Sense::Vision,
        offset: Vec3::Z,
        dist: 1.0,
        bearing: 0.0,
        elevation: 0.0,
        size: 0.0,
    };
    p.inject(0, Vec3::ZERO, &[fed]);
    assert!(p.percepts(0).is_empty());
    let food = p.summaries(0)[Category::Food as usize];
    assert_eq!((food.count, food.nearest), (1, None));
}

#[test]
fn a_reused_buffer_holds_no_summary_of_a_rock_that_is_gone() {
    // Agents near a rock take the general path and summarize it; once the rock is removed
    // they take the kin kernel, which rewrites only the kin summary of a row it cleared
    // itself: the rock's summary must be gone, as in a fresh perception, whatever path
    // each row took the tick before.
    let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 1);
    let mut rng = Rng::new(3, 0);
    for k in 0..200 {
        let pos = random_point(&mut rng, 10.0);
        w.agents.push(agent(k, 0, pos, rng.range(-3.0, 3.0)));
    }
    w.add_obstacle(Shape::Sphere {
        center: Vec3::ZERO,
        radius: 2.0,
    });
    let mut groups = GroupQueries::new();
    groups.insert(GroupQuery::Separation { radius: 2.0 });
    let reads = Reads {
        percepts: false,
        agent_percepts: false,
        bearing_range: Some(0.0),
        groups,
        headings: false,
    };
    let sense = SenseParams {
        vision_radius: 5.0,
        vision_half_angle: std::f32::consts::PI,
        smell_radius: 0.0,
        occlusion: false,
        ..SenseParams::default()
    };
    let mut rel = Relations::new(1);
    rel.set(0, 0, Some(Category::Kin));
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, 5.0, w.agents.iter().map(|a| a.pos));
    let run = |p: &mut Perception, w: &World| {
        p.run_selective(w, &ag, &Grid::new(), &[sense], &rel, &[reads]);
    };
    // Without the rock (the kernel clears every row and flags it), with it (the general
    // path must unflag the rows it writes), then twice without it again.
    let mut reused = Perception::new();
    for active in [false, true, false, false] {
        w.obstacles[0].active = active;
        run(&mut reused, &w);
        let mut fresh = Perception::new();
        run(&mut fresh, &w);
        for i in 0..w.agents.len() {
            assert_eq!(reused.summaries(i), fresh.summaries(i), "agent {i}");
        }
        let near_rock = (0..w.agents.len())
            .filter(|&i| reused.summaries(i)[Category::Obstacle as usize].count > 0)
            .count();
        if active {
            assert!(near_rock > 10, "{near_rock} agents see the rock");
        } else {
            assert_eq!(near_rock, 0);
        }
    }
}

#[test]
fn the_kin_kernel_perceives_what_the_general_path_does() {
    // A world of one kin-only species without slots is perceived by the kin kernel; naming
    // a second species (with no agent) as `Other` sends it down the general path. Same
    // neighbors, same counts; the sums differ by rounding only.
    let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 2);
    let mut rng = Rng::new(7, 0);
    for k in 0..400 {
        let pos = random_point(&mut rng, 15.0);
        let mut a = agent(k, 0, pos, rng.range(-3.0, 3.0));
        a.pitch = rng.range(-0.5, 0.5);
        a.speed = rng.range(0.0, 2.0);
        w.agents.push(a);
    }
    // Agents near the rock perceive it too (the kernel then runs inside the general
    // fold); the others take the kernel alone.
    w.add_obstacle(Shape::Sphere {
        center: Vec3::new(8.0, 8.0, 8.0),
        radius: 2.0,
    });
    let mut groups = GroupQueries::new();
    groups.insert(GroupQuery::Separation { radius: 2.0 });
    groups.insert(GroupQuery::Mean { radius: 3.0 });
    let reads = Reads {
        percepts: false,
        agent_percepts: false,
        bearing_range: Some(0.0),
        groups,
        headings: true,
    };
    let whole = SenseParams {
        vision_radius: 5.0,
        vision_half_angle: std::f32::consts::PI,
        smell_radius: 0.0,
        occlusion: false,
        ..SenseParams::default()
    };
    let cone_and_smell = SenseParams {
        vision_radius: 5.0,
        vision_half_angle: 2.0,
        smell_radius: 3.5,
        ..whole
    };
    for sense in [whole, cone_and_smell] {
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 2.5, w.agents.iter().map(|a| a.pos));
        let perceive = |rel: &Relations| {
            let mut p = Perception::new();
            p.run_selective(&w, &ag, &Grid::new(), &[sense; 2], rel, &[reads; 2]);
            p
        };
        let mut kernel = Relations::new(2);
        kernel.set(0, 0, Some(Category::Kin));
        kernel.set(0, 1, Some(Category::Kin));
        let mut general = kernel.clone();
        general.set(0, 1, Some(Category::Other));
        let (a, b) = (perceive(&kernel), perceive(&general));
        let close = |x: Vec3, y: Vec3| (x - y).length() <= 1e-4 * (1.0 + y.length());
        let mut perceived = 0;
        for i in 0..w.agents.len() {
            let (ka, kb) = (
                &a.summaries(i)[Category::Kin as usize],
                &b.summaries(i)[Category::Kin as usize],
            );
            assert_eq!((ka.count, ka.seen), (kb.count, kb.seen), "agent {i}");
            perceived += ka.count;
            assert!((ka.nearest_dist - kb.nearest_dist).abs() <= 1e-5 || ka.count == 0);
            assert!(close(ka.centroid, kb.centroid), "agent {i}");
            assert!(close(ka.mean_heading, kb.mean_heading), "agent {i}");
            assert!(close(ka.mean_velocity, kb.mean_velocity), "agent {i}");
            for (ga, gb) in a.group_sums(i).iter().zip(b.group_sums(i)) {
                assert_eq!(ga.n, gb.n, "agent {i}");
                assert!(close(ga.a.into(), gb.a.into()), "agent {i}");
                assert!(close(ga.b.into(), gb.b.into()), "agent {i}");
            }
        }
        assert!(perceived > 400, "{perceived}");
        let near_rock = (0..w.agents.len())
            .filter(|&i| a.summaries(i)[Category::Obstacle as usize].count > 0)
            .count();
        assert!(near_rock > 0 && near_rock < w.agents.len(), "{near_rock}");
    }
}

#[test]
fn the_plain_path_matches_the_general_one() {
    // A kin-only perceiver without slots takes the plain path; naming a third species (with
    // no agent) as `Other` sends it down the general path: the results must be the same.
    let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 3);
    let mut rng = Rng::new(5, 0);
    for k in 0..300 {
        let pos = random_point(&mut rng, 15.0);
        let mut a = agent(k, 0, pos, rng.range(-3.0, 3.0));
        a.pitch = rng.range(-0.5, 0.5);
        a.speed = rng.range(0.0, 2.0);
        w.agents.push(a);
    }
    let sense = SenseParams {
        smell_radius: 6.0,
        vision_radius: 4.0,
        occlusion: false,
        ..SenseParams::default()
    };
    let mut groups = GroupQueries::new();
    groups.insert(GroupQuery::Separation { radius: 2.0 });
    groups.insert(GroupQuery::Mean { radius: 3.0 });
    groups.insert(GroupQuery::Headings { radius: 3.0 });
    let reads = Reads {
        percepts: false,
        agent_percepts: false,
        bearing_range: Some(0.0),
        groups,
        headings: true,
    };
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, 3.0, w.agents.iter().map(|a| a.pos));
    let perceive = |rel: &Relations| {
        let mut p = Perception::new();
        p.run_selective(&w, &ag, &Grid::new(), &[sense; 3], rel, &[reads; 3]);
        p
    };
    let mut plain = Relations::new(3);
    plain.set(0, 0, Some(Category::Kin));
    let mut general = plain.clone();
    general.set(0, 2, Some(Category::Other));
    let (a, b) = (perceive(&plain), perceive(&general));
    for i in 0..w.agents.len() {
        assert_eq!(a.summaries(i), b.summaries(i), "agent {i}");
        assert_eq!(a.group_sums(i), b.group_sums(i), "agent {i}");
    }
    assert!(a.summaries(0)[Category::Kin as usize].count > 0);
}
#[test]
fn the_grid_order_walk_perceives_what_the_agent_order_walk_does() {
    // Fish (with mates, food, rocks and a predator) take the general path, which walks the
    // perceivers in the grid's order. A grid with one entry beyond the agents makes the same
    // perception walk in agent order: every agent's results must be the same, bit for bit.
    let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 1);
    let mut rng = Rng::new(9, 0);
    let point = |rng: &mut Rng| random_point(rng, 18.0);
    for k in 0..400 {
        let species = u16::from(k % 40 == 0);
        let mut a = agent(k, species, point(&mut rng), rng.range(-3.0, 3.0));
        a.pitch = rng.range(-0.5, 0.5);
        a.speed = rng.range(0.0, 2.0);
        if k % 2 == 1 {
            a.attrs.sex = crate::world::Sex::Male;
        }
        w.agents.push(a);
    }
    for _ in 0..60 {
        let p = point(&mut rng);
        w.add_food(p);
    }
    for id in 0..6 {
        w.obstacles.push(crate::world::Obstacle {
            id,
            shape: Shape::Sphere {
                center: point(&mut rng),
                radius: 1.5,
            },
            active: true,
        });
    }
    let sense = SenseParams {
        smell_radius: 6.0,
        vision_radius: 4.0,
        max_percepts: 8,
        ..SenseParams::default()
    };
    let mut rel = rel();
    rel.set_mates(0, true);
    let mut groups = GroupQueries::new();
    groups.insert(GroupQuery::Separation { radius: 2.0 });
    groups.insert(GroupQuery::Mean { radius: 3.0 });
    let reads = Reads {
        groups,
        ..Reads::default()
    };
    let mut fg = Grid::new();
    fg.rebuild(w.bounds, 6.0, w.food.iter().map(|f| f.pos));
    let perceive = |extra: Option<Vec3>| {
        let mut ag = Grid::new();
        let points: Vec<Vec3> = w.agents.iter().map(|a| a.pos).chain(extra).collect();
        ag.rebuild(w.bounds, 6.0, points.into_iter());
        let mut p = Perception::new();
        p.run_selective(&w, &ag, &fg, &[sense; 2], &rel, &[reads; 2]);
        p
    };
    let (by_grid, by_agent) = (perceive(None), perceive(Some(Vec3::splat(19.0))));
    let n = w.agents.len();
    assert!(by_grid.by_grid, "walked in the grid's order");
    assert_ne!(by_grid.slot_of, (0..n as u32).collect::<Vec<_>>());
    assert!(!by_agent.by_grid, "walked in agent order");
    let mut kept = 0;
    for i in 0..n {
        assert_eq!(by_grid.percepts(i), by_agent.percepts(i), "agent {i}");
        assert_eq!(by_grid.summaries(i), by_agent.summaries(i), "agent {i}");
        assert_eq!(by_grid.group_sums(i), by_agent.group_sums(i), "agent {i}");
        kept += by_grid.percepts(i).len();
    }
    assert!(kept > n, "most fish keep percepts");
    // Fed percepts land on the agent they are for, whatever its row.
    let mut fed = by_grid.clone();
    let p = by_grid.percepts(7)[0];
    fed.inject(3, w.agents[3].pos, &[p]);
    assert_eq!(fed.percepts(3), &[p]);
    for i in (0..n).filter(|&i| i != 3) {
        assert_eq!(fed.percepts(i), by_grid.percepts(i), "agent {i}");
    }
}

#[test]
fn few_slots_still_keep_the_nearest_of_each_category() {
    // A kin at 1 m, the shark at 5 m and food at 6 m: however few percepts a species asks
    // for, the predator and the food must not be hidden by the kin in front of them.
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    w.agents.push(agent(1, 0, Vec3::new(0.0, 0.0, 1.0), 0.0));
    w.agents.push(agent(2, 1, Vec3::new(0.0, 0.0, 5.0), 0.0));
    w.add_food(Vec3::new(0.0, 0.0, 6.0));
    for max_percepts in [1, 2] {
        let sense = SenseParams {
            max_percepts,
            ..SenseParams::default()
        };
        let p = run(&w, &rel(), sense);
        let sm = p.summaries(0);
        for c in [Category::Kin, Category::Predator, Category::Food] {
            assert_eq!(sm[c as usize].count, 1);
            let k = sm[c as usize]
                .nearest
                .unwrap_or_else(|| panic!("{c:?} kept with {max_percepts} slots"));
            assert_eq!(p.percepts(0)[k as usize].category, c);
        }
    }
}

#[test]
fn a_species_reading_obstacles_only_keeps_no_agent_percept() {
    // Kin all around and a rock ahead: only the rock is kept; kin are summed, not kept, and
    // no empty record stands in for them.
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    for k in 0..12 {
        w.agents.push(agent(
            k + 1,
            0,
            Vec3::new(0.5 * k as f32 - 3.0, 0.0, 1.0),
            0.0,
        ));
    }
    w.add_obstacle(Shape::Sphere {
        center: Vec3::new(0.0, 0.0, 6.0),
        radius: 1.0,
    });
    let reads = Reads {
        agent_percepts: false,
        ..Reads::default()
    };
    let sense = SenseParams {
        occlusion: false,
        ..SenseParams::default()
    };
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, 5.0, w.agents.iter().map(|a| a.pos));
    let mut p = Perception::new();
    p.run_selective(
        &w,
        &ag,
        &Grid::new(),
        &[sense, sense],
        &rel(),
        &[reads, reads],
    );
    let kept = p.percepts(0);
    assert_eq!(kept.len(), 1, "{kept:?}");
    assert_eq!(kept[0].source, Source::Obstacle(0));
    let sm = p.summaries(0);
    assert_eq!(sm[Category::Kin as usize].count, 12);
    assert_eq!(sm[Category::Kin as usize].nearest, None);
    assert_eq!(sm[Category::Obstacle as usize].nearest, Some(0));
}
