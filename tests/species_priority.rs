//! The arbitration rules of seed 000 §3, each in a world built for it: a probe species whose
//! drives only change when the test sets them (`native: false`), so every trigger is explicit.
//! Levels: flee 1; feed, court 2; rest 3; idle 4 (initial).

mod common;

use common::{folder, load, Change, Sim};
use glam::Vec3;
use shoal::events::{Cause, Event};
use shoal::world::{Aabb, AgentId};

const PROBE: &str = r#"
Species(
    name: "probe",
    drives: (native: false, hunger: Fixed(0.0)),
    initial: "idle",
    behaviors: [
        Behavior(name: "flee", priority: 1, when: Above(Drive(Fear), 0.5), done: Below(Drive(Fear), 0.5), steer: Cruise(speed: 1.0)NO_MIN),
        Behavior(name: "feed", priority: 2, when: Above(Drive(Hunger), 0.5), done: Below(Drive(Hunger), 0.5), steer: Cruise(speed: 0.6)EXTRA_FEED),
        Behavior(name: "court", priority: 2, when: Above(Drive(Libido), 0.5), done: Below(Drive(Libido), 0.5), steer: Cruise(speed: 0.4)NO_MIN),
        Behavior(name: "rest", priority: 3, when: Above(Drive(Fatigue), 0.5), done: Below(Drive(Fatigue), 0.5), steer: StopEXTRA_REST),
        Behavior(name: "idle", priority: 4, steer: Wander()NO_MIN),
    ],
)
"#;

/// A probe world; `feed` and `rest` get the extra fields given. Its behaviors have no minimum
/// time unless a test gives `feed` one, so that each rule shows at the granularity of a tick.
fn probe(extra_feed: &str, extra_rest: &str) -> (Sim, AgentId, tempfile::TempDir) {
    let no_min = |extra: &str| {
        if extra.contains("min_time") {
            extra.to_string()
        } else {
            format!(", min_time: 0.0{extra}")
        }
    };
    probe_text(
        &PROBE
            .replace("EXTRA_FEED", &no_min(extra_feed))
            .replace("EXTRA_REST", &no_min(extra_rest))
            .replace("NO_MIN", ", min_time: 0.0"),
    )
}

/// A probe world from the species text `text`.
fn probe_text(text: &str) -> (Sim, AgentId, tempfile::TempDir) {
    let text = text.to_string();
    let dir = folder(&[("probe.ron", &text)]);
    let sp = load(&dir.path().join("probe.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let id = sim.spawn("probe", Vec3::ZERO, 0.0);
    (sim, id, dir)
}

fn set(sim: &mut Sim, id: AgentId, hunger: f32, libido: f32, fear: f32, fatigue: f32) {
    let d = &mut sim.agent_mut(id).drives;
    d.hunger = hunger;
    d.libido = libido;
    d.fear = fear;
    d.fatigue = fatigue;
}

fn change(
    from: &str,
    to: &str,
    cause: Cause,
    condition: &str,
    stack: &[&str],
) -> (String, String, Cause, Option<String>, Vec<String>) {
    (
        from.into(),
        to.into(),
        cause,
        Some(condition.into()),
        stack.iter().map(|s| s.to_string()).collect(),
    )
}

fn key(c: &Change) -> (String, String, Cause, Option<String>, Vec<String>) {
    (
        c.from.clone(),
        c.to.clone(),
        c.cause,
        c.condition.clone(),
        c.stack.clone(),
    )
}

#[test]
fn higher_interrupts_lower_and_the_lower_goes_on_the_stack() {
    let (mut sim, id, _dir) = probe("", "");
    sim.run(5);
    assert_eq!(sim.behavior(id), "idle");
    assert!(sim.changes(id).is_empty(), "nothing fired yet");

    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change(
            "idle",
            "feed",
            Cause::Interrupted,
            "hunger > 0.5",
            &["idle"]
        )
    );

    set(&mut sim, id, 0.9, 0.0, 0.9, 0.0);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change(
            "feed",
            "flee",
            Cause::Interrupted,
            "fear > 0.5",
            &["idle", "feed"]
        )
    );
    assert_eq!(sim.stack(id), ["idle", "feed"]);
    assert_eq!(sim.agent(id).mind.depth, 2);
}

