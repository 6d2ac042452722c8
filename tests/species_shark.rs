//! `behaviors/shark.ron`: patrol, stalk by smell, hunt with seed 002's linear prediction, rest
//! when fed, avoid rocks.

mod common;

use common::{behaviors, folder, load, Change, Sim};
use glam::Vec3;
use shoal::events::{Cause, Event};
use shoal::steering::Steer;
use shoal::world::{Aabb, AgentId, Shape};
use std::f32::consts::{FRAC_PI_2, PI};

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Prey that swims straight on at 1.2 units/s and never reacts (named like one of the shark's
/// prey species).
const PREY: &str = r#"Species(
    name: "sardine",
    body: (size: (0.12, 0.2, 0.5), limits: (max_speed: 2.0)),
    relations: (see_others: false),
    initial: "cruise",
    behaviors: [Behavior(name: "cruise", priority: 1, steer: Cruise(speed: 0.6))],
)
"#;

fn world() -> (Sim, tempfile::TempDir) {
    let dir = folder(&[("sardine.ron", PREY)]);
    let root = behaviors();
    let sim = Sim::new(
        vec![
            load(&root.join("shark.ron"), &root),
            load(&dir.path().join("sardine.ron"), dir.path()),
        ],
        Aabb::new(v(-60.0, 0.0, -60.0), v(60.0, 40.0, 60.0)),
    );
    (sim, dir)
}

fn is(c: &Change, from: &str, to: &str, cause: Cause, condition: &str) {
    assert_eq!(
        (
            c.from.as_str(),
            c.to.as_str(),
            c.cause,
            c.condition.as_deref()
        ),
        (from, to, cause, Some(condition)),
        "{c:?}"
    );
}

fn hungry_shark(sim: &mut Sim, pos: Vec3, yaw: f32, hunger: f32) -> AgentId {
    let id = sim.spawn("shark", pos, yaw);
    sim.set_hunger(id, hunger);
    id
}

#[test]
fn a_sated_shark_patrols() {
    let (mut sim, _dir) = world();
    let shark = sim.spawn("shark", v(0.0, 20.0, 0.0), 0.0);
    assert_eq!(sim.behavior(shark), "patrol");
    sim.run(100);
    assert!(sim.changes(shark).is_empty(), "{:?}", sim.changes(shark));
    assert!(sim.agent(shark).pos.distance(v(0.0, 20.0, 0.0)) > 5.0);
}

#[test]
fn hunt_aims_at_the_linear_prediction_catches_then_rests_until_digested() {
    let (mut sim, _dir) = world();
    let shark = hungry_shark(&mut sim, v(0.0, 20.0, 0.0), 0.0, 0.6);
    // Prey crossing ahead, from the shark's right to its left (+X is left).
    let prey = sim.spawn("sardine", v(-3.0, 20.0, 8.0), -FRAC_PI_2);
    sim.step();
    is(
        &sim.last_change(shark),
        "patrol",
        "hunt",
        Cause::Interrupted,
        "latched on (hunger > 0.5) until (hunger < 0.3) and sees food",
    );
    // Seed 002: the shark seeks X_{t+1} = 2·X_t − X_{t−1}, not where the prey is now.
    for _ in 0..3 {
        let (me, now, before) = {
            let (s, p) = (sim.agent(shark), sim.agent(prey));
            (s.pos, p.pos, p.prev_pos)
        };
        assert_ne!(now, before, "the prey moves");
        sim.step();
        let aim = 2.0 * now - before;
        let Steer::Velocity(vel) = sim.agent(shark).mind.last_steer else {
            panic!("{:?}", sim.agent(shark).mind.last_steer)
        };
        let expected = (aim - me).normalize() * 5.5;
        assert!((vel - expected).length() < 1e-3, "{vel} vs {expected}");
        let naive = (now - me).normalize() * 5.5;
        assert!((vel - naive).length() > 1e-2, "prediction leads the prey");
    }
    sim.run_until(200, |s| !s.alive(prey)).expect("caught");
    assert!(sim.log.iter().any(|(_, e)| matches!(
        e,
        Event::Catch { agent, prey: p } if *agent == shark && *p == prey
    )));
    assert_eq!(sim.pipeline.stats.catches, 1);
    // The catch is a meal: n_e = 0.8 + 1 → H = 1 − 1.8/2 = 0.1: it rests.
    sim.step();
    is(
        &sim.last_change(shark),
        "hunt",
        "rest",
        Cause::Completed,
        "hunger < 0.3 or not (sees food)",
    );
    assert!((sim.agent(shark).drives.hunger - 0.1).abs() < 1e-3);
    sim.run(40);
    assert_eq!(sim.behavior(shark), "rest");
    assert!(sim.agent(shark).speed < 1.0, "resting cruises slowly");
    // 30 s of digestion later (r = 1 − 0.02·30 = 0.4): H = 1 − 1.8·0.4/2 = 0.64.
    sim.agent_mut(shark).drives.since_meal += 30.0;
    sim.step();
    is(
        &sim.last_change(shark),
        "rest",
        "patrol",
        Cause::Resumed,
        "hunger > 0.5",
    );
}

#[test]
fn stalk_follows_the_smell_of_prey_behind_until_it_is_in_sight() {
    let (mut sim, _dir) = world();
    let shark = hungry_shark(&mut sim, v(0.0, 20.0, 0.0), 0.0, 0.9);
    // Behind the shark, beyond the 4 units its perception volume reaches backwards.
    sim.spawn("sardine", v(0.0, 20.0, -8.0), PI);
    sim.step();
    is(
        &sim.last_change(shark),
        "patrol",
        "stalk",
        Cause::Interrupted,
        "hunger > 0.5 and smells food and not (sees food)",
    );
    sim.run_until(200, |s| s.behavior(shark) != "stalk")
        .expect("turns until it sees the prey");
    is(
        &sim.last_change(shark),
        "stalk",
        "hunt",
        Cause::Completed,
        "sees food or not (perceives food) or hunger < 0.3",
    );
}

#[test]
fn avoid_static_steers_around_a_rock() {
    let (mut sim, _dir) = world();
    sim.world.add_obstacle(Shape::Sphere {
        center: v(0.0, 20.0, 8.0),
        radius: 2.0,
    });
    let shark = sim.spawn("shark", v(0.0, 20.0, 0.0), 0.0);
    sim.step();
    is(
        &sim.last_change(shark),
        "patrol",
        "avoid_static",
        Cause::Interrupted,
        "obstacle pressure above M_min",
    );
    let mut closest = f32::INFINITY;
    sim.run_until(200, |s| {
        closest = closest.min(s.agent(shark).pos.distance(v(0.0, 20.0, 8.0)));
        s.behavior(shark) != "avoid_static"
    })
    .expect("clear of the rock");
    is(
        &sim.last_change(shark),
        "avoid_static",
        "patrol",
        Cause::Resumed,
        "not (obstacle pressure above M_min)",
    );
    assert!(closest > 2.0, "{closest}");
}
