//! The walks agree bit for bit: kin kernel, plain and general paths, grid and agent order.

use super::*;

#[test]
fn the_kin_kernel_perceives_what_the_general_path_does() {
    // A world of one kin-only species without slots is perceived by the kin kernel; naming
    // a second species (with no agent) as `Other` sends it down the general path. Same
    // neighbors, same counts; the sums differ by rounding only.
    let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 2);
    let mut rng = Rng::new(7, 0);
    push_swarm(&mut w, &mut rng, 400, 15.0);
    // Agents near a rock perceive it too (the kernel then runs inside the general fold, and
    // with occlusion the rocks hide some neighbors); the others take the kernel alone.
    w.add_obstacle(Shape::Sphere {
        center: Vec3::new(8.0, 8.0, 8.0),
        radius: 2.0,
    });
    w.add_obstacle(Shape::Box(Aabb::new(
        Vec3::new(-3.0, -1.0, -6.0),
        Vec3::new(3.0, 1.0, 6.0),
    )));
    w.add_obstacle(Shape::Cylinder {
        base: Vec3::new(-9.0, -8.0, 5.0),
        radius: 1.5,
        height: 16.0,
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
    let occluded = |s: SenseParams| SenseParams {
        occlusion: true,
        ..s
    };
    let mut hidden = Vec::new();
    // "Any part" reaches past the centre's range: not the kernel's test, so not the kernel.
    let any_part = SenseParams {
        extent: Extent::AnyPart,
        ..cone_and_smell
    };
    for sense in [
        whole,
        cone_and_smell,
        occluded(whole),
        occluded(cone_and_smell),
        any_part,
    ] {
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 2.5, w.agents.iter().map(|a| a.pos));
        let perceive = |rel: &Relations| {
            let mut p = Perception::new();
            // The second species (no agent) perceives plainly by the kernel: its lanes are
            // there for the first to misuse.
            p.run_selective(&w, &ag, &Grid::new(), &[sense, whole], rel, &[reads; 2]);
            p
        };
        let mut kernel = Relations::new(2);
        for (a, b) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            kernel.set(a, b, Some(Category::Kin));
        }
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
                assert!(close(ga.a, gb.a), "agent {i}");
                assert!(close(ga.b, gb.b), "agent {i}");
            }
        }
        assert!(perceived > 400, "{perceived}");
        hidden.push(perceived);
        let near_rock = (0..w.agents.len())
            .filter(|&i| a.summaries(i)[Category::Obstacle as usize].count > 0)
            .count();
        assert!(near_rock > 0 && near_rock < w.agents.len(), "{near_rock}");
    }
    // The rocks hide neighbors: fewer are perceived with occlusion than without.
    assert!(hidden[2] < hidden[0] && hidden[3] < hidden[1], "{hidden:?}");
}

#[test]
fn the_plain_path_matches_the_general_one() {
    // A kin-only perceiver without slots takes the plain path; naming a third species (with
    // no agent) as `Other` sends it down the general path: the results must be the same.
    let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 3);
    let mut rng = Rng::new(5, 0);
    push_swarm(&mut w, &mut rng, 300, 15.0);
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
    // Its summaries are rebuilt in its row; a row that shrinks to nothing and grows again
    // leaves the rows after it in its list as they were.
    let j = (0..n).find(|&j| !by_grid.percepts(j).is_empty()).unwrap();
    let q = by_grid.percepts(j)[0];
    let c = q.category() as usize;
    fed.inject(j, w.agents[j].pos, &[]);
    assert!(fed.summaries(j).iter().all(Summary::is_none));
    assert!(fed.percepts(j).is_empty());
    fed.inject(j, w.agents[j].pos, &[q, q]);
    assert_eq!(fed.percepts(j), &[q, q]);
    assert_eq!(fed.summaries(j)[c].count, 2);
    assert_eq!(fed.summaries(j)[c].nearest_dist, q.dist);
    for i in (0..n).filter(|&i| i != 3 && i != j) {
        assert_eq!(fed.summaries(i), by_grid.summaries(i), "agent {i}");
        assert_eq!(fed.percepts(i), by_grid.percepts(i), "agent {i}");
    }
    // The same in the last, partial chunk of rows (400 rows: 384 to 399).
    let last = (0..n)
        .find(|&i| by_grid.slot_of[i] as usize == n - 2)
        .unwrap();
    fed.inject(last, w.agents[last].pos, &[q, q, q]);
    assert_eq!(fed.percepts(last), &[q, q, q]);
    let tail = (0..n)
        .find(|&i| by_grid.slot_of[i] as usize == n - 1)
        .unwrap();
    assert!(!by_grid.percepts(tail).is_empty());
    assert_eq!(fed.percepts(tail), by_grid.percepts(tail));
    assert_eq!(fed.summaries(tail), by_grid.summaries(tail));
}

