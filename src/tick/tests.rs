//! Unit tests of the pipeline's own promises: what a step leaves and replaces, spawning's draws,
//! the stage times. The stages' results are checked end to end in `tests/` (determinism,
//! species, scenarios).

use super::*;
use crate::species::Species;
use std::time::Duration;

/// One species that drifts ahead, in a 100 × 40 × 100 m world.
fn drifters() -> (Pipeline, World) {
    let text = r#"(
        name: "drifter",
        initial: "drift",
        behaviors: [Behavior(name: "drift", priority: 1, steer: Cruise(speed: 0.5))],
    )"#;
    let species = Species::parse("drifter.ron", text).unwrap();
    let set = SpeciesSet::new(vec![species.into()]).unwrap();
    let bounds = Aabb::new(Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 40.0, 50.0));
    (Pipeline::new(Arc::new(set)), World::new(bounds, 0.05, 7))
}

/// A species that drifts, and dashes under `conditions` (the dash behavior's `when`, `done`
/// and `fail` keys).
fn dasher(conditions: &str) -> Species {
    let text = format!(
        r#"(
        name: "dasher",
        initial: "drift",
        behaviors: [
            Behavior(name: "drift", priority: 2, steer: Cruise(speed: 0.5)),
            Behavior(name: "dash", priority: 1, {conditions}, steer: Cruise(speed: 2.0)),
        ],
    )"#
    );
    Species::parse("dasher.ron", &text).unwrap()
}

#[test]
fn a_step_appends_to_the_events_and_leaves_them() {
    let (mut p, mut w) = drifters();
    let id = p.spawn(&mut w, 0, Vec3::new(0.0, 10.0, 0.0), 0.0, 0.0);
    p.step(&mut w);
    p.step(&mut w);
    assert!(matches!(p.events.first(), Some(Event::Spawn { agent, .. }) if *agent == id));
    assert_eq!(w.tick, 2);
    assert_eq!(p.stats.behavior_ticks, vec![vec![2]]);
    assert_eq!(p.stage_times().ticks, 2);
}

#[test]
fn a_delivered_message_is_heard_for_one_tick() {
    let (mut p, mut w) = drifters();
    let id = p.spawn(&mut w, 0, Vec3::new(0.0, 10.0, 0.0), 0.0, 0.0);
    assert!(!p.deliver(&mut w, AgentId(id.0 + 1), MessageKind::Mate));
    assert!(p.deliver(&mut w, id, MessageKind::Mate));
    assert!(p.deliver(&mut w, id, MessageKind::Danger));
    assert_eq!(w.agents[0].inbox.kind(), Some(MessageKind::Danger));
    p.step(&mut w);
    assert_eq!(w.agents[0].inbox.kind(), None);
}

#[test]
fn spawns_draw_from_each_agent_own_stream() {
    let (mut p, mut w) = drifters();
    let (mut q, mut v) = drifters();
    let at = Vec3::new(1.0, 10.0, -2.0);
    // Another agent spawned first takes nothing from the second one's stream.
    p.spawn(&mut w, 0, at, 0.3, 0.0);
    let a = p.spawn(&mut w, 0, at, 0.3, 0.0);
    v.next_agent_id = a.0;
    let b = q.spawn(&mut v, 0, at, 0.3, 0.0);
    assert_eq!(a, b);
    let (x, y) = (&w.agents[1], &v.agents[0]);
    assert_eq!(x.attrs.sex, y.attrs.sex);
    assert_eq!(x.attrs.age.to_bits(), y.attrs.age.to_bits());
    assert_eq!(x.drives.hunger.to_bits(), y.drives.hunger.to_bits());
    assert_eq!(x.rng, y.rng);
}

#[test]
fn stage_times_are_read_per_tick() {
    let t = StageTimes {
        index: Duration::from_millis(4),
        perception: Duration::from_millis(8),
        agents: Duration::from_millis(12),
        events: Duration::from_millis(2),
        ticks: 4,
    };
    let ms = t.ms_per_tick();
    assert_eq!(ms.map(|(name, _)| name), StageTimes::NAMES);
    for ((_, m), want) in ms.into_iter().zip([1.0, 2.0, 3.0, 0.5]) {
        assert!((m - want).abs() < 1e-9, "{m} against {want}");
    }
    assert_eq!(StageTimes::default().ms_per_tick()[0].1, 0.0);
}

