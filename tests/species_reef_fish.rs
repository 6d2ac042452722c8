//! `behaviors/reef_fish.ron`: each of the nine behaviors of seed 000 starts and completes in a
//! world built for it, with the transition causes of §3.

mod common;

use common::{Change, Sim};
use glam::Vec3;
use shoal::events::{Cause, Event, MessageKind};
use shoal::world::{Sex, Shape};
use std::f32::consts::{FRAC_PI_2, PI};

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

fn sim() -> Sim {
    Sim::shipped(&["reef_fish", "shark", "jellyfish"])
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

/// A reef fish that is neither hungry nor in the mood (mating clock at zero).
fn calm_fish(sim: &mut Sim, pos: Vec3, yaw: f32) -> shoal::world::AgentId {
    let id = sim.spawn("reef_fish", pos, yaw);
    sim.set_hunger(id, 0.1);
    sim.agent_mut(id).drives.since_mating = 0.0;
    id
}

#[test]
fn wander_is_the_fallback_of_a_fish_alone() {
    let mut sim = sim();
    let fish = calm_fish(&mut sim, v(0.0, 20.0, 0.0), 0.0);
    sim.run(100);
    assert_eq!(sim.behavior(fish), "wander");
    assert!(sim.changes(fish).is_empty(), "{:?}", sim.changes(fish));
    let a = sim.agent(fish);
    // Cruising at 0.4·V_max = 1.6 with random turns: it moved and turned.
    assert!(a.pos.distance(v(0.0, 20.0, 0.0)) > 4.0, "{}", a.pos);
    assert!(a.yaw.abs() > 0.05);
}

#[test]
fn avoid_static_turns_away_from_a_rock_ahead_and_completes() {
    let mut sim = sim();
    // The rock's surface 1.3 ahead: within the 1.5 at which avoid_static takes over from the
    // avoidance every other behavior steers with.
    sim.world.add_obstacle(Shape::Sphere {
        center: v(0.0, 20.0, 2.8),
        radius: 1.5,
    });
    let fish = calm_fish(&mut sim, v(0.0, 20.0, 0.0), 0.0);
    let mut closest = f32::INFINITY;
    sim.run_until(40, |s| s.behavior(fish) == "avoid_static")
        .expect("the rock comes within range");
    is(
        &sim.last_change(fish),
        "wander",
        "avoid_static",
        Cause::Interrupted,
        "obstacle pressure above M_min and obstacle within 1.5",
    );
    sim.run_until(100, |s| {
        closest = closest.min(s.agent(fish).pos.distance(v(0.0, 20.0, 2.8)));
        s.behavior(fish) != "avoid_static"
    })
    .expect("avoidance completes");
    is(
        &sim.last_change(fish),
        "avoid_static",
        "wander",
        Cause::Resumed,
        "not (obstacle pressure above M_min)",
    );
    // Never closer to the rock than half its width (0.15).
    assert!(closest >= 1.5 + 0.15, "kept off the rock: {closest}");
}

#[test]
fn escape_interrupts_eating_and_eating_resumes_when_the_shark_is_gone() {
    let mut sim = sim();
    let fish = sim.spawn("reef_fish", v(0.0, 20.0, 0.0), 0.0);
    sim.set_hunger(fish, 0.9);
    sim.world.add_food(v(0.0, 20.0, 9.0));
    sim.step();
    // Food in sight: eat starts in its `bite` part.
    is(
        &sim.last_change(fish),
        "wander",
        "eat/bite",
        Cause::Interrupted,
        "latched on (hunger > 0.45) until (hunger < 0.2) and perceives food",
    );
    // A shark appears on the fish's left, swimming away from it (not head-on traffic).
    let shark = sim.spawn("shark", v(4.0, 20.0, 1.0), -FRAC_PI_2);
    sim.step();
    let c = sim.last_change(fish);
    is(
        &c,
        "eat/bite",
        "escape",
        Cause::Interrupted,
        "sees predator or (heard danger and perceives predator)",
    );
    assert_eq!(c.stack, ["wander", "eat/bite"]);
    // On entering, escape warns kin around.
    assert!(sim.pipeline.events.iter().any(|e| matches!(
        e,
        Event::Message { from, kind: MessageKind::Danger, radius } if *from == fish && *radius == 8.0
    )));
    sim.run(10);
    // Seed 000 §4.4, vision mode: predator on the left → turn right by π/4 per step (which the
    // turn-rate response spreads over a few ticks) until the predator is behind (|θ| > π/2).
    let a = sim.agent(fish);
    let (bearing, _) =
        shoal::frame::bearing_elevation(a.yaw, a.pitch, sim.agent(shark).pos - a.pos);
    assert!(a.yaw > 0.2, "turned right: {}", a.yaw);
    assert!(bearing.abs() > FRAC_PI_2, "shark behind: bearing {bearing}");
    assert_eq!(sim.behavior(fish), "escape");
    // The shark leaves for good: escape completes and the stacked eat resumes.
    sim.teleport(shark, v(45.0, 38.0, 45.0));
    sim.step();
    let c = sim.last_change(fish);
    is(
        &c,
        "escape",
        "eat/bite",
        Cause::Resumed,
        "predator behind and out of sight",
    );
    assert_eq!(c.stack, ["wander"]);
}

#[test]
fn a_danger_message_makes_a_fish_that_only_smells_the_shark_escape() {
    let mut sim = sim();
    // A sees the shark ahead; B, behind A and facing away, only smells it.
    let a = calm_fish(&mut sim, v(0.0, 20.0, 0.0), 0.0);
    let b = calm_fish(&mut sim, v(0.0, 20.0, -3.0), PI);
    sim.spawn("shark", v(0.0, 20.0, 6.0), -FRAC_PI_2);
    sim.step();
    assert_eq!(sim.behavior(a), "escape");
    assert_eq!(
        sim.behavior(b),
        "wander",
        "B neither sees it nor has heard yet"
    );
    sim.step();
    is(
        &sim.last_change(b),
        "wander",
        "escape",
        Cause::Interrupted,
        "sees predator or (heard danger and perceives predator)",
    );
}

/// A large body that cruises straight on, for head-on traffic: neither food nor predator to a
/// reef fish, so it is "other" (a dynamic obstacle).
const BARGE: &str = r#"Species(
    name: "barge",
    body: (size: (1.0, 1.0, 2.0), limits: (max_speed: 2.0, min_speed: 1.0)),
    relations: (see_others: false),
    initial: "cruise",
    behaviors: [Behavior(name: "cruise", priority: 1, steer: Cruise(speed: 0.5))],
)
"#;

