//! The bounded kin neighborhood (`SenseParams::neighbors`): the nearest `n` kin, found by the
//! outward walk, against a brute force; everything else still perceived within range; the
//! same bits wherever the walk starts, and the same neighbors whatever the grid's cells.

use super::*;

/// 600 kin in a ball and 12 predators among them.
fn school() -> World {
    let mut w = World::new(Aabb::new(Vec3::splat(-30.0), Vec3::splat(30.0)), 0.1, 2);
    let mut rng = Rng::new(11, 0);
    push_school(&mut w, &mut rng, 612, 12.0, |k| u16::from(k % 51 == 50));
    w
}

fn bounded(n: u32) -> SenseParams {
    SenseParams {
        vision_radius: 4.0,
        smell_radius: 7.0,
        occlusion: false,
        neighbors: Some(n),
        ..SenseParams::default()
    }
}

fn perceive(w: &World, sense: SenseParams, cell: f32, p: &mut Perception) {
    let mut ag = Grid::new();
    ag.rebuild(w.bounds, cell, w.agents.iter().map(|a| a.pos));
    p.run(
        w,
        &ag,
        &Grid::new(),
        &[sense, SenseParams::default()],
        &rel(),
    );
}

#[test]
fn a_bound_perceives_the_nearest_kin_and_every_predator_in_range() {
    let w = school();
    let sense = bounded(9);
    let mut p = Perception::new();
    perceive(&w, sense, sense.query_radius(), &mut p);
    // Each row's reach is held for the next walk.
    assert_eq!(p.reaches.len(), w.agents.len());
    let (mut bounded_some, mut sparse_some) = (false, false);
    for (i, me) in w.agents.iter().enumerate() {
        if me.species.0 != 0 {
            continue;
        }
        let mut kin: Vec<(f32, Vec3)> = Vec::new();
        let mut predators = 0;
        for (j, o) in w.agents.iter().enumerate() {
            let d = (o.pos - me.pos).length();
            if j == i || d > sense.smell_radius {
                continue;
            }
            if o.species.0 == 0 {
                kin.push((d, o.pos));
            } else {
                predators += 1;
            }
        }
        kin.sort_by(|a, b| a.0.total_cmp(&b.0));
        let in_range = kin.len();
        kin.truncate(9);
        let sm = &p.summaries(i);
        let k = &sm[Category::Kin as usize];
        assert_eq!(
            k.count as usize,
            kin.len(),
            "agent {i}: {in_range} kin in range"
        );
        let centroid = kin.iter().map(|c| c.1).sum::<Vec3>() / kin.len().max(1) as f32;
        if !kin.is_empty() {
            assert!((k.centroid - centroid).length() < 1e-4, "agent {i}");
            assert!((k.nearest_dist - kin[0].0).abs() < 1e-5, "agent {i}");
        }
        assert_eq!(
            sm[Category::Predator as usize].count,
            predators,
            "agent {i}: every predator within smell"
        );
        bounded_some |= in_range > 9;
        sparse_some |= in_range < 9;
    }
    // The world has both: perceivers the bound cuts, and perceivers with fewer kin in range.
    assert!(bounded_some && sparse_some);
}

#[test]
fn a_bound_gives_the_same_bits_whatever_the_cells_and_the_start() {
    let w = school();
    let sense = bounded(12);
    let bits = |p: &Perception| {
        (0..w.agents.len())
            .flat_map(|i| {
                p.summaries(i)
                    .iter()
                    .flat_map(|s| {
                        let c = s.centroid.to_array().map(f32::to_bits);
                        let h = s.mean_velocity.to_array().map(f32::to_bits);
                        [s.count, s.seen, c[0], c[1], c[2], h[0], h[1], h[2]]
                    })
                    .collect::<Vec<_>>()
            })
            .collect::<Vec<_>>()
    };
    let mut first = Perception::new();
    perceive(&w, sense, sense.query_radius(), &mut first);
    let want = bits(&first);
    // Again with the hints the first walk left (a different start), and with other cells.
    perceive(&w, sense, sense.query_radius(), &mut first);
    assert!(
        bits(&first) == want,
        "started from last walk's reach: other bits"
    );
    // Other cells put the agents in another order, so the sums round differently; the
    // neighbors are the same.
    for cell in [1.0, 2.5, 20.0] {
        let mut p = Perception::new();
        perceive(&w, sense, cell, &mut p);
        for i in 0..w.agents.len() {
            for (a, b) in p.summaries(i).iter().zip(first.summaries(i)) {
                assert_eq!(
                    (a.count, a.seen),
                    (b.count, b.seen),
                    "cells of {cell}, agent {i}"
                );
                let off = (a.centroid - b.centroid).length();
                assert!(off < 1e-4, "cells of {cell}, agent {i}: {off}");
            }
        }
    }
}

#[test]
fn without_a_bound_every_kin_in_range_is_perceived() {
    let w = school();
    let sense = SenseParams {
        neighbors: None,
        ..bounded(9)
    };
    let mut p = Perception::new();
    perceive(&w, sense, sense.query_radius(), &mut p);
    let most = (0..w.agents.len())
        .map(|i| p.summaries(i)[Category::Kin as usize].count)
        .max();
    assert!(most > Some(9), "{most:?}");
}

#[test]
fn a_bound_sums_the_others_in_the_agent_grids_order() {
    // The others (here predators, a third of the agents) are walked in a grid of their own;
    // their sums must be those of the agent grid's order, bit for bit, whatever its cells:
    // the general walk's order, the same sums as without a bound.
    let mut w = World::new(Aabb::new(Vec3::splat(-30.0), Vec3::splat(30.0)), 0.1, 2);
    let mut rng = Rng::new(5, 0);
    push_school(&mut w, &mut rng, 900, 12.0, |k| u16::from(k % 3 == 2));
    let sense = bounded(8);
    let r2 = sense.smell_radius * sense.smell_radius;
    let mut checked = 0;
    for cell in [1.5, 4.0, sense.query_radius(), 25.0] {
        let mut ag = Grid::new();
        ag.rebuild(w.bounds, cell, w.agents.iter().map(|a| a.pos));
        let mut p = Perception::new();
        p.run(
            &w,
            &ag,
            &Grid::new(),
            &[sense, SenseParams::default()],
            &rel(),
        );
        for (i, me) in w.agents.iter().enumerate() {
            if me.species.0 != 0 {
                continue;
            }
            let c = Vec3A::from(me.pos);
            let (mut n, mut sum) = (0u32, Vec3A::ZERO);
            for (k, &pos) in ag.positions().iter().enumerate() {
                let j = ag.entries()[k] as usize;
                if w.agents[j].species.0 == 1 && (pos - c).length_squared() <= r2 {
                    n += 1;
                    sum += pos;
                }
            }
            let sm = &p.summaries(i)[Category::Predator as usize];
            assert_eq!(sm.count, n, "cells of {cell}, agent {i}");
            if n > 0 {
                let want = Vec3::from(sum / n as f32).to_array().map(f32::to_bits);
                let got = sm.centroid.to_array().map(f32::to_bits);
                assert_eq!(got, want, "cells of {cell}, agent {i}");
                checked += 1;
            }
        }
    }
    assert!(checked > 1000, "{checked}");
}