#[test]
fn a_fired_condition_reads_as_its_behaviors_own_text_and_node() {
    use crate::decision::{Fired, Transition, Which};
    let sp = dasher(
        "when: Above(Drive(Hunger), 0.5), done: Below(Drive(Hunger), 0.2), \
         fail: Above(Drive(Fear), 0.9)",
    );
    let b = &sp.behaviors[1];
    for (which, want, node) in [
        (Which::When, &b.when_text, &b.when),
        (Which::Done, &b.done_text, &b.done),
        (Which::Fail, &b.fail_text, &b.fail),
    ] {
        let f = Fired::new(1, which);
        assert_eq!(f.text(&sp).as_deref(), Some(&**want));
        assert_eq!(f.node(&sp), Some(node));
    }
    // The three texts differ, or the loop above proves little.
    assert!(b.when_text != b.done_text && b.done_text != b.fail_text);
    // A behavior the species does not have names nothing.
    assert_eq!(Fired::new(9, Which::When).text(&sp), None);
    // A transition holds the fired condition, or none.
    let t = Transition::new(
        1,
        0,
        crate::events::Cause::Completed,
        Some(Fired::new(1, Which::Done)),
    );
    assert_eq!(t.fired(), Some(Fired::new(1, Which::Done)));
    assert_eq!(
        Transition::new(1, 0, crate::events::Cause::Script, None).fired(),
        None
    );
}

#[test]
fn a_spawns_long_event_list_is_given_back_at_the_next_tick() {
    let (mut p, mut w) = drifters();
    for k in 0..20_000 {
        p.spawn(
            &mut w,
            0,
            Vec3::new((k % 100) as f32, 10.0, (k / 100) as f32 * 0.2),
            0.0,
            0.0,
        );
    }
    assert!(p.events.capacity() >= 20_000);
    // As a run does: the spawns' events read, then cleared before the tick.
    p.events.clear();
    p.step(&mut w);
    assert!(p.events.capacity() <= 2 * (p.events.len() + 1024));
}

#[test]
fn a_world_without_messages_contacts_or_stations_keeps_nothing_for_them() {
    let (mut p, mut w) = drifters();
    for k in 0..3 {
        p.spawn(&mut w, 0, Vec3::new(k as f32, 10.0, 0.0), 0.0, 0.0);
    }
    for _ in 0..3 {
        p.step(&mut w);
    }
    // Per-agent lists of the next tick's inboxes and of the tick's contacts: none kept.
    assert_eq!(p.next_inbox.capacity(), 0);
    assert_eq!(p.next_events.capacity(), 0);
    assert_eq!(p.dead.capacity(), 0);
    assert_eq!(p.mated.capacity(), 0);
    // The rare parts of a mind: not made.
    assert!(w.agents.iter().all(|a| a.mind.rare.0.is_none()));
    // A message makes the inboxes, and the next tick without one empties them.
    let id = w.agents[1].id;
    assert!(p.deliver(&mut w, id, MessageKind::Danger));
    p.step(&mut w);
    assert!(w
        .agents
        .iter()
        .all(|a| a.inbox == crate::world::Inbox::Empty));
    assert_eq!(p.next_inbox.len(), 3);
}

