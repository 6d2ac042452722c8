//! Unit tests of squads at run time: the leader's progress and the members' slots, and the
//! terrain as the viewer reads it.

use super::*;
use crate::formation::{Formation, FormationShape, Plan, TaskClass};
use glam::Vec2;

/// A flat 40 × 40 terrain of 1 m cells and a squad of three in a line (spacing 2) whose
/// plan runs from (5.5, 5.5) east to (30.5, 5.5), then south to (30.5, 30.5).
fn squad() -> Squad {
    let terrain = Arc::new(Terrain::from_heights(
        40,
        40,
        1.0,
        Vec2::ZERO,
        vec![0.0; 1600],
    ));
    let grid = Arc::new(CostGrid::open(40, 40, 1.0, Vec2::ZERO));
    let formations = vec![Formation::new(&FormationShape::Line, 3, 2.0).unwrap()];
    let key = |c: usize, r: usize, i: usize| crate::formation::KeyPoint {
        cell: crate::terrain::Cell::new(c, r),
        pos: Vec2::new(c as f32 + 0.5, r as f32 + 0.5),
        formation: 0,
        path_index: i,
    };
    let key_points = vec![key(5, 5, 0), key(30, 5, 25), key(30, 30, 50)];
    let plan = Plan {
        leader: 0,
        leader_cells: Vec::new(),
        leader_path: Vec::new(),
        formation_along: Vec::new(),
        member_paths: crate::formation::member_paths(&key_points, &formations, 0),
        held: vec![0; key_points.len()],
        key_points,
        transitions: Vec::new(),
        tried: vec![(0.1, 0.9)],
        cost: 50.0,
        score: 50.0,
        expanded: 0,
    };
    let ground = Ground {
        terrain,
        grids: vec![Some(grid)],
    };
    let setup = SquadSetup {
        species: 0,
        formations,
        leader: 0,
        task: TaskClass::MayChangeRarely,
        planning: Default::default(),
        start: Vec2::new(5.5, 5.5),
        goal: Vec2::new(30.5, 30.5),
        plan,
    };
    Squad::new(0, &setup, vec![AgentId(0), AgentId(1), AgentId(2)], &ground)
}

#[test]
fn progress_follows_the_leader_along_the_key_points() {
    let mut s = squad();
    let keys: Vec<Vec2> = s.plan.key_points.iter().map(|k| k.pos).collect();
    assert_eq!(keys.len(), 3, "{keys:?}");
    let len0 = keys[0].distance(keys[1]);
    // Halfway along the first leg, 1 m off the path: projected, not measured from the path.
    s.update_progress(keys[0].lerp(keys[1], 0.5) + Vec2::new(0.0, 1.0));
    assert_eq!(s.progress.leg, 0);
    assert!((s.progress.t - 0.5).abs() < 1e-5);
    assert!((s.distance_done() - 0.5 * len0).abs() < 1e-4);
    // Followers sit on their member paths at the same fraction.
    for m in 1..3 {
        assert_eq!(s.slot(m), s.plan.member_paths[m].position_at(0, 0.5));
    }
    assert_eq!(s.slot(0), keys[0].lerp(keys[1], 0.5));
    // Progress never goes back on a leg.
    s.update_progress(keys[0]);
    assert!((s.progress.t - 0.5).abs() < 1e-5);
    // 3 m ahead along the path, around the corner when it is near.
    assert_eq!(
        s.point_ahead(3.0),
        keys[0].lerp(keys[1], 0.5) + (keys[1] - keys[0]).normalize() * 3.0
    );
    s.update_progress(keys[1] - Vec2::new(1.0, 0.0));
    let ahead = s.point_ahead(3.0);
    assert!(
        (ahead - (keys[1] + (keys[2] - keys[1]).normalize() * 2.0)).length() < 1e-4,
        "{ahead}"
    );
    // Cutting the corner: nearer the second leg and close to the key point, the leader is on it.
    s.update_progress(keys[1] + Vec2::new(-0.3, 1.5));
    assert_eq!(s.progress.leg, 1);
    assert!(s.progress.t > 0.0 && s.progress.t < 0.1);
    assert!(!s.progress.finished);
    // Within a metre of the goal it has arrived: slots are the final ones.
    s.update_progress(keys[2] - Vec2::new(0.0, 0.8));
    assert!(s.progress.finished);
    for m in 0..3 {
        assert_eq!(s.slot(m), s.final_slot(m));
    }
    assert_eq!(s.point_ahead(3.0), keys[2]);
}

#[test]
fn big_terrains_are_downsampled_for_the_viewer() {
    let (cols, rows) = (1030, 520);
    let heights = (0..cols * rows).map(|i| (i % cols) as f32).collect();
    let terrain = Terrain::from_heights(cols, rows, 1.0, Vec2::new(-5.0, 7.0), heights);
    let mut grid = CostGrid::open(cols, rows, 1.0, Vec2::new(-5.0, 7.0));
    grid.blocked[cols + 5] = true; // cell (5, 1): in block (1, 0) when k = 3
    let squads = Squads {
        ground: Some(Arc::new(Ground {
            terrain: Arc::new(terrain),
            grids: vec![Some(Arc::new(grid))],
        })),
        ..Squads::default()
    };
    let v = record::terrain_json(&squads);
    // 1030 × 520 > 512²; halved it is still 515 × 260 = 133,900 ≤ 262,144: k = 2.
    assert_eq!(v["cols"], 515);
    assert_eq!(v["rows"], 260);
    assert_eq!(v["cell"], 2.0);
    let h = v["heights"].as_array().unwrap();
    assert_eq!(h.len(), 515 * 260);
    // Block 1 covers cells 2–3 (centres at heights 2 and 3); its centre is between them.
    assert_eq!(h[1], 2.5);
    let b = v["blocked"].as_array().unwrap();
    assert_eq!(b[2], 1);
    assert_eq!(b.iter().filter(|x| x.as_u64() == Some(1)).count(), 1);
    assert_eq!(record::plans_json(&squads), serde_json::json!([]));
    assert_eq!(
        record::terrain_json(&Squads::default()),
        serde_json::Value::Null
    );
}