#[test]
fn a_lower_level_never_interrupts_a_higher_one() {
    let (mut sim, id, _dir) = probe("", "");
    set(&mut sim, id, 0.0, 0.0, 0.9, 0.0);
    sim.step();
    assert_eq!(sim.behavior(id), "flee");
    // Every lower level fires at once, for a while: flee stays.
    set(&mut sim, id, 0.9, 0.9, 0.9, 0.9);
    let before = sim.changes(id).len();
    sim.run(40);
    assert_eq!(sim.behavior(id), "flee");
    assert_eq!(sim.changes(id).len(), before, "{:?}", sim.changes(id));
    assert_eq!(sim.stack(id), ["idle"]);
}

#[test]
fn equal_levels_may_interrupt_each_other_unless_the_behavior_forbids_it() {
    let (mut sim, id, _dir) = probe("", "");
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step();
    set(&mut sim, id, 0.9, 0.9, 0.0, 0.0);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change(
            "feed",
            "court",
            Cause::Interrupted,
            "libido > 0.5",
            &["idle", "feed"]
        )
    );
    // The interrupted one cannot interrupt back while it waits on the stack.
    sim.run(10);
    assert_eq!(sim.behavior(id), "court");

    let (mut sim, id, _dir) = probe(", equal_may_interrupt: false", "");
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step();
    set(&mut sim, id, 0.9, 0.9, 0.0, 0.0);
    sim.run(10);
    assert_eq!(
        sim.behavior(id),
        "feed",
        "feed forbids equal-level interrupts"
    );
    // A higher level still interrupts it.
    set(&mut sim, id, 0.9, 0.9, 0.9, 0.0);
    sim.step();
    assert_eq!(sim.behavior(id), "flee");
}

#[test]
fn the_stacked_behavior_resumes_when_it_outranks_the_newly_triggered_one() {
    let (mut sim, id, _dir) = probe("", "");
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step(); // idle → feed
    set(&mut sim, id, 0.9, 0.0, 0.9, 0.0);
    sim.step(); // feed → flee, stack [idle, feed]
                // Flee completes while rest (level 3) fires: feed (level 2) outranks it and resumes.
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.9);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change("flee", "feed", Cause::Resumed, "fear < 0.5", &["idle"])
    );
    // Feed completes while rest fires: rest (3) outranks idle (4) on the stack, so rest starts
    // and idle stays stacked.
    set(&mut sim, id, 0.0, 0.0, 0.0, 0.9);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change("feed", "rest", Cause::Completed, "hunger < 0.5", &["idle"])
    );
    // Rest completes with nothing new: idle resumes from the stack.
    set(&mut sim, id, 0.0, 0.0, 0.0, 0.0);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change("rest", "idle", Cause::Resumed, "fatigue < 0.5", &[])
    );
}

#[test]
fn an_equal_new_behavior_starts_and_the_stacked_one_keeps_waiting() {
    let (mut sim, id, _dir) = probe("", "");
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step(); // idle → feed
    set(&mut sim, id, 0.9, 0.0, 0.9, 0.0);
    sim.step(); // feed → flee
                // Flee completes while court (level 2, like feed) fires: the stacked feed does not outrank
                // it, so court starts and feed stays on the stack.
    set(&mut sim, id, 0.9, 0.9, 0.0, 0.0);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change(
            "flee",
            "court",
            Cause::Completed,
            "fear < 0.5",
            &["idle", "feed"]
        )
    );
    // Court completes: feed resumes, then idle when feed completes.
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change("court", "feed", Cause::Resumed, "libido < 0.5", &["idle"])
    );
    set(&mut sim, id, 0.0, 0.0, 0.0, 0.0);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change("feed", "idle", Cause::Resumed, "hunger < 0.5", &[])
    );
}

