//! `behaviors/sardine.ron` (seed 003): schooling with R–A zones and Vicsek alignment, joining a
//! school, group escape by messages, density-driven dispersal, foraging, obstacle avoidance, and
//! the shared `common/schooling.rhai` module.

mod common;

use common::{Change, Sim};
use glam::Vec3;
use shoal::events::{Cause, Event, MessageKind};
use shoal::world::{AgentId, MemValue, Shape};
use std::f32::consts::FRAC_PI_2;

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

fn sim() -> Sim {
    Sim::shipped(&["sardine", "shark"])
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

fn sardine(sim: &mut Sim, pos: Vec3, yaw: f32) -> AgentId {
    let id = sim.spawn("sardine", pos, yaw);
    sim.set_hunger(id, 0.2);
    id
}

fn remember(sim: &mut Sim, id: AgentId, key: &str, value: MemValue) {
    let m = &mut sim.agent_mut(id).memory;
    match m.binary_search_by(|(k, _)| (**k).cmp(key)) {
        Ok(i) => m[i].1 = value,
        Err(i) => m.insert(i, (key.into(), value)),
    }
}

fn recalls(sim: &Sim, id: AgentId, key: &str) -> Option<MemValue> {
    sim.agent(id)
        .memory
        .iter()
        .find(|(k, _)| &**k == key)
        .map(|(_, v)| v.clone())
}

/// |mean forward| of the agents: 1 when all head the same way (seed 003 order parameter).
fn polarization(sim: &Sim, ids: &[AgentId]) -> f32 {
    let sum: Vec3 = ids.iter().map(|&id| sim.agent(id).forward()).sum();
    sum.length() / ids.len() as f32
}

#[test]
fn a_lone_sardine_cruises() {
    let mut sim = sim();
    let id = sardine(&mut sim, v(0.0, 20.0, 0.0), 0.0);
    sim.run(100);
    assert_eq!(sim.behavior(id), "cruise");
    assert!(sim.changes(id).is_empty(), "{:?}", sim.changes(id));
}

#[test]
fn a_school_forms_aligns_and_keeps_together() {
    let mut sim = sim();
    // 16 sardines in a 4×4 grid, 1.2 apart, headings spread over 180°.
    let ids: Vec<_> = (0..16)
        .map(|k| {
            let (i, j) = ((k % 4) as f32, (k / 4) as f32);
            sardine(
                &mut sim,
                v(i * 1.2, 20.0 + 0.3 * j, j * 1.2),
                -FRAC_PI_2 + 0.21 * k as f32,
            )
        })
        .collect();
    let p0 = polarization(&sim, &ids);
    sim.run(8); // scripts (decision interval 4) have run for everyone
    for &id in &ids {
        let c = sim.changes(id);
        is(
            &c[0],
            "cruise",
            "school",
            Cause::Interrupted,
            "sees kin and wants_school()",
        );
    }
    sim.run(92);
    // Mean polarization over seconds 5 to 10.
    let mut p1 = 0.0;
    for _ in 0..100 {
        sim.step();
        p1 += polarization(&sim, &ids) / 100.0;
    }
    assert!(ids.iter().all(|&id| sim.behavior(id) == "school"));
    assert!(p0 < 0.7 && p1 > 0.85, "Vicsek alignment: {p0} → {p1}");
    // R–A zones: nobody inside another's body, and the school holds together.
    let centroid: Vec3 = ids.iter().map(|&id| sim.agent(id).pos).sum::<Vec3>() / 16.0;
    let mut nearest_sum = 0.0;
    for &a in &ids {
        let pa = sim.agent(a).pos;
        assert!(
            pa.distance(centroid) < 8.0,
            "straggler at {}",
            pa.distance(centroid)
        );
        let nearest = ids
            .iter()
            .filter(|&&b| b != a)
            .map(|&b| sim.agent(b).pos.distance(pa))
            .fold(f32::INFINITY, f32::min);
        nearest_sum += nearest;
    }
    let mean_nearest = nearest_sum / 16.0;
    assert!(
        (0.3..2.5).contains(&mean_nearest),
        "mean nearest-neighbor distance {mean_nearest}"
    );
}

#[test]
fn a_sardine_that_only_smells_kin_swims_to_them_and_joins() {
    let mut sim = sim();
    for k in 0..5 {
        sardine(&mut sim, v(k as f32, 20.0, 0.0), 0.0);
    }
    // 9 units behind the school, beyond vision (6), within smell (12), facing away.
    let lone = sardine(&mut sim, v(2.0, 20.0, -9.0), std::f32::consts::PI);
    sim.step();
    is(
        &sim.last_change(lone),
        "cruise",
        "join",
        Cause::Interrupted,
        "smells kin and not (sees kin)",
    );
    sim.run_until(100, |s| s.behavior(lone) != "join")
        .expect("it sees them");
    let c = sim.last_change(lone);
    assert_eq!(
        (c.from.as_str(), c.condition.as_deref()),
        ("join", Some("sees kin or not (perceives kin)"))
    );
    sim.run_until(20, |s| s.behavior(lone) == "school")
        .expect("and schools with them");
}

#[test]
fn escape_warns_the_school_which_reacts_to_the_danger_message() {
    let mut sim = sim();
    // The front sardine will see the shark 7.5 ahead; the others, beside and behind it (in its
    // view, so it stays with them), only smell it.
    let front = sardine(&mut sim, v(0.0, 20.0, 0.0), 0.0);
    let rest: Vec<_> = [-3.0, -2.0, 2.0, 3.0]
        .iter()
        .map(|&x| sardine(&mut sim, v(x, 20.0, -1.5), 0.0))
        .collect();
    sim.run(4);
    assert!(rest.iter().all(|&id| sim.behavior(id) == "school"));
    let ahead = sim.agent(front).pos + v(0.0, 0.0, 7.5);
    for &id in &rest {
        assert!(sim.agent(id).pos.distance(ahead) > 8.0, "out of sight");
    }
    let shark = sim.spawn("shark", ahead, -FRAC_PI_2);
    sim.step();
    let c = sim.last_change(front);
    assert_eq!(
        (c.to.as_str(), c.cause, c.condition.as_deref()),
        (
            "escape",
            Cause::Interrupted,
            Some("sees predator or (heard danger and perceives predator)")
        )
    );
    assert!(sim.pipeline.events.iter().any(|e| matches!(
        e,
        Event::Message { from, kind: MessageKind::Danger, radius } if *from == front && *radius == 8.0
    )));
    assert!(rest.iter().all(|&id| sim.behavior(id) == "school"));
    sim.step();
    // They hear the danger and smell the shark: they escape too, before they see it.
    for &id in &rest {
        is(
            &sim.last_change(id),
            "school",
            "escape",
            Cause::Interrupted,
            "sees predator or (heard danger and perceives predator)",
        );
    }
    // Each passes the warning on, once.
    let relays = sim
        .pipeline
        .events
        .iter()
        .filter(|e| matches!(e, Event::Message { kind: MessageKind::Danger, radius, .. } if *radius == 8.0))
        .count();
    assert_eq!(relays, rest.len());
    // Each turns away from the shark (seed 000 §4.4 smell mode: by π/8 a step until it is no
    // longer ahead): its bearing from each of them grows.
    let bearing = |s: &Sim, id| {
        let a = s.agent(id);
        let to = s.agent(shark).pos - a.pos;
        shoal::frame::bearing_elevation(a.yaw, a.pitch, to).0.abs()
    };
    let before: Vec<f32> = rest.iter().map(|&id| bearing(&sim, id)).collect();
    sim.run(10);
    for (k, &id) in rest.iter().enumerate() {
        let after = bearing(&sim, id);
        assert!(after > before[k] + 0.3, "{id:?}: {} → {after}", before[k]);
    }
    // Once the shark is gone, each escape ends; none of them raised the alarm (which is for
    // a danger heard of while the predator is not perceived).
    sim.teleport(shark, v(55.0, 38.0, 55.0));
    for &id in &rest {
        sim.run_until(60, |s| s.behavior(id) != "escape")
            .expect("escape ends");
    }
    let alarms = |s: &Sim, id| s.changes(id).iter().filter(|c| c.to == "alarm").count();
    assert!(rest.iter().all(|&id| alarms(&sim, id) == 0));
}

#[test]
fn a_sluggish_sardine_disperses_and_trades_its_food_memory_for_the_schools() {
    let mut sim = sim();
    let id = sardine(&mut sim, v(0.0, 20.0, 0.0), 0.0);
    sim.run(60); // 3 s: the speed window is filled
    assert_eq!(sim.behavior(id), "cruise");
    // It has been slow for the whole window (mean 0.3 < v_d = 0.35·3.2) and remembers food.
    let now = sim.world.time() as f32;
    remember(&mut sim, id, "mean_speed", MemValue::Float(0.3));
    remember(&mut sim, id, "sampled_at", MemValue::Float(now));
    remember(&mut sim, id, "best_food", MemValue::Vec3(v(5.0, 20.0, 5.0)));
    sim.agent_mut(id).speed = 0.45;
    sim.run_until(4, |s| s.behavior(id) == "disperse")
        .expect("the next script run notices");
    is(
        &sim.last_change(id),
        "cruise",
        "disperse",
        Cause::Interrupted,
        "sluggish()",
    );
    // On entering: its own best food position is forgotten (no school around to adopt from)
    // and the speed window restarts.
    assert_eq!(recalls(&sim, id, "best_food"), None);
    // Speed re-drawn in [V_min, V_max], then at least cruising: it speeds up.
    sim.run(10);
    assert!(sim.agent(id).speed > 0.35 * 3.2, "{}", sim.agent(id).speed);
    sim.run_until(40, |s| s.behavior(id) != "disperse")
        .expect("disperse lasts 1.5 s");
    is(
        &sim.last_change(id),
        "disperse",
        "cruise",
        Cause::Resumed,
        "1.5 s in behavior",
    );
}

#[test]
fn dispersing_in_a_school_adopts_the_schools_best_food_position() {
    // The school's best (seed 003) is a food position a perceived member knows: with one, the
    // dispersing sardine swaps its own for it; with none, it is left with no food target at
    // all (it used to head for a point ahead of the school, where no food need be).
    for member_knows in [true, false] {
        let mut sim = sim();
        let ids: Vec<_> = (0..4)
            .map(|k| sardine(&mut sim, v(k as f32, 20.0, 0.0), 0.0))
            .collect();
        sim.run(60);
        let id = ids[0];
        // Remembered by member 2, beyond its vision (8): kept until it gets there.
        let food = v(30.0, 20.0, 0.0);
        if member_knows {
            sim.agent_mut(ids[2]).mind.set_best_food(Some(food));
        }
        let now = sim.world.time() as f32;
        remember(&mut sim, id, "mean_speed", MemValue::Float(0.3));
        remember(&mut sim, id, "sampled_at", MemValue::Float(now));
        remember(
            &mut sim,
            id,
            "best_food",
            MemValue::Vec3(v(-40.0, 5.0, -40.0)),
        );
        sim.run_until(4, |s| s.behavior(id) == "disperse")
            .expect("disperses");
        let best = recalls(&sim, id, "best_food");
        if member_knows {
            assert_eq!(best, Some(MemValue::Vec3(food)), "adopted the member's");
        } else {
            assert_eq!(best, None, "no member knows food: no target");
        }
    }
}

#[test]
fn a_hungry_sardine_forages_eats_and_stops() {
    let mut sim = sim();
    let id = sim.spawn("sardine", v(0.0, 20.0, 0.0), 0.0);
    // n_e = 0.3; one meal of 0.5 gives n_e = 0.8 → H = 0.2 < 0.3.
    sim.set_hunger(id, 0.7);
    sim.world.add_food(v(0.5, 20.0, 4.0));
    sim.step();
    is(
        &sim.last_change(id),
        "cruise",
        "forage",
        Cause::Interrupted,
        "hunger > 0.6 and (perceives food or knows_food())",
    );
    sim.run_until(100, |s| s.behavior(id) != "forage")
        .expect("sated");
    assert_eq!(sim.pipeline.stats.meals, 1);
    is(
        &sim.last_change(id),
        "forage",
        "cruise",
        Cause::Resumed,
        "hunger < 0.3 or (not (perceives food) and not (knows_food()))",
    );
    // The meal's place is remembered (on_event).
    assert!(matches!(
        recalls(&sim, id, "best_food"),
        Some(MemValue::Vec3(_))
    ));
}

#[test]
fn avoid_static_keeps_a_sardine_off_a_rock() {
    let mut sim = sim();
    // A rock 1.2 ahead: close enough for avoid_static to take over from cruise's own avoidance.
    sim.world.add_obstacle(Shape::Sphere {
        center: v(0.0, 20.0, 2.2),
        radius: 1.0,
    });
    let id = sardine(&mut sim, v(0.0, 20.0, 0.0), 0.0);
    sim.run_until(40, |s| s.behavior(id) == "avoid_static")
        .expect("in range");
    is(
        &sim.last_change(id),
        "cruise",
        "avoid_static",
        Cause::Interrupted,
        "obstacle pressure above M_min and obstacle within 1.5",
    );
    let mut closest = f32::INFINITY;
    sim.run_until(100, |s| {
        closest = closest.min(s.agent(id).pos.distance(v(0.0, 20.0, 2.2)));
        s.behavior(id) != "avoid_static"
    })
    .expect("clear");
    assert!(closest > 1.0, "{closest}");
    is(
        &sim.last_change(id),
        "avoid_static",
        "cruise",
        Cause::Resumed,
        "not (obstacle pressure above M_min)",
    );
}