#[test]
fn avoid_dynamic_gives_way_to_a_body_coming_head_on() {
    let dir = common::folder(&[("barge.ron", BARGE)]);
    let root = common::behaviors();
    let mut sim = Sim::new(
        vec![
            common::load(&root.join("reef_fish.ron"), &root),
            common::load(&dir.path().join("barge.ron"), dir.path()),
        ],
        shoal::world::Aabb::new(v(-50.0, 0.0, -50.0), v(50.0, 40.0, 50.0)),
    );
    let fish = calm_fish(&mut sim, v(0.0, 20.0, 0.0), 0.0);
    // Coming straight at the fish at 1 unit/s, slightly to its right.
    sim.spawn("barge", v(-0.5, 20.0, 6.0), PI);
    sim.run_until(40, |s| s.behavior(fish) == "avoid_dynamic")
        .expect("the barge comes within range");
    is(
        &sim.last_change(fish),
        "wander",
        "avoid_dynamic",
        Cause::Interrupted,
        "moving obstacle pressure above M_min",
    );
    let ticks = sim
        .run_until(100, |s| s.behavior(fish) != "avoid_dynamic")
        .expect("the barge passes");
    // min_time 0.2 s: at least 4 ticks.
    assert!(ticks >= 4, "{ticks}");
    is(
        &sim.last_change(fish),
        "avoid_dynamic",
        "wander",
        Cause::Resumed,
        "not (moving obstacle pressure above M_min)",
    );
}

