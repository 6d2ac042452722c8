//! `behaviors/jellyfish.ron`: a species that is not a fish. It drifts with the current, pulses
//! upward now and then (rigid-body thrust and drag), and stings food it touches.

mod common;

use common::{Change, Sim};
use glam::Vec3;
use shoal::events::{Cause, Event};

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
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

fn sim() -> Sim {
    Sim::shipped(&["jellyfish"])
}

#[test]
fn drifting_it_moves_exactly_with_the_current() {
    let mut sim = sim();
    sim.world.current = v(0.5, 0.0, 0.2);
    let id = sim.spawn("jellyfish", v(0.0, 20.0, 0.0), 0.0);
    sim.set_hunger(id, 0.1);
    let mut drifted = 0;
    for _ in 0..200 {
        let before = sim.agent(id).pos;
        sim.step();
        let a = sim.agent(id);
        // `Stop` under braking: once still, only the current moves it.
        if sim.behavior(id) == "drift" && a.speed == 0.0 {
            let step = a.pos - before;
            assert!((step - v(0.025, 0.0, 0.01)).length() < 1e-5, "{step}");
            drifted += 1;
        }
    }
    assert!(drifted > 100, "{drifted}");
}

#[test]
fn a_pulse_climbs_for_one_and_a_half_seconds_then_it_drifts_again() {
    let mut sim = sim();
    let id = sim.spawn("jellyfish", v(0.0, 20.0, 0.0), 0.0);
    sim.set_hunger(id, 0.1);
    sim.run_until(600, |s| s.behavior(id) == "pulse")
        .expect("a pulse within 30 s (0.15 per second)");
    let start = sim.last_change(id);
    is(
        &start,
        "drift",
        "pulse",
        Cause::Interrupted,
        "chance 0.15/s and below_ceiling()",
    );
    let y0 = sim.agent(id).pos.y;
    let n = sim
        .run_until(40, |s| s.behavior(id) != "pulse")
        .expect("the pulse ends");
    assert_eq!(n, 30, "1.5 s at 20 ticks per second");
    is(
        &sim.last_change(id),
        "pulse",
        "drift",
        Cause::Resumed,
        "1.5 s in behavior",
    );
    let y1 = sim.agent(id).pos.y;
    assert!(y1 > y0 + 0.3, "climbed {y0} → {y1}");
    // Drag slows it down once the pulse is over.
    let s0 = sim.agent(id).speed;
    sim.run(10);
    assert!(sim.agent(id).speed < s0);
}

#[test]
fn it_stays_within_two_units_above_its_home_depth() {
    let mut sim = sim();
    let id = sim.spawn("jellyfish", v(0.0, 20.0, 0.0), 0.0);
    sim.set_hunger(id, 0.1);
    let mut top = 0.0f32;
    for _ in 0..1200 {
        sim.step();
        top = top.max(sim.agent(id).pos.y);
    }
    let pulses = sim.changes(id).iter().filter(|c| c.to == "pulse").count();
    assert!(pulses >= 3, "{pulses}");
    // A pulse may start just below home + 2 and carry it about one more unit.
    assert!(top < 23.5, "{top}");
}

#[test]
fn it_stings_food_it_touches() {
    let mut sim = sim();
    let id = sim.spawn("jellyfish", v(0.0, 20.0, 0.0), 0.0);
    sim.set_hunger(id, 0.9);
    sim.world.add_food(v(1.0, 20.0, 0.0));
    sim.step();
    is(
        &sim.last_change(id),
        "drift",
        "sting",
        Cause::Interrupted,
        "hunger > 0.2 and food within 1.5",
    );
    // One touch, then the bell holds still 0.6 s.
    let t = sim
        .run_until(20, |s| s.behavior(id) != "sting")
        .expect("eaten");
    assert!(t >= 11, "the sting lasted {t} ticks");
    assert!(sim
        .log
        .iter()
        .any(|(_, e)| matches!(e, Event::Meal { agent, .. } if *agent == id)));
    is(
        &sim.last_change(id),
        "sting",
        "drift",
        Cause::Resumed,
        "0.6 s in behavior and not (food within 1.5)",
    );
    // Food farther than the tentacles reach is ignored, even when sensed.
    sim.world.add_food(v(0.0, 20.0, 2.2));
    sim.run(20);
    assert_eq!(sim.world.food.len(), 1);
}