#[test]
fn stacked_behaviors_already_done_are_dropped_on_resume() {
    let (mut sim, id, _dir) = probe("", "");
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step(); // idle → feed
    set(&mut sim, id, 0.9, 0.0, 0.9, 0.0);
    sim.step(); // feed → flee
                // Both flee's and feed's completions hold: feed is dropped, idle resumes.
    set(&mut sim, id, 0.0, 0.0, 0.0, 0.0);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change("flee", "idle", Cause::Resumed, "fear < 0.5", &[])
    );
}

#[test]
fn transitions_are_recorded_as_events_with_cause_condition_and_stack() {
    let (mut sim, id, _dir) = probe("", "");
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step();
    let sp = &sim.pipeline.species.species[0];
    let (feed, idle) = (
        sp.behavior_index("feed").unwrap(),
        sp.behavior_index("idle").unwrap(),
    );
    let transitions: Vec<&Event> = sim
        .pipeline
        .events
        .iter()
        .filter(|e| matches!(e, Event::Transition { .. }))
        .collect();
    assert_eq!(
        transitions,
        [&Event::Transition {
            agent: id,
            species: 0,
            from: idle,
            to: feed,
            cause: Cause::Interrupted,
            condition: Some("hunger > 0.5".into()),
            stack: vec![idle],
        }]
    );
    assert_eq!(sim.pipeline.stats.transitions, 1);
    assert_eq!(Cause::Interrupted.name(), "interrupted");
}

#[test]
fn min_time_delays_completion_and_equal_interrupts_but_not_higher_ones() {
    // feed must run 1 s (20 ticks) before it may complete or be interrupted by court.
    let (mut sim, id, _dir) = probe(", min_time: 1.0", "");
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step();
    let entered = sim.world.tick - 1;
    set(&mut sim, id, 0.0, 0.9, 0.0, 0.0); // done holds and court fires
    let t = sim
        .run_until(40, |s| s.behavior(id) != "feed")
        .expect("feed ends");
    let ended = sim.last_change(id);
    assert_eq!(ended.tick - entered, 20, "{ended:?}");
    assert_eq!(
        (ended.to.as_str(), ended.cause),
        ("court", Cause::Completed)
    );
    assert!(t > 1);

    // A higher level interrupts at once.
    let (mut sim, id, _dir) = probe(", min_time: 1.0", "");
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step();
    set(&mut sim, id, 0.9, 0.0, 0.9, 0.0);
    sim.step();
    assert_eq!(sim.behavior(id), "flee");
}

#[test]
fn behaviors_run_half_a_second_unless_the_species_says_otherwise() {
    // The probe as written, without any min_time: feed completes 10 ticks (0.5 s) after it
    // started, not on the tick after its done holds.
    let (mut sim, id, _dir) = probe_text(
        &PROBE
            .replace("EXTRA_FEED", "")
            .replace("EXTRA_REST", "")
            .replace("NO_MIN", ""),
    );
    set(&mut sim, id, 0.9, 0.0, 0.0, 0.0);
    sim.step();
    let entered = sim.world.tick - 1;
    set(&mut sim, id, 0.0, 0.0, 0.0, 0.0);
    sim.run_until(40, |s| s.behavior(id) != "feed")
        .expect("feed ends");
    assert_eq!(sim.last_change(id).tick - entered, 10);
}

#[test]
fn cooldown_keeps_a_completed_behavior_from_restarting() {
    // rest may not restart for 2 s (40 ticks) after it completes.
    let (mut sim, id, _dir) = probe("", ", cooldown: 2.0");
    set(&mut sim, id, 0.0, 0.0, 0.0, 0.9);
    sim.step();
    assert_eq!(sim.behavior(id), "rest");
    set(&mut sim, id, 0.0, 0.0, 0.0, 0.0);
    sim.step();
    assert_eq!(sim.behavior(id), "idle");
    let completed = sim.world.tick - 1;
    set(&mut sim, id, 0.0, 0.0, 0.0, 0.9);
    sim.run_until(100, |s| s.behavior(id) == "rest")
        .expect("rest restarts after the cooldown");
    let restarted = sim.last_change(id).tick;
    assert_eq!(restarted - completed, 40);
}