#[test]
fn eat_chases_by_smell_then_bites_in_sight_and_ends_after_the_meal() {
    let mut sim = sim();
    let fish = sim.spawn("reef_fish", v(0.0, 20.0, 0.0), 0.0);
    sim.set_hunger(fish, 0.9);
    sim.agent_mut(fish).drives.since_mating = 0.0;
    // Beyond vision (10), within smell (20).
    sim.world.add_food(v(0.0, 20.0, 15.0));
    sim.step();
    // Smelt, not seen: eat starts in its default part, `chase`.
    is(
        &sim.last_change(fish),
        "wander",
        "eat/chase",
        Cause::Interrupted,
        "latched on (hunger > 0.45) until (hunger < 0.2) and perceives food",
    );
    sim.run_until(60, |s| s.behavior(fish) != "eat/chase")
        .expect("the food comes into sight");
    // In sight, the higher part interrupts the chase inside eat.
    let c = sim.last_change(fish);
    is(&c, "eat/chase", "eat/bite", Cause::Interrupted, "sees food");
    assert_eq!(c.stack, ["wander", "eat/chase"]);
    sim.run_until(100, |s| s.behavior(fish) != "eat/bite")
        .expect("the fish eats and is sated");
    assert!(sim
        .log
        .iter()
        .any(|(_, e)| matches!(e, Event::Meal { agent, .. } if *agent == fish)));
    assert_eq!(sim.pipeline.stats.meals, 1);
    // Eat's own `done` ends it with both its parts (the stacked chase is dropped).
    let c = sim.last_change(fish);
    is(
        &c,
        "eat/bite",
        "wander",
        Cause::Resumed,
        "hunger < 0.2 or not (perceives food)",
    );
    assert_eq!(c.stack, Vec::<String>::new());
    assert!(sim.agent(fish).drives.hunger < 0.2);
    assert!(sim.world.food.is_empty());
}

#[test]
fn mate_then_leave_then_wander() {
    let mut sim = sim();
    let f = sim.spawn("reef_fish", v(0.0, 20.0, 0.0), 0.0);
    let m = sim.spawn("reef_fish", v(0.0, 20.0, 3.0), PI);
    for (id, sex) in [(f, Sex::Female), (m, Sex::Male)] {
        sim.set_hunger(id, 0.1);
        let a = sim.agent_mut(id);
        a.attrs.sex = sex;
        // l(Δt_L)·(1 − H) = 0.02·100·0.9 ≥ 1: in the mood.
        a.drives.since_mating = 100.0;
    }
    sim.run_until(40, |s| s.pipeline.stats.matings > 0)
        .expect("they meet");
    let d0 = sim.agent(f).pos.distance(sim.agent(m).pos);
    sim.run(80);
    assert_eq!(sim.pipeline.stats.matings, 1, "mating resets libido: once");
    let seq = |id| -> Vec<(String, String, Cause, String)> {
        sim.changes(id)
            .into_iter()
            .map(|c| (c.from, c.to, c.cause, c.condition.unwrap_or_default()))
            .collect()
    };
    let t = |a: &str, b: &str, c: Cause, d: &str| (a.to_string(), b.to_string(), c, d.to_string());
    // Mate is a sequence: the contact ends `court` with success and `leave` starts at once for
    // both partners, with no tick of wander in between; leave's success ends the sequence.
    for id in [f, m] {
        assert_eq!(
            seq(id),
            [
                t(
                    "wander",
                    "mate/court",
                    Cause::Interrupted,
                    "libido > 0.5 and perceives mate"
                ),
                t("mate/court", "mate/leave", Cause::Succeeded, "contact made"),
                t("mate/leave", "wander", Cause::Resumed, "3 s in behavior"),
            ]
        );
    }
    // Both partners heard of the mating (on_event) and swam apart.
    for id in [f, m] {
        assert!(sim.agent(id).memory.iter().any(|(k, _)| &**k == "mated_at"));
    }
    let d1 = sim.agent(f).pos.distance(sim.agent(m).pos);
    assert!(d1 > d0 + 3.0, "they swam apart: {d0} → {d1}");
}

#[test]
fn school_forms_with_kin_around_and_completes_when_they_are_gone() {
    let mut sim = sim();
    let ids: Vec<_> = (0..5)
        .map(|k| calm_fish(&mut sim, v(k as f32 * 1.5, 20.0, 0.0), 0.2 * k as f32))
        .collect();
    sim.step();
    for &id in &ids {
        is(
            &sim.last_change(id),
            "wander",
            "school",
            Cause::Interrupted,
            "number of kin > 2",
        );
    }
    sim.run(40);
    assert!(ids.iter().all(|&id| sim.behavior(id) == "school"));
    for (k, &id) in ids[1..].iter().enumerate() {
        sim.teleport(id, v(-45.0 + 3.0 * k as f32, 35.0, -45.0));
    }
    sim.run_until(10, |s| s.behavior(ids[0]) != "school")
        .expect("alone again");
    is(
        &sim.last_change(ids[0]),
        "school",
        "wander",
        Cause::Resumed,
        "number of kin < 2",
    );
}