#[test]
fn a_row_keeps_the_categories_its_species_can_perceive_with_the_same_bits() {
    // Plain flockers in a world without obstacles: each row holds the kin summary alone. A rock
    // far from every flocker gives them rows of kin and obstacles, and the same bits.
    let mut w = World::new(Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)), 0.1, 1);
    let mut rng = Rng::new(11, 0);
    push_swarm(&mut w, &mut rng, 300, 12.0);
    let reads = separation_only(2.0);
    let sense = SenseParams {
        vision_radius: 5.0,
        vision_half_angle: 2.0,
        smell_radius: 0.0,
        occlusion: false,
        ..SenseParams::default()
    };
    let mut rel = Relations::new(1);
    rel.set(0, 0, Some(Category::Kin));
    let perceive = |w: &World| {
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, 2.5, w.agents.iter().map(|a| a.pos));
        let mut p = Perception::new();
        p.run_selective(w, &ag, &Grid::new(), &[sense], &rel, &[reads]);
        p
    };
    let compact = perceive(&w);
    let n = w.agents.len();
    assert_eq!(compact.row_room(), n, "one summary a row");
    w.add_obstacle(Shape::Sphere {
        center: Vec3::splat(90.0),
        radius: 1.0,
    });
    let full = perceive(&w);
    assert_eq!(full.row_room(), n * 2, "kin and obstacles");
    // Slots for obstacles, none kept (the rock is out of sight, agents are not kept): the lists
    // keep room for one row's slots, not for every row's.
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, 2.5, w.agents.iter().map(|a| a.pos));
    let mut slotted = Perception::new();
    let reads_rock = Reads {
        percepts: true,
        ..reads
    };
    slotted.run_selective(&w, &ag, &Grid::new(), &[sense], &rel, &[reads_rock]);
    assert!((0..n).all(|i| slotted.percepts(i).is_empty()));
    let [room, slots] = slotted.percept_room();
    assert_eq!(slots, n * sense.slots());
    assert_eq!(room, n.div_ceil(64) * sense.slots());
    for i in 0..n {
        assert_eq!(compact.summaries(i), full.summaries(i), "agent {i}");
        assert_eq!(compact.group_sums(i), full.group_sums(i), "agent {i}");
    }
    let seen: u32 = (0..n)
        .map(|i| compact.summaries(i)[Category::Kin as usize].count)
        .sum();
    assert!(seen > n as u32, "flockers see each other: {seen}");
    // While percepts are fed, every row holds every category.
    let mut fed = Perception::new();
    fed.set_full_rows(true);
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, 2.5, w.agents.iter().map(|a| a.pos));
    let everything = Reads {
        percepts: true,
        agent_percepts: true,
        ..reads
    };
    w.obstacles.clear();
    fed.run_selective(&w, &ag, &Grid::new(), &[sense], &rel, &[everything]);
    assert_eq!(fed.row_room(), n * Category::COUNT);
}

#[test]
fn rows_of_what_a_species_can_perceive_lose_nothing() {
    // Fish (kin, mates, food, a predator, rocks) and their predator on the general path: rows
    // of the categories each can perceive give the summaries and percepts rows of all give.
    let mut w = World::new(Aabb::new(Vec3::splat(-30.0), Vec3::splat(30.0)), 0.1, 2);
    let mut rng = Rng::new(5, 1);
    for k in 0..300 {
        let species = u16::from(k % 25 == 0);
        let mut a = agent(
            k,
            species,
            random_point(&mut rng, 20.0),
            rng.range(-3.0, 3.0),
        );
        a.attrs.sex = if k % 2 == 0 {
            crate::world::Sex::Female
        } else {
            crate::world::Sex::Male
        };
        a.speed = rng.range(0.0, 2.0);
        w.agents.push(a);
    }
    for _ in 0..40 {
        w.add_food(random_point(&mut rng, 20.0));
    }
    for _ in 0..6 {
        w.add_obstacle(Shape::Sphere {
            center: random_point(&mut rng, 18.0),
            radius: 2.0,
        });
    }
    let mut rel = rel();
    rel.set_mates(0, true);
    let sense = SenseParams {
        vision_radius: 6.0,
        smell_radius: 8.0,
        ..SenseParams::default()
    };
    let (masked, full) = (run(&w, &rel, sense), run_full(&w, &rel, sense));
    let n = w.agents.len();
    let fish = (0..n).filter(|&i| w.agents[i].species.0 == 0).count();
    // Fish: food, predator, kin, mate, obstacle (nothing is `Other` to them); predators: food
    // and obstacles.
    assert_eq!(masked.row_room(), fish * 5 + (n - fish) * 2);
    assert_eq!(full.row_room(), n * Category::COUNT);
    // Of those, a row keeps the summaries of what it perceived, whatever its room.
    for p in [&masked, &full] {
        let perceived: usize = (0..n)
            .map(|i| p.summaries(i).iter().filter(|s| !s.is_none()).count())
            .sum();
        assert_eq!(p.summaries_held(), perceived);
        assert!(perceived < masked.row_room(), "{perceived}");
    }
    let mut seen = [0u32; Category::COUNT];
    // A worker's buffer, passed from fish to predator and back, reads what a fresh copy does.
    let mut buf = SummaryBuf::default();
    for i in (0..n).chain((0..n).rev()) {
        assert_eq!(
            *masked.summaries_in(i, &mut buf),
            masked.summaries(i),
            "agent {i}"
        );
    }
    for i in 0..n {
        assert_eq!(masked.summaries(i), full.summaries(i), "agent {i}");
        assert_eq!(masked.percepts(i), full.percepts(i), "agent {i}");
        assert_eq!(masked.group_sums(i), full.group_sums(i), "agent {i}");
        for (c, s) in masked.summaries(i).iter().enumerate() {
            seen[c] += s.count;
        }
    }
    // Every category the rows keep was perceived somewhere.
    for c in [
        Category::Food,
        Category::Predator,
        Category::Kin,
        Category::Mate,
        Category::Obstacle,
    ] {
        assert!(seen[c as usize] > 0, "{c:?}: {seen:?}");
    }
}