#[test]
fn latch_gives_hysteresis_between_its_on_and_off_conditions() {
    let text = r#"
Species(
    name: "latch_probe",
    drives: (native: false),
    initial: "idle",
    behaviors: [
        Behavior(
            name: "graze",
            priority: 1,
            when: Latch(on: Above(Drive(Hunger), 0.8), off: Below(Drive(Hunger), 0.3)),
            done: TimeIn(0.25),
            steer: Cruise(speed: 0.2),
        ),
        Behavior(name: "idle", priority: 2, steer: Wander()),
    ],
)
"#;
    let dir = folder(&[("latch_probe.ron", text)]);
    let sp = load(&dir.path().join("latch_probe.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let id = sim.spawn("latch_probe", Vec3::ZERO, 0.0);
    let hunger = |sim: &mut Sim, h: f32| sim.agent_mut(id).drives.hunger = h;

    // 0.6 is below the on threshold: nothing.
    hunger(&mut sim, 0.6);
    sim.run(10);
    assert_eq!(sim.behavior(id), "idle");
    // 0.9 latches it on.
    hunger(&mut sim, 0.9);
    sim.step();
    assert_eq!(
        key(&sim.last_change(id)),
        change(
            "idle",
            "graze",
            Cause::Interrupted,
            "latched on (hunger > 0.8) until (hunger < 0.3)",
            &["idle"]
        )
    );
    sim.run_until(10, |s| s.behavior(id) == "idle")
        .expect("graze completes");
    assert_eq!(
        key(&sim.last_change(id)),
        change("graze", "idle", Cause::Resumed, "0.25 s in behavior", &[])
    );
    // Back at 0.6 it is still latched: graze starts again (a plain `hunger > 0.8` would not).
    hunger(&mut sim, 0.6);
    sim.step();
    assert_eq!(sim.behavior(id), "graze");
    sim.run_until(10, |s| s.behavior(id) == "idle")
        .expect("graze completes");
    // Below the off threshold the latch releases; 0.6 no longer starts it.
    hunger(&mut sim, 0.2);
    sim.step();
    hunger(&mut sim, 0.6);
    sim.run(20);
    assert_eq!(sim.behavior(id), "idle");
    assert_eq!(
        sim.changes(id).iter().filter(|c| c.to == "graze").count(),
        2
    );
}

/// A script called on entering a behavior draws from the agent's random stream as arbitration
/// left it, and its draws are kept: the stream never hands the same numbers out twice.
#[test]
fn an_on_enter_call_draws_from_the_stream_and_keeps_it_moving() {
    let species = r#"
Species(
    name: "dice",
    drives: (native: false, hunger: Fixed(0.0)),
    script: Some("dice.rhai"),
    memory: { "a": Float(None), "b": Float(None) },
    initial: "idle",
    behaviors: [
        Behavior(name: "roll", priority: 1, when: Above(Drive(Hunger), 0.5), on_enter: [Call("roll")], steer: Stop),
        Behavior(name: "idle", priority: 4, steer: Stop),
    ],
)
"#;
    let script = r#"fn roll() { this["a"] = this.random(); this["b"] = this.random(); }"#;
    let dir = folder(&[("dice.ron", species), ("dice.rhai", script)]);
    let sp = load(&dir.path().join("dice.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let id = sim.spawn("dice", Vec3::ZERO, 0.0);
    sim.run(2);
    sim.set_hunger(id, 0.9);
    sim.step();
    assert_eq!(sim.behavior(id), "roll");
    assert!(sim.script_errors().is_empty(), "{:?}", sim.script_errors());
    let a = sim.agent(id);
    let drawn = |key: &str| match a.memory.iter().find(|(k, _)| &**k == key) {
        Some((_, shoal::world::MemValue::Float(x))) => *x,
        other => panic!("{key}: {other:?}"),
    };
    let (x, y) = (drawn("a"), drawn("b"));
    assert_ne!(x, y);
    // What the stream gives next is neither of the script's draws.
    let mut rng = a.rng;
    let next: Vec<f32> = (0..4).map(|_| rng.next_f32()).collect();
    assert!(!next.contains(&x) && !next.contains(&y), "{x} {y} {next:?}");
}

/// A cruiser that avoids moving obstacles, with `FOCUS` in place of its `focus`, and an alarm
/// (level 1) that fires when another fish comes within 3.
const CRUISER: &str = r#"
Species(
    name: "cruiser",
    drives: (native: false, hunger: Fixed(0.0)),
    relations: (see_others: true),
    initial: "cruise",
    behaviors: [
        Behavior(name: "alarm", priority: 1, when: Within(Other, 3.0), steer: Stop, min_time: 0.0),
        Behavior(name: "cruise", priority: 2, steer: Priority([AvoidDynamic(), Cruise(speed: 0.5)])FOCUS),
    ],
)
"#;

const INTRUDER: &str = r#"
Species(
    name: "intruder",
    drives: (native: false, hunger: Fixed(0.0)),
    initial: "go",
    behaviors: [Behavior(name: "go", priority: 1, steer: Cruise(speed: 1.0))],
)
"#;

/// A cruiser heading +z and an intruder coming head-on, a little to its left; runs until the
/// cruiser's alarm fires (or 200 ticks). Returns the cruiser's largest |yaw| while it cruised
/// and whether the alarm fired.
fn head_on(focus: &str) -> (f32, bool) {
    let cruiser = CRUISER.replace("FOCUS", focus);
    let dir = folder(&[("cruiser.ron", &cruiser), ("intruder.ron", INTRUDER)]);
    let species = vec![
        load(&dir.path().join("cruiser.ron"), dir.path()),
        load(&dir.path().join("intruder.ron"), dir.path()),
    ];
    let mut sim = Sim::new(species, Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let me = sim.spawn("cruiser", Vec3::ZERO, 0.0);
    sim.spawn("intruder", Vec3::new(0.4, 0.0, 9.0), std::f32::consts::PI);
    let mut turned = 0.0f32;
    let alarm = sim
        .run_until(200, |s| {
            s.behavior(me) == "alarm" || {
                turned = turned.max(s.agent(me).yaw.abs());
                false
            }
        })
        .is_some();
    (turned, alarm)
}

/// Seed 000 §1's focuser: a behavior focused on obstacles steers as if the fish coming at it
/// were not there (its heading stays exactly +z), while the same behavior unfocused turns away;
/// the alarm, a condition, still sees the intruder in both.
#[test]
fn a_focused_behavior_ignores_a_moving_obstacle_but_conditions_still_see_it() {
    let (unfocused, alarm) = head_on("");
    assert!(unfocused > 0.1, "unfocused, it turns away: {unfocused}");
    assert!(alarm);
    let (focused, alarm) = head_on(", focus: Some([Obstacle])");
    assert_eq!(focused, 0.0, "focused on obstacles, it keeps its heading");
    assert!(alarm, "the alarm's `when` reads everything");
    // Listing the intruder's category brings the avoidance back.
    let (with_other, _) = head_on(", focus: Some([Other, Obstacle])");
    assert_eq!(with_other, unfocused);
}

#[test]
fn above_and_below_are_strict_and_every_latch_keeps_its_own_bit() {
    let text = r#"
Species(
    name: "edge_probe",
    drives: (native: false),
    initial: "idle",
    behaviors: [
        Behavior(
            name: "graze",
            priority: 1,
            when: Latch(on: Above(Drive(Hunger), 0.8), off: Below(Drive(Hunger), 0.3)),
            done: TimeIn(0.25),
            steer: Cruise(speed: 0.2),
        ),
        Behavior(
            name: "hide",
            priority: 2,
            when: Latch(on: Above(Drive(Fear), 0.8), off: Below(Drive(Fear), 0.3)),
            done: TimeIn(0.25),
            steer: Cruise(speed: 0.2),
        ),
        Behavior(
            name: "court",
            priority: 3,
            when: Above(Drive(Libido), 0.5),
            done: Not(Above(Drive(Libido), 0.5)),
            steer: Cruise(speed: 0.2),
        ),
        Behavior(
            name: "doze",
            priority: 4,
            when: Below(Drive(Libido), 0.25),
            done: Not(Below(Drive(Libido), 0.25)),
            steer: Cruise(speed: 0.2),
        ),
        Behavior(name: "idle", priority: 5, steer: Wander()),
    ],
)
"#;
    let dir = folder(&[("edge_probe.ron", text)]);
    let sp = load(&dir.path().join("edge_probe.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let id = sim.spawn("edge_probe", Vec3::ZERO, 0.0);
    let drives = |sim: &mut Sim, fear: f32, libido: f32| {
        let d = &mut sim.agent_mut(id).drives;
        (d.hunger, d.fear, d.libido) = (0.0, fear, libido);
    };

    // Exactly at a threshold is neither above nor below it.
    drives(&mut sim, 0.0, 0.5);
    sim.run(3);
    assert_eq!(sim.behavior(id), "idle");
    drives(&mut sim, 0.0, 0.25);
    sim.run(3);
    assert_eq!(sim.behavior(id), "idle");
    drives(&mut sim, 0.0, 0.249_999);
    sim.step();
    assert_eq!(sim.behavior(id), "doze");
    drives(&mut sim, 0.0, 0.3);
    sim.run_until(20, |s| s.behavior(id) == "idle")
        .expect("doze ends");
    drives(&mut sim, 0.0, 0.500_001);
    sim.step();
    assert_eq!(sim.behavior(id), "court");
    drives(&mut sim, 0.0, 0.3);
    sim.run_until(20, |s| s.behavior(id) == "idle")
        .expect("court ends");

    // The second latch (its own bit) holds between its thresholds like the first.
    drives(&mut sim, 0.9, 0.3);
    sim.step();
    assert_eq!(sim.behavior(id), "hide");
    sim.run_until(10, |s| s.behavior(id) == "idle")
        .expect("hide completes");
    drives(&mut sim, 0.6, 0.3);
    sim.step();
    assert_eq!(sim.behavior(id), "hide", "still latched at 0.6");
    sim.run_until(10, |s| s.behavior(id) == "idle")
        .expect("hide completes");
    drives(&mut sim, 0.2, 0.3);
    sim.step();
    drives(&mut sim, 0.6, 0.3);
    sim.run(20);
    assert_eq!(sim.behavior(id), "idle", "released below 0.3");
}

#[test]
fn smells_needs_something_perceived_but_not_seen() {
    let text = r#"
Species(
    name: "nose_probe",
    drives: (native: false),
    senses: (vision_radius: 5.0, smell_radius: 20.0),
    initial: "idle",
    behaviors: [
        Behavior(name: "sniff", priority: 1, when: Smells(Kin), steer: Stop),
        Behavior(name: "idle", priority: 2, steer: Stop),
    ],
)
"#;
    let dir = folder(&[("nose_probe.ron", text)]);
    let sp = load(&dir.path().join("nose_probe.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let a = sim.spawn("nose_probe", Vec3::ZERO, 0.0);
    // Alone: nothing perceived, nothing smelt.
    sim.run(3);
    assert_eq!(sim.behavior(a), "idle");
    // A kin 3 ahead is seen, so it is not smelt only.
    let b = sim.spawn("nose_probe", Vec3::new(0.0, 0.0, 3.0), 0.0);
    sim.run(3);
    assert_eq!(sim.behavior(a), "idle");
    // 12 away it is beyond sight but within smell.
    sim.teleport(b, Vec3::new(0.0, 0.0, 12.0));
    sim.step();
    assert_eq!(sim.behavior(a), "sniff");
}

/// A species whose only non-idle behavior, "on", starts when `WHEN` holds and ends when it
/// does not; it and its idle behavior stand still, so a test can place it and read one tick.
fn one_condition(when: &str, done: &str) -> (Sim, AgentId, tempfile::TempDir) {
    let text = format!(
        r#"
Species(
    name: "cond_probe",
    drives: (native: false, hunger: Fixed(0.0)),
    initial: "idle",
    behaviors: [
        Behavior(name: "on", priority: 1, when: {when}, done: {done}, steer: Stop, min_time: 0.0),
        Behavior(name: "idle", priority: 2, steer: Stop),
    ],
)
"#
    );
    let dir = folder(&[("cond_probe.ron", &text)]);
    let sp = load(&dir.path().join("cond_probe.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let id = sim.spawn("cond_probe", Vec3::ZERO, 0.0);
    (sim, id, dir)
}

/// `NearBounds(m)`: closer than `m` to any face of the world's box, on any axis, low or high;
/// exactly `m` away is not near.
#[test]
fn near_bounds_is_any_face_closer_than_the_margin() {
    let (mut sim, id, _dir) = one_condition("NearBounds(5.0)", "Not(NearBounds(5.0))");
    // (position, near?) — the box is ±100: -96 is 4 from the low face, 96 is 4 from the high
    // one, ±95 exactly 5 (neither), the centre 100 from every face.
    let cases = [
        (Vec3::ZERO, false),
        (Vec3::new(-96.0, 0.0, 0.0), true),
        (Vec3::new(0.0, 0.0, 96.0), true),
        (Vec3::new(0.0, -95.0, 0.0), false),
        (Vec3::new(95.0, 0.0, 0.0), false),
        (Vec3::new(0.0, 96.0, 0.0), true),
        (Vec3::new(50.0, -50.0, 50.0), false),
    ];
    for (pos, near) in cases {
        sim.teleport(id, pos);
        sim.step();
        let want = if near { "on" } else { "idle" };
        assert_eq!(sim.behavior(id), want, "at {pos}");
    }
}

/// `ObstacleNear`: a rock 1.3 ahead puts the static pressure above M_min; with no rock, or one
/// far away, the pressure is 0 and the condition does not hold.
#[test]
fn obstacle_near_needs_a_rock_within_reach() {
    use shoal::world::Shape;
    let (mut sim, id, _dir) = one_condition("ObstacleNear", "Not(ObstacleNear)");
    sim.run(3);
    assert_eq!(sim.behavior(id), "idle", "open water");
    sim.world.add_obstacle(Shape::Sphere {
        center: Vec3::new(0.0, 0.0, 60.0),
        radius: 1.5,
    });
    sim.run(3);
    assert_eq!(sim.behavior(id), "idle", "a rock 58 away");
    sim.world.add_obstacle(Shape::Sphere {
        center: Vec3::new(0.0, 0.0, 2.8),
        radius: 1.5,
    });
    sim.step();
    assert_eq!(sim.behavior(id), "on", "a rock 1.3 ahead");
}

/// `TrafficNear`: seed 000 §4.2's dynamic avoidance has something to answer — another fish
/// coming head-on; a fish swimming away from it does not count.
#[test]
fn traffic_near_is_a_fish_on_a_collision_course() {
    let run = |intruder_pos: Vec3, intruder_yaw: f32| {
        let watcher = r#"
Species(
    name: "watcher",
    drives: (native: false, hunger: Fixed(0.0)),
    relations: (see_others: true),
    initial: "idle",
    behaviors: [
        Behavior(name: "on", priority: 1, when: TrafficNear, done: Not(TrafficNear), steer: Stop, min_time: 0.0),
        Behavior(name: "idle", priority: 2, steer: Cruise(speed: 0.5)),
    ],
)
"#;
        let dir = folder(&[("watcher.ron", watcher), ("intruder.ron", INTRUDER)]);
        let species = vec![
            load(&dir.path().join("watcher.ron"), dir.path()),
            load(&dir.path().join("intruder.ron"), dir.path()),
        ];
        let mut sim = Sim::new(species, Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
        let me = sim.spawn("watcher", Vec3::ZERO, 0.0);
        sim.spawn("intruder", intruder_pos, intruder_yaw);
        sim.run_until(100, |s| s.behavior(me) == "on").is_some()
    };
    assert!(
        run(Vec3::new(0.4, 0.0, 9.0), std::f32::consts::PI),
        "head-on"
    );
    assert!(
        !run(Vec3::new(0.0, 0.0, 9.0), 0.0),
        "ahead, swimming away faster"
    );
}

/// `Chance(p)`: fires with probability p·dt per tick, i.e. about p times a second while it is
/// looked at. At p = 2 and dt = 0.05 that is 0.1 of the idle ticks.
#[test]
fn chance_fires_p_times_a_second() {
    let (mut sim, id, _dir) = one_condition("Chance(2.0)", "TimeIn(0.01)");
    let (mut idle_ticks, mut starts) = (0u32, 0u32);
    for _ in 0..4000 {
        let was_idle = sim.behavior(id) == "idle";
        sim.step();
        if was_idle {
            idle_ticks += 1;
            starts += u32::from(sim.behavior(id) == "on");
        }
    }
    let rate = starts as f32 / idle_ticks as f32;
    // 0.1 ± about 4 standard deviations of a binomial over ~3,600 idle ticks (σ ≈ 0.005).
    assert!(
        (0.08..0.12).contains(&rate),
        "{starts} of {idle_ticks}: {rate}"
    );
}

/// Value expressions: `1 − v`, `a·b` and `a + b` each computed as written. With fear 0.2 and
/// libido 0.3, (1 − 0.2) + 0.3·3 = 1.7 is above 1.5; with fear 0.6, 0.4 + 0.9 = 1.3 is not.
#[test]
fn one_minus_mul_and_add_compute_what_they_say() {
    let v = "Above(Add(OneMinus(Drive(Fear)), Mul(Drive(Libido), Const(3.0))), 1.5)";
    let (mut sim, id, _dir) = one_condition(v, &format!("Not({v})"));
    for (fear, on) in [(0.2, true), (0.6, false), (0.2, true)] {
        let d = &mut sim.agent_mut(id).drives;
        (d.fear, d.libido) = (fear, 0.3);
        sim.step();
        assert_eq!(
            sim.behavior(id),
            if on { "on" } else { "idle" },
            "fear {fear}"
        );
    }
}

/// Two behaviors triggered on the same tick: the higher level starts, though the lower one,
/// declared after it, holds too.
#[test]
fn of_two_triggered_behaviors_the_higher_starts() {
    let text = r#"
Species(
    name: "two",
    drives: (native: false, hunger: Fixed(0.0)),
    initial: "idle",
    behaviors: [
        Behavior(name: "high", priority: 1, when: Above(Drive(Fear), 0.5), steer: Stop),
        Behavior(name: "low", priority: 2, when: Above(Drive(Fear), 0.5), steer: Stop),
        Behavior(name: "idle", priority: 3, steer: Stop),
    ],
)
"#;
    let dir = folder(&[("two.ron", text)]);
    let sp = load(&dir.path().join("two.ron"), dir.path());
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let id = sim.spawn("two", Vec3::ZERO, 0.0);
    sim.step();
    assert_eq!(sim.behavior(id), "idle");
    sim.agent_mut(id).drives.fear = 0.9;
    sim.step();
    assert_eq!(sim.behavior(id), "high");
}

#[test]
fn a_lone_behavior_ends_only_by_its_own_completion() {
    // One behavior that never completes: no change, ever.
    let lone = |done: &str| {
        format!(
            r#"Species(
    name: "probe",
    drives: (native: false, hunger: Fixed(0.0)),
    initial: "swim",
    behaviors: [
        Behavior(name: "swim", priority: 1, min_time: 0.0{done}, steer: Cruise(speed: 1.0)),
    ],
)"#
        )
    };
    let (mut sim, id, _dir) = probe_text(&lone(""));
    sim.run(20);
    assert!(sim.changes(id).is_empty(), "{:?}", sim.changes(id));
    assert_eq!(sim.behavior(id), "swim");
    // The same behavior with a completion: it ends when that holds and starts again, the
    // initial behavior, with the condition as its cause.
    let (mut sim, id, _dir) = probe_text(&lone(", done: Above(Drive(Hunger), 0.5)"));
    sim.run(3);
    assert!(sim.changes(id).is_empty());
    sim.agent_mut(id).drives.hunger = 0.9;
    sim.step();
    let c = sim.last_change(id);
    assert_eq!(
        (c.from.as_str(), c.to.as_str(), c.cause),
        ("swim", "swim", Cause::Completed)
    );
}
