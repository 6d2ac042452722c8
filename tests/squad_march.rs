//! End to end: `scenarios/squad_march.ron`, seed 004's worked example (five members in a
//! triangle, K1 = 0.1, K2 = 0.9, flag = 1) marching across the shipped valley through the slot
//! canyon. Measures the formation error (mean distance of the followers from their slots), checks
//! that every member reaches its goal slot, walks on the ground and never stands on a blocked
//! cell, and that the squad files through the canyon as a column.

use glam::Vec2;
use shoal::events::Event;
use shoal::scenario::{Overrides, Run, Scenario};
use std::path::Path;

/// Mean follower distance from its slot over the whole run must stay below this (m). The slot
/// spacing is 4 m; followers lag a little on curves and where an interpolated slot lies on a
/// blocked cell (the canyon exit) and they take the nearest free cell instead.
const MEAN_ERROR_LIMIT: f32 = 0.5;
/// No follower is ever farther than this from its slot (m).
const MAX_ERROR_LIMIT: f32 = 4.0;
/// Every member ends within this distance of its final slot (m).
const ARRIVAL_RADIUS: f32 = 1.0;

fn load() -> Run {
    let sc =
        Scenario::load(Path::new("scenarios/squad_march.ron")).unwrap_or_else(|e| panic!("{e}"));
    Run::new(sc, Overrides::default())
}

#[test]
fn the_squad_marches_in_formation_through_the_canyon_to_its_goal() {
    let mut run = load();
    let grid = run.squads.squads[0].grid.clone();
    let terrain = run.world.terrain.clone().expect("terrain");
    let names: Vec<String> = {
        let sq = &run.squads.squads[0];
        sq.plan
            .transitions
            .iter()
            .map(|t| {
                format!(
                    "{}->{}",
                    sq.formations[sq.formation_of(t.from)].name(),
                    sq.formations[sq.formation_of(t.to)].name()
                )
            })
            .collect()
    };
    // The triangle does not fit the canyon: a column through it, the triangle again after.
    assert_eq!(names, ["triangle->column", "column->triangle"]);
    let members = run.squads.squads[0].members.clone();
    assert_eq!(members.len(), 5);
    let (mut sum, mut samples, mut max) = (0.0f64, 0u64, 0.0f32);
    let mut in_canyon_as_column = 0u32;
    let mut errors = Vec::new();
    let mut finished_at = None;
    while !run.finished() {
        run.step();
        for e in &run.pipeline.events {
            if let Event::ScriptError { message, .. } = e {
                errors.push(message.clone());
            }
        }
        let sq = &run.squads.squads[0];
        if sq.progress.finished && finished_at.is_none() {
            finished_at = Some(run.world.time());
        }
        let mut xs = Vec::new();
        for (m, id) in members.iter().enumerate() {
            let a = run.world.agent(*id).expect("nobody dies");
            let p = Vec2::new(a.pos.x, a.pos.z);
            let cell = grid.cell_of(p).expect("on the terrain");
            assert!(
                !grid.blocked[grid.index(cell)],
                "member {m} on blocked cell {cell:?} at t = {}",
                run.world.time()
            );
            assert!(
                (a.pos.y - terrain.height_at(p.x, p.y)).abs() < 1e-4,
                "on the ground"
            );
            assert!(a.pitch.abs() < 0.8 + 1e-6, "pitch within the body's limit");
            if m != sq.leader {
                let d = p.distance(sq.slot(m));
                sum += f64::from(d);
                samples += 1;
                max = max.max(d);
            }
            xs.push(p);
        }
        // Deep in the canyon (rows 110–128, 4 m wide) the five walk single file.
        if xs.iter().all(|p| (220.0..256.0).contains(&p.y)) {
            assert!(xs.iter().all(|p| (118.0..122.0).contains(&p.x)), "{xs:?}");
            in_canyon_as_column += 1;
        }
    }
    let sq = &run.squads.squads[0];
    let mean = (sum / samples as f64) as f32;
    let finals: Vec<f32> = members
        .iter()
        .enumerate()
        .map(|(m, id)| {
            let a = run.world.agent(*id).unwrap();
            Vec2::new(a.pos.x, a.pos.z).distance(sq.final_slot(m))
        })
        .collect();
    eprintln!(
        "squad_march: path {:.0} m, leader arrived at t = {:.1} s; formation error mean {mean:.3} m, max {max:.2} m \
         (runtime's own: {:.3} m); final distances {finals:.2?} m; blocked steps {}, stuck {}, detour ticks {}, re-plans {}; \
         {in_canyon_as_column} ticks with the whole squad in the canyon",
        sq.plan
            .key_points
            .windows(2)
            .map(|w| w[0].pos.distance(w[1].pos))
            .sum::<f32>(),
        finished_at.unwrap_or(f64::NAN),
        sq.stats.mean_error(),
        sq.stats.blocked_steps,
        sq.stats.stuck,
        sq.stats.detour_ticks,
        sq.stats.replans,
    );
    assert!(errors.is_empty(), "{errors:?}");
    assert!(finished_at.is_some(), "the leader reached the goal");
    assert!(mean < MEAN_ERROR_LIMIT, "mean formation error {mean}");
    assert!(max < MAX_ERROR_LIMIT, "largest formation error {max}");
    assert!((sq.stats.mean_error() - mean).abs() < 1e-3);
    for (m, d) in finals.iter().enumerate() {
        assert!(
            *d < ARRIVAL_RADIUS,
            "member {m} ended {d} m from its goal slot"
        );
    }
    // No step ever had to be cut back at a blocked cell: the members steered clear by themselves.
    assert_eq!(sq.stats.blocked_steps, 0);
    assert_eq!(run.squads.blocked_steps, 0);
    assert!(
        in_canyon_as_column > 100,
        "the squad went through the canyon"
    );
    // At the goal everyone holds.
    let hold = run.scenario.species.species[0]
        .behavior_index("hold")
        .unwrap();
    for id in &members {
        assert_eq!(run.world.agent(*id).unwrap().mind.current, hold);
    }
}

#[test]
fn squad_runs_are_bit_identical_whatever_the_thread_count() {
    let positions = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let sc = Scenario::load(Path::new("scenarios/squad_march.ron")).unwrap();
            let mut run = Run::new(
                sc,
                Overrides {
                    duration: Some(30.0),
                    ..Overrides::default()
                },
            );
            while !run.finished() {
                run.step();
            }
            run.world
                .agents
                .iter()
                .map(|a| {
                    (
                        a.pos.to_array().map(f32::to_bits),
                        a.yaw.to_bits(),
                        a.pitch.to_bits(),
                    )
                })
                .collect::<Vec<_>>()
        })
    };
    assert_eq!(positions(1), positions(3));
}