#[test]
fn mean_headings_are_kept_only_where_a_species_reads_them() {
    // Fish and predators on the general path: every summary is the same whether its species
    // reads mean headings or not, but for the heading itself, zero where nobody reads it.
    let mut w = World::new(Aabb::new(Vec3::splat(-30.0), Vec3::splat(30.0)), 0.1, 2);
    let mut rng = Rng::new(9, 1);
    push_school(&mut w, &mut rng, 200, 15.0, |k| u16::from(k % 20 == 0));
    let sense = SenseParams {
        vision_radius: 6.0,
        ..SenseParams::default()
    };
    let (ag, _) = grids(&w, sense.query_radius());
    let perceive = |headings: [bool; 2]| {
        let reads = headings.map(|headings| Reads {
            headings,
            ..Reads::default()
        });
        let mut p = Perception::new();
        p.run_selective(&w, &ag, &Grid::new(), &[sense; 2], &rel(), &reads);
        p
    };
    let (none, fish, all) = (
        perceive([false, false]),
        perceive([true, false]),
        perceive([true, true]),
    );
    assert!(none.heading_chunks.iter().all(|h| h.capacity() == 0));
    let mut turned = 0;
    for i in 0..w.agents.len() {
        let full = all.summaries(i);
        for p in [&none, &fish] {
            let kept = p.keep_headings;
            for (a, b) in p.summaries(i).iter().zip(&full) {
                let heading = if kept { b.mean_heading } else { Vec3::ZERO };
                assert_eq!(
                    *a,
                    Summary {
                        mean_heading: heading,
                        ..*b
                    },
                    "agent {i}"
                );
            }
        }
        turned += full.iter().filter(|s| s.mean_heading != Vec3::ZERO).count();
    }
    assert!(turned > 100, "{turned}");
    assert!(fish.keep_headings && !none.keep_headings);
}