#[test]
fn a_mind_without_its_rare_parts_equals_one_with_them_empty() {
    use crate::world::{Mind, MindParts, RareMind};
    let plain = Mind::new(0, 0);
    let mut made = plain.clone();
    made.rare_mut();
    assert!(made.rare.0.is_some());
    assert_eq!(plain, made);
    assert_eq!(made, plain);
    made.rare_mut().station = crate::world::Spot::new(Some(Vec3::X));
    assert_ne!(plain, made);
    assert_ne!(made, plain);
    assert_eq!(made.station(), Some(Vec3::X));
    assert_eq!(plain.station(), None);
    assert_eq!((plain.scope_depth(), plain.scope_entered(0)), (0, None));
    let parts = MindParts {
        scope_entered: vec![4, 5].into(),
        ..Default::default()
    };
    let deep = Mind {
        rare: RareMind(Some(Box::new(parts))),
        ..plain.clone()
    };
    assert_eq!(deep.scope_depth(), 2);
    assert_eq!(
        [0, 1, 2].map(|d| deep.scope_entered(d)),
        [Some(4), Some(5), None]
    );
    assert_ne!(deep, plain);
}

#[test]
fn cooldowns_hold_only_started_ones_by_behavior_and_drop_those_run_out() {
    use crate::world::Cooldowns;
    let mut c = Cooldowns::default();
    assert!(c.ready(3, 0) && c.until(3).is_none());
    c.start(7, 10, 30);
    c.start(2, 12, 15);
    // Held by behavior, whatever the order they started in.
    assert_eq!(c, Cooldowns::from_pairs([(2, 15), (7, 30)]));
    assert!(!c.ready(2, 14) && c.ready(2, 15) && !c.ready(7, 29) && c.ready(7, 30));
    assert!(c.ready(5, 0), "a behavior without one may start");
    // A start drops those that ran out (2's at 15) and replaces the behavior's own.
    c.start(7, 20, 40);
    assert_eq!(c, Cooldowns::from_pairs([(7, 40)]));
    assert_eq!(c.running(39).collect::<Vec<_>>(), vec![(7, 40)]);
    assert_eq!(c.running(40).count(), 0);
    // From pairs: the last of a behavior's wins.
    assert_eq!(
        Cooldowns::from_pairs([(1, 5), (0, 9), (1, 8)]),
        Cooldowns::from_pairs([(0, 9), (1, 8)])
    );
}

#[test]
fn an_outcome_with_a_transition_alone_boxes_nothing_more() {
    // Every agent starts in "drift" and soon switches to "dash": a whole school's first
    // transitions, with no message, contact or error beside them.
    let species = dasher("when: Always");
    let set = SpeciesSet::new(vec![species.into()]).unwrap();
    let bounds = Aabb::new(Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 40.0, 50.0));
    let (mut p, mut w) = (Pipeline::new(Arc::new(set)), World::new(bounds, 0.05, 7));
    for k in 0..4 {
        p.spawn(&mut w, 0, Vec3::new(3.0 * k as f32, 10.0, 0.0), 0.0, 0.0);
    }
    // Ticks as `step` runs them, the outcomes looked at before stage 7 takes them.
    let mut seen = 0;
    for _ in 0..40 {
        p.perceive(&w);
        p.agent_pass(&mut w);
        for rare in p.outcomes.iter().filter_map(|o| o.rare.as_deref()) {
            let t = rare.transitions[0].expect("a transition");
            assert!(rare.more.is_none());
            // The condition is named, not copied: its text is the species'.
            let fired = t.fired().expect("a condition fired");
            assert_eq!(
                fired,
                crate::decision::Fired::new(1, crate::decision::Which::When)
            );
            assert_eq!(fired.text(&p.species.species[0]).as_deref(), Some("always"));
            seen += 1;
        }
        p.apply(&mut w);
        // ... and the event carries it.
        for e in p.events.iter() {
            if let crate::events::Event::Transition { condition, .. } = e {
                assert_eq!(condition.as_deref(), Some("always"));
            }
        }
    }
    assert_eq!(seen, 4);
    // A transition is 8 bytes; the box holding two and the pointer to the rest is 24 (a
    // 32-byte heap block).
    assert_eq!(std::mem::size_of::<crate::decision::Transition>(), 8);
    assert!(std::mem::size_of::<super::agent_pass::Rare>() <= 24);
    assert_eq!(p.stats.transitions, 4);
}

