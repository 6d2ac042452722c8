//! What is kept of what is perceived (the nearest of each category first), the summaries and group sums, and injected percepts.

use super::*;

#[test]
fn injected_percepts_replace_an_agents_and_rebuild_its_summaries() {
    let mut w = World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), 0.1, 1);
    w.agents.push(agent(0, 0, Vec3::ZERO, 0.0));
    w.add_food(Vec3::new(0.0, 0.0, 3.0));
    let mut p = run_full(&w, &rel(), SenseParams::default());
    assert_eq!(p.summaries(0)[Category::Food as usize].count, 1);
    // A fed percept's bearing, elevation and size are its own, whatever its offset says.
    let fed = |category, sense, offset: Vec3| {
        let mut p = Percept::new(
            Source::Injected,
            category,
            sense,
            offset,
            offset.length(),
            1.5,
        );
        (p.bearing, p.elevation) = (0.25, -0.125);
        p
    };
    let percepts = [
        fed(Category::Predator, Sense::Smell, Vec3::new(0.0, 0.0, 12.0)),
        fed(Category::Mate, Sense::Vision, Vec3::new(0.0, 0.0, 2.0)),
        fed(Category::Kin, Sense::Vision, Vec3::new(0.0, 0.0, 4.0)),
    ];
    p.inject(0, Vec3::new(1.0, 0.0, 0.0), &percepts);
    let sm = p.summaries(0);
    assert_eq!(p.percepts(0), percepts);
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
        assert_eq!(near.category(), c);
        assert!((near.dist - d).abs() < 1e-5, "{c:?} {}", near.dist);
    }
    // They took the places of the two farthest kin: the nearest 14 kin stay (0.2 … 2.8 m).
    let far_kin = kept
        .iter()
        .filter(|q| q.category() == Category::Kin)
        .map(|q| q.dist)
        .fold(0.0, f32::max);
    assert!((far_kin - 2.8).abs() < 1e-5, "{far_kin}");
    assert_eq!(
        kept.iter()
            .filter(|q| q.category() == Category::Kin)
            .count(),
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
    let mut p = run_full(&w, &rel(), sense);
    let fed = |category, offset: Vec3| {
        Percept::new(
            Source::Injected,
            category,
            Sense::Vision,
            offset,
            offset.length(),
            1.0,
        )
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
    assert_eq!(p.percepts(0)[k].category(), Category::Predator);
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
    p.set_full_rows(true);
    let sense = SenseParams::default();
    p.run_selective(
        &w,
        &ag,
        &Grid::new(),
        &[sense, sense],
        &rel(),
        &[reads, reads],
    );
    let fed = Percept::new(
        Source::Injected,
        Category::Food,
        Sense::Vision,
        Vec3::Z,
        1.0,
        0.0,
    );
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
    let reads = separation_only(2.0);
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
fn a_reused_buffer_keeps_what_a_fresh_one_does_as_agents_come_and_go() {
    // The kept percepts of 64 rows share a list that keeps its room from tick to tick: rows
    // that keep more than the tick before, a school that shrinks (a partial last chunk) and
    // grows again, and a quiet tick (nothing in sight) must read back as a fresh perception.
    let mut w = World::new(Aabb::new(Vec3::splat(-30.0), Vec3::splat(30.0)), 0.1, 1);
    let mut rng = Rng::new(5, 0);
    let sense = SenseParams {
        vision_radius: 4.0,
        max_percepts: 8,
        ..SenseParams::default()
    };
    let reads = Reads::default();
    let mut reused = Perception::new();
    for (n, spread) in [
        (400, 12.0),
        (130, 12.0),
        (400, 6.0),
        (400, 28.0),
        (257, 8.0),
    ] {
        w.agents.clear();
        for k in 0..n {
            let pos = random_point(&mut rng, spread);
            w.agents.push(agent(k, 0, pos, rng.range(-3.0, 3.0)));
        }
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 4.0, w.agents.iter().map(|a| a.pos));
        let run = |p: &mut Perception| {
            p.run_selective(&w, &ag, &Grid::new(), &[sense], &rel(), &[reads]);
        };
        run(&mut reused);
        let mut fresh = Perception::new();
        run(&mut fresh);
        let mut kept = 0;
        for i in 0..n as usize {
            assert_eq!(
                reused.percepts(i),
                fresh.percepts(i),
                "{n} agents, agent {i}"
            );
            assert_eq!(
                reused.summaries(i),
                fresh.summaries(i),
                "{n} agents, agent {i}"
            );
            kept += fresh.percepts(i).len();
        }
        assert!(kept > 0, "{n} agents keep percepts");
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
            assert_eq!(p.percepts(0)[k as usize].category(), c);
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
    assert_eq!(kept[0].source(), Source::Obstacle(0));
    let sm = p.summaries(0);
    assert_eq!(sm[Category::Kin as usize].count, 12);
    assert_eq!(sm[Category::Kin as usize].nearest, None);
    assert_eq!(sm[Category::Obstacle as usize].nearest, Some(0));
}

#[test]
fn kept_percepts_read_back_their_sizes_and_the_bearings_their_species_reads() {
    // Fish (bearings within 2 m), their predators (every bearing), food and rocks; agents of
    // several sizes and headings. A kept percept is held without its size and bearing: both
    // read back as the walk would have made them, in the grid's order and in agent order (a
    // kin-only species the kernel serves sends the walk to agent order).
    for kernel in [false, true] {
        let mut w = World::new(Aabb::new(Vec3::splat(-30.0), Vec3::splat(30.0)), 0.1, 3);
        let mut rng = Rng::new(13, 2);
        for k in 0..240 {
            let species = if k % 30 == 0 {
                1
            } else if kernel && k % 3 == 0 {
                2
            } else {
                0
            };
            let mut a = agent(
                k,
                species,
                random_point(&mut rng, 12.0),
                rng.range(-3.0, 3.0),
            );
            a.pitch = rng.range(-0.6, 0.6);
            a.size = Vec3::new(
                rng.range(0.1, 1.0),
                rng.range(0.1, 1.0),
                rng.range(0.5, 2.0),
            );
            w.agents.push(a);
        }
        for _ in 0..30 {
            w.add_food(random_point(&mut rng, 12.0));
        }
        for _ in 0..4 {
            w.add_obstacle(Shape::Sphere {
                center: random_point(&mut rng, 12.0),
                radius: rng.range(0.5, 2.0),
            });
        }
        let species = if kernel { 3 } else { 2 };
        let mut rel = Relations::new(species);
        rel.set(0, 0, Some(Category::Kin));
        rel.set(0, 1, Some(Category::Predator));
        rel.set(1, 0, Some(Category::Food));
        rel.set_eats_items(0, true);
        if kernel {
            for s in 0..3 {
                rel.set(2, s, Some(Category::Kin));
            }
        }
        let sense = SenseParams {
            vision_radius: 6.0,
            max_percepts: 8,
            ..SenseParams::default()
        };
        let reads = [
            Reads {
                bearing_range: Some(2.0),
                ..Reads::default()
            },
            Reads::default(),
            separation_only(1.0),
        ];
        let (ag, fg) = grids(&w, sense.query_radius());
        let mut p = Perception::new();
        let senses = [sense; 3];
        p.run_selective(&w, &ag, &fg, &senses[..species], &rel, &reads[..species]);
        assert_eq!(p.by_grid, !kernel);
        let (mut with, mut without, mut sources) = (0, 0, [0; 3]);
        for (i, a) in w.agents.iter().enumerate() {
            let nearest: Vec<u16> = p.summaries(i).iter().filter_map(|s| s.nearest).collect();
            let range = reads[a.species.0 as usize].bearing_range;
            for (k, q) in p.percepts(i).iter().enumerate() {
                let size = match q.source() {
                    Source::Agent(j) => w.agents[j as usize].diagonal(),
                    Source::Obstacle(j) => w.obstacles[j as usize].shape.diagonal(),
                    _ => 0.0,
                };
                sources[match q.source() {
                    Source::Agent(_) => 0,
                    Source::Food(_) => 1,
                    _ => 2,
                }] += 1;
                assert_eq!(q.size.to_bits(), size.to_bits(), "agent {i}: {q:?}");
                let wanted = range.is_none_or(|r| {
                    nearest.contains(&(k as u16))
                        || q.category() == Category::Obstacle
                        || q.dist <= r
                });
                let (b, e) = if wanted {
                    crate::frame::bearing_elevation(a.yaw, a.pitch, q.offset)
                } else {
                    (0.0, 0.0)
                };
                assert_eq!(
                    [q.bearing, q.elevation].map(f32::to_bits),
                    [b, e].map(f32::to_bits),
                    "agent {i}: {q:?}"
                );
                if wanted {
                    with += 1;
                } else {
                    without += 1;
                }
            }
        }
        assert!(with > 100 && without > 100, "{with} {without}");
        assert!(sources.iter().all(|&n| n > 10), "{sources:?}");
    }
}