#[test]
fn an_obstacle_out_of_range_leaves_every_bit_of_the_kin_sums() {
    // The obstacle grid lists a rock for every cell its bounding sphere, grown by the reach,
    // touches: most agents it lists it for are out of its range. Those perceive exactly what
    // they perceive with no rock in the world, bit for bit; those within range perceive it.
    let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 2);
    let mut rng = Rng::new(11, 0);
    push_swarm(&mut w, &mut rng, 900, 18.0);
    let bare = w.clone();
    let rocks = [
        Shape::Sphere {
            center: Vec3::new(8.0, 8.0, 8.0),
            radius: 1.0,
        },
        Shape::Box(Aabb::new(
            Vec3::new(-3.0, -1.0, -6.0),
            Vec3::new(-1.0, 1.0, -4.0),
        )),
        Shape::Cylinder {
            base: Vec3::new(-9.0, -8.0, 5.0),
            radius: 0.5,
            height: 6.0,
        },
    ];
    for r in rocks {
        w.add_obstacle(r);
    }
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
    let cone_occluded = SenseParams {
        vision_half_angle: 2.0,
        smell_radius: 3.5,
        occlusion: true,
        ..whole
    };
    let mut kin = Relations::new(1);
    kin.set(0, 0, Some(Category::Kin));
    for sense in [whole, cone_occluded] {
        let perceive = |w: &World| {
            let mut ag = Grid::new();
            ag.rebuild(w.bounds, 2.5, w.agents.iter().map(|a| a.pos));
            let mut p = Perception::new();
            p.run_selective(w, &ag, &Grid::new(), &[sense], &kin, &[reads]);
            p
        };
        let (with, without) = (perceive(&w), perceive(&bare));
        let (mut listed, mut in_range) = (0, 0);
        for (i, a) in w.agents.iter().enumerate() {
            let reach = sense.query_radius();
            let near = w
                .obstacles
                .iter()
                .filter(|o| (o.shape.closest_point(a.pos) - a.pos).length() <= reach)
                .count() as u32;
            let (s, t) = (with.summaries(i), without.summaries(i));
            if near > 0 {
                // The whole sphere sees every obstacle within its radius.
                if sense.vision_half_angle == whole.vision_half_angle {
                    assert_eq!(s[Category::Obstacle as usize].count, near, "agent {i}");
                }
                in_range += 1;
                continue;
            }
            // Seen or not, an obstacle within the reach is perceived (smell has no cone).
            assert_eq!(s[Category::Obstacle as usize].count, 0, "agent {i}");
            if !with.obstacles_near(a.pos).is_empty() {
                listed += 1;
            }
            // Every category's summary (the rock's world rows also hold obstacles: none).
            assert_eq!(format!("{s:?}"), format!("{t:?}"), "agent {i}");
            assert_eq!(
                format!("{:?}", with.group_sums(i)),
                format!("{:?}", without.group_sums(i)),
                "agent {i}"
            );
        }
        // Enough of each kind for the test to mean something.
        assert!(
            listed > 150 && in_range > 20,
            "{listed} listed, {in_range} in range"
        );
    }
}

#[test]
fn a_world_the_kernel_serves_alone_copies_no_bodies_and_no_past_positions() {
    // Kin-only flockers that keep no percepts perceive by the kernel alone: the grid-order
    // bodies (`near`), last tick's positions and the grid's inverse are not copied. Listing a second species that
    // keeps agent percepts (with no agent of it) brings both back, and changes no bit.
    let mut w = World::new(Aabb::new(Vec3::splat(-20.0), Vec3::splat(20.0)), 0.1, 2);
    let mut rng = Rng::new(5, 0);
    push_swarm(&mut w, &mut rng, 300, 15.0);
    for a in &mut w.agents {
        a.prev_pos = a.pos - Vec3::new(0.1, 0.0, 0.2);
    }
    let mut rel = Relations::new(2);
    rel.set(0, 0, Some(Category::Kin));
    rel.set(0, 1, Some(Category::Kin));
    rel.set(1, 0, Some(Category::Kin));
    rel.set(1, 1, Some(Category::Kin));
    let plain = separation_only(2.0);
    let sense = SenseParams {
        vision_radius: 5.0,
        vision_half_angle: std::f32::consts::PI,
        ..SenseParams::default()
    };
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, 5.0, w.agents.iter().map(|a| a.pos));
    let fg = Grid::new();
    let perceive = |reads: &[Reads]| {
        let mut p = Perception::new();
        p.run_selective(&w, &ag, &fg, &[sense; 2], &rel, reads);
        p
    };
    let alone = perceive(&[plain; 2]);
    assert!(alone.kernel.iter().all(|&k| k));
    assert!(alone.near.is_empty() && alone.prev_pos.is_empty());
    // Nor the grid's inverse (the walk read the grid's own), nor reaches (no species has a
    // bounded neighborhood).
    assert!(alone.slot_of.is_empty() && alone.reaches.is_empty());
    assert_eq!(alone.prev_pos(3), None);
    let beside = perceive(&[plain, Reads::default()]);
    assert_eq!(beside.kernel, [true, false]);
    assert_eq!(beside.near.len(), w.agents.len());
    let mut kin = 0;
    for (i, a) in w.agents.iter().enumerate() {
        assert_eq!(beside.prev_pos(i), Some(a.prev_pos), "agent {i}");
        assert_eq!(alone.summaries(i), beside.summaries(i), "agent {i}");
        assert_eq!(alone.group_words(i), beside.group_words(i), "agent {i}");
        kin += alone.summaries(i)[Category::Kin as usize].count;
    }
    assert!(kin > 300, "kin perceived: {kin}");
    // An agent of a species without senses perceives with the defaults, which keep agent
    // percepts: its past position is held.
    let mut stray = w.clone();
    stray.agents[7].species = SpeciesId(5);
    let mut ag = Grid::new();
    ag.rebuild(stray.bounds, 5.0, stray.agents.iter().map(|a| a.pos));
    let mut p = Perception::new();
    p.run_selective(&stray, &ag, &fg, &[sense; 2], &rel, &[plain; 2]);
    assert_eq!(p.prev_pos(7), Some(stray.agents[7].prev_pos));
    assert_eq!(p.near.len(), stray.agents.len());
}