#[test]
fn tracked_scopes_hold_just_their_room() {
    let mut m = crate::world::Mind::new(0, 0);
    let ticks = |m: &crate::world::Mind| m.rare.0.as_ref().unwrap().scope_entered.to_vec();
    m.track_scopes(2, 5);
    assert_eq!(ticks(&m), [5, 5]);
    assert_eq!(m.rare.0.as_ref().unwrap().scope_entered.room(), 2);
    m.track_scopes(1, 7);
    assert_eq!(ticks(&m), [5]);
    // One depth holds no list at all.
    assert_eq!(m.rare.0.as_ref().unwrap().scope_entered.room(), 1);
    m.track_scopes(3, 9);
    assert_eq!(ticks(&m), [5, 9, 9]);
    assert_eq!(m.rare.0.as_ref().unwrap().scope_entered.room(), 3);
    m.set_scope_entered(2, 11);
    m.set_scope_entered(3, 12);
    assert_eq!(ticks(&m), [5, 9, 11]);
    assert_eq!(m.scope_entered(3), None);
    m.track_scopes(0, 13);
    assert_eq!((m.scope_depth(), m.scope_entered(0)), (0, None));
    m.set_scope_entered(0, 14);
    assert_eq!(m.scope_depth(), 0);
}

/// Ticks of a world of one lone species (one behavior and nothing to decide) that forages with
/// native drives, turns at its own response and wanders: every agent's record and every event
/// of each tick, as text (floats in their round-trip form, so equal text is equal bits).
fn lone_trace(explain: Explain) -> Vec<String> {
    let text = r#"(
        name: "grazer",
        senses: (vision_radius: 6.0, vision_half_angle: 2.0, smell_radius: 9.0, max_percepts: 6),
        relations: (eats_items: true),
        initial: "graze",
        behaviors: [
            Behavior(
                name: "graze",
                priority: 1,
                response: Some(0.3),
                steer: Priority([
                    AvoidStatic(),
                    Contain(),
                    Blend([
                        (w: 1.0, steer: Separation(k: 1.0, radius: 1.5)),
                        (w: 0.5, steer: Alignment(k: 0.3)),
                        (w: 0.6, steer: Chase(target: Food)),
                        (w: 0.4, steer: Wander(cruise: 0.5)),
                    ]),
                ]),
            ),
        ],
    )"#;
    let species = Species::parse("grazer.ron", text).unwrap();
    assert!(super::agent_pass::lone(&species) && species.drives.native);
    let set = SpeciesSet::new(vec![species.into()]).unwrap();
    let bounds = Aabb::new(Vec3::new(-20.0, 0.0, -20.0), Vec3::new(20.0, 10.0, 20.0));
    let (mut p, mut w) = (Pipeline::new(Arc::new(set)), World::new(bounds, 0.05, 11));
    p.explain = explain;
    let mut draw = crate::world::Rng::new(5, 0);
    for _ in 0..80 {
        let at = Vec3::new(
            draw.range(-8.0, 8.0),
            draw.range(2.0, 8.0),
            draw.range(-8.0, 8.0),
        );
        p.spawn(&mut w, 0, at, draw.range(-3.0, 3.0), 0.0);
    }
    for _ in 0..30 {
        w.add_food(Vec3::new(
            draw.range(-15.0, 15.0),
            1.0,
            draw.range(-15.0, 15.0),
        ));
    }
    let mut out = Vec::new();
    for _ in 0..60 {
        p.step(&mut w);
        out.push(format!("{:?} {:?}", w.agents, p.events));
    }
    out
}

#[test]
fn a_lone_species_pass_is_the_general_pass_bit_for_bit() {
    // Explaining every agent sends each through the general pass (arbitration, the mind out
    // of the record); without, a lone species takes its own.
    let lone = lone_trace(Explain::default());
    let every = Explain {
        every: 1,
        only: None,
    };
    let general = lone_trace(every);
    for (k, (a, b)) in lone.iter().zip(&general).enumerate() {
        assert!(a == b, "tick {k} differs");
    }
    // Grazers remembered food they perceived: the foraging memory is compared too.
    let last = lone.last().unwrap();
    assert!(last.contains("best_food: Some("), "no food known");
}
