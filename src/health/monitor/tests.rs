//! Unit tests of the run-health monitor: stops and frozen episodes, the pitch limit, switches
//! and flips, turning, pairs, obstacles, messages, and the report read back from JSON.

use super::place::signed_distance;
use super::track::SCAN_OBSTACLES;
use super::*;
use crate::events::MessageKind;
use crate::health::Figure;
use crate::health::{Health, NextTo};
use crate::scenario::normalize;
use crate::species::{load_species_str, Species};
use crate::world::Shape;
use crate::world::{Aabb, AgentId};
use std::path::Path;
use std::sync::Arc;

fn species(name: &str) -> Species {
    let text = format!(
        r#"Species(
    name: "{name}",
    script: None,
    drives: (native: false),
    initial: "swim",
    behaviors: [
        Behavior(name: "swim", priority: 2, steer: Priority([AvoidStatic(), Cruise(speed: 1.0)])),
        Behavior(name: "rest", priority: 2, when: Above(Speed, 100.0), steer: Priority([AvoidStatic(), Stop])),
        Behavior(name: "dart", priority: 2, when: Above(Speed, 200.0), steer: Blend([(w: 1.0, steer: Arrive(target: Point(0.0, 0.0, 0.0)))])),
        Behavior(name: "hold", priority: 2, when: Above(Speed, 300.0), steer: Priority([AvoidStatic(), HoldStation()])),
    ],
)"#
    );
    load_species_str(
        Path::new("fish.ron"),
        &text,
        &normalize(Path::new(".")),
        &Default::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// A hand-built world: agents placed and moved by the test, ticks counted by hand.
struct Rig {
    world: World,
    pipe: Pipeline,
    monitor: Monitor,
}

const SWIM: u16 = 0;
const REST: u16 = 1;
const DT: f32 = 0.05;

impl Rig {
    fn new(names: &[&str]) -> Rig {
        let set = SpeciesSet::new(names.iter().map(|n| Arc::new(species(n))).collect())
            .unwrap_or_else(|e| panic!("{e}"));
        let monitor = Monitor::new(&set, DT);
        Rig {
            world: World::new(Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0)), DT, 1),
            pipe: Pipeline::new(Arc::new(set)),
            monitor,
        }
    }

    /// Adds an agent of species `s` at `pos`, heading +Z at speed 1.
    fn add(&mut self, s: usize, pos: Vec3) -> usize {
        self.pipe.spawn(&mut self.world, s, pos, 0.0, 0.0);
        let a = self.world.agents.last_mut().unwrap();
        a.speed = 1.0;
        self.world.agents.len() - 1
    }

    fn agent(&mut self, i: usize) -> &mut crate::world::Agent {
        &mut self.world.agents[i]
    }

    /// One tick with these events.
    fn tick(&mut self, events: &[Event]) {
        self.world.tick += 1;
        self.monitor.observe_events(&self.world, events);
    }

    fn health(&self) -> Health {
        self.monitor.report()
    }
}

fn transition(agent: u32, from: u16, to: u16) -> Event {
    Event::Transition {
        agent: AgentId(agent),
        species: 0,
        from,
        to,
        cause: crate::events::Cause::Activated,
        condition: None,
        stack: Vec::new(),
    }
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn may_stop_looks_through_the_recipe_tree() {
    let sp = species("fish");
    let flags: Vec<bool> = sp.behaviors.iter().map(|b| may_stop(&b.steer)).collect();
    assert_eq!(flags, [false, true, true, true]);
}

#[test]
fn a_body_that_goes_nowhere_is_stopped_whatever_its_speed() {
    let mut r = Rig::new(&["fish"]);
    // Full speed into a wall of the world for 6 s: it never moves.
    let pinned = r.add(0, Vec3::new(50.0, 0.0, 0.0));
    let free = r.add(0, Vec3::new(0.0, 0.0, 0.0));
    for _ in 1..=120u64 {
        r.agent(pinned).speed = 2.0;
        r.agent(free).speed = 2.0;
        r.agent(free).pos.z += 2.0 * DT;
        r.tick(&[]);
    }
    let h = r.health();
    let s = &h.species[0];
    // The first observation has nothing to compare with: 119 of 240 agent-ticks stopped.
    assert!(
        close(s.stopped_share, 119.0 / 240.0, 1e-12),
        "{}",
        s.stopped_share
    );
    assert_eq!(s.frozen_agents, 1);
}

#[test]
fn stopped_six_seconds_is_frozen_four_is_not() {
    let mut r = Rig::new(&["fish"]);
    r.world.add_obstacle(Shape::Sphere {
        center: Vec3::new(0.0, 0.0, 3.0),
        radius: 1.0,
    });
    let long = r.add(0, Vec3::ZERO); // stopped 7 s in swim
    let short = r.add(0, Vec3::new(20.0, 0.0, 0.0)); // stopped 4 s, then swims
    let resting = r.add(0, Vec3::new(-20.0, 0.0, 0.0)); // stopped 7 s in rest: allowed
    let edge = r.add(0, Vec3::new(0.0, 20.0, 0.0)); // stopped 99 ticks, then 100 ticks
    r.agent(resting).mind.current = REST;
    for t in 1..=140u64 {
        r.agent(long).speed = 0.0;
        r.agent(short).speed = if t <= 80 { 0.01 } else { 1.0 };
        r.agent(resting).speed = 0.0;
        r.agent(edge).speed = if t <= 99 || (101..=200).contains(&t) {
            0.0
        } else {
            1.0
        };
        // Bodies go as far as their speed takes them.
        for id in [long, short, resting, edge] {
            let a = r.agent(id);
            a.pos.x += a.speed * DT;
        }
        r.tick(&[]);
    }
    let h = r.health();
    let s = &h.species[0];
    // Stopped in swim: 140 + 80 + (99 + 40) of 3 × 140 agent-ticks.
    let swim = &s.behaviors[SWIM as usize];
    assert!(!swim.may_stop && s.behaviors[REST as usize].may_stop);
    assert_eq!(swim.agent_ticks, 420);
    assert!(close(swim.stopped_share, 359.0 / 420.0, 1e-12));
    assert!(close(s.stopped_share, 359.0 / 420.0, 1e-12));
    assert_eq!(s.behaviors[REST as usize].stopped_share, 1.0);
    // Only the 7-s stop is frozen: 4 s and 99 ticks (4.95 s) are not, the resting one may.
    assert_eq!(s.frozen_agents, 1);
    assert_eq!(swim.frozen_agents, 1);
    assert_eq!(s.behaviors[REST as usize].frozen_agents, 0);
    let f = &s.frozen[0];
    assert_eq!((f.agent, f.start_tick, f.behavior.as_str()), (0, 1, "swim"));
    assert!(close(f.seconds, 7.0, 1e-9));
    assert_eq!(
        f.near,
        NextTo::Obstacle {
            id: 0,
            label: "sphere 0".into(),
            distance: 2.0
        }
    );
    assert_eq!(swim.frozen_at[0].place, "sphere 0");
    let w = h.warnings();
    let frozen = w.iter().find(|w| w.figure == Figure::Frozen).unwrap();
    assert_eq!(
        frozen.message,
        "fish: 1 agent stopped ≥ 5 s in swim, at sphere 0"
    );
    assert_eq!((frozen.tick, frozen.agent), (Some(1), Some(0)));
    assert!(w.iter().any(|w| w.figure == Figure::Stopped));
}

#[test]
fn a_stop_of_exactly_five_seconds_freezes_and_ends_at_death() {
    let mut r = Rig::new(&["fish"]);
    let a = r.add(0, Vec3::ZERO);
    let b = r.add(0, Vec3::new(3.0, 0.0, 0.0));
    for _ in 0..100 {
        r.agent(a).speed = 0.0;
        r.tick(&[]);
    }
    let id = r.world.agents[a].id;
    r.world.agents.remove(a);
    r.tick(&[Event::Death {
        agent: id,
        species: 0,
        cause: "caught",
    }]);
    let _ = b;
    let h = r.health();
    let f = &h.species[0].frozen[0];
    assert!(close(f.seconds, 5.0, 1e-9), "{f:?}");
    // No obstacle: the nearest agent.
    assert_eq!(
        f.near,
        NextTo::Agent {
            id: 1,
            species: "fish".into(),
            distance: 3.0
        }
    );
    assert_eq!(h.species[0].behaviors[0].frozen_at[0].place, "open water");
}

#[test]
fn pitch_limit_share_counts_ticks_at_the_limit() {
    let mut r = Rig::new(&["fish"]);
    let a = r.add(0, Vec3::ZERO);
    let limit = r.pipe.species.species[0].def.body.limits.pitch_limit();
    for t in 1..=100u64 {
        // 30 ticks at the limit, 70 just outside the margin.
        r.agent(a).pitch = if (41..=70).contains(&t) {
            -limit
        } else {
            limit - 0.02
        };
        r.tick(&[]);
    }
    let s = &r.health().species[0];
    assert!(close(s.pitch_limit_share, 0.3, 1e-12));
    assert_eq!(s.pitch_limit_at, Some(Spot { tick: 41, agent: 0 }));
}

#[test]
fn switches_short_episodes_and_flips() {
    let mut r = Rig::new(&["fish"]);
    r.add(0, Vec3::ZERO);
    r.add(0, Vec3::new(5.0, 0.0, 0.0));
    // Agent 0 switches during the steps from ticks 10, 14, 40 and 41 (seen after ticks 11,
    // 15, 41, 42): episodes 10–14 (short, flips back), 14–40, 40–41 (one tick, short, flips
    // back); the one it spawned in (0–10) was not chosen and is not counted.
    for t in 1..=100u64 {
        let events: Vec<Event> = match t {
            11 => vec![transition(0, SWIM, REST)],
            15 => vec![transition(0, REST, SWIM)],
            41 => vec![transition(0, SWIM, REST)],
            42 => vec![transition(0, REST, SWIM)],
            _ => vec![],
        };
        r.tick(&events);
    }
    let h = r.health();
    let s = &h.species[0];
    assert_eq!(s.transitions, 4);
    // 4 transitions over 2 agents × 5 s.
    assert!(close(s.switch_rate, 0.4, 1e-12));
    assert_eq!(s.episodes, 3);
    assert!(close(s.short_episode_share, 2.0 / 3.0, 1e-12));
    assert!(close(s.one_tick_share, 1.0 / 3.0, 1e-12));
    assert_eq!(s.short_episode_at, Some(Spot { tick: 14, agent: 0 }));
    assert_eq!(s.flips.len(), 1);
    let f = &s.flips[0];
    assert_eq!((f.a.as_str(), f.b.as_str(), f.count), ("swim", "rest", 2));
    assert_eq!(f.first, Spot { tick: 10, agent: 0 });
    assert_eq!(s.most_switches_at, Some(Spot { tick: 41, agent: 0 }));
    // Three episodes are too few to call flicker: no warning until there are 20.
    let w = h.warnings();
    assert!(!s.judged(Figure::ShortEpisodes));
    // The tables still show the figure, starred with this reason.
    assert_eq!(
        s.not_judged_because(Figure::ShortEpisodes).as_deref(),
        Some("only 3 episodes, judged from 20")
    );
    assert_eq!(s.not_judged_because(Figure::SwitchRate), None);
    assert!(
        !w.iter().any(|w| w.figure == Figure::ShortEpisodes),
        "{w:?}"
    );
    assert!(!w.iter().any(|w| w.figure == Figure::SwitchRate), "{w:?}");
    let mut many = h.clone();
    many.species[0].episodes = crate::health::MIN_EPISODES;
    assert_eq!(
        many.species[0].not_judged_because(Figure::ShortEpisodes),
        None
    );
    assert!(many
        .warnings()
        .iter()
        .any(|w| w.figure == Figure::ShortEpisodes
            && w.message
                .contains("67% of 20 behavior episodes shorter than 0.5 s, 33% a single tick")));
}

#[test]
fn a_flip_needs_the_reverse_within_half_a_second() {
    let mut r = Rig::new(&["fish"]);
    r.add(0, Vec3::ZERO);
    for t in 1..=60u64 {
        let events: Vec<Event> = match t {
            11 => vec![transition(0, SWIM, REST)],
            // 11 ticks later: 0.55 s, not a flip.
            22 => vec![transition(0, REST, SWIM)],
            // 13 ticks later again, then A → B → C, no flip either.
            35 => vec![transition(0, SWIM, REST)],
            36 => vec![transition(0, REST, 2)],
            _ => vec![],
        };
        r.tick(&events);
    }
    let s = &r.health().species[0];
    assert!(s.flips.is_empty(), "{:?}", s.flips);
    assert_eq!(s.switch_rate, 4.0 / 3.0);
}

#[test]
fn turning_waste_is_one_for_a_steady_turn_and_large_for_a_zigzag() {
    let run = |yaw: &dyn Fn(u64) -> f32| {
        let mut r = Rig::new(&["fish"]);
        let a = r.add(0, Vec3::ZERO);
        for t in 1..=41u64 {
            r.agent(a).yaw = yaw(t);
            r.tick(&[]);
        }
        r.health().species[0].clone()
    };
    let steady = run(&|t| 0.05 * t as f32);
    // Two windows of 20 ticks, each turning 1 rad toward the new heading.
    assert!(close(steady.turning, 2.0, 1e-4), "{}", steady.turning);
    assert!(close(steady.turning_waste.unwrap(), 1.0, 1e-4));
    // Left-right-left on a slow drift: 10 × 0.21 + 10 × 0.19 = 4 rad of turning for 0.2 rad
    // of heading change per window.
    let zigzag = run(&|t| 0.01 * t as f32 + if t % 2 == 1 { 0.2 } else { 0.0 });
    assert!(close(zigzag.turning, 8.0, 1e-3), "{}", zigzag.turning);
    assert!(close(zigzag.net_turning, 0.4, 1e-4));
    assert!(close(zigzag.turning_waste.unwrap(), 20.0, 0.01));
    assert_eq!(zigzag.turning_waste_at, Some(Spot { tick: 1, agent: 0 }));
    let straight = run(&|_| 0.3);
    assert_eq!(straight.turning_waste, None);
}

#[test]
fn pairs_coincide_and_overlap() {
    let mut r = Rig::new(&["fish", "eel"]);
    // Fish are 0.2 wide and 1 long: neighbors within 2, overlapping within 0.18.
    r.add(0, Vec3::new(0.0, 5.0, 0.0));
    r.add(0, Vec3::new(0.0, 5.0, 0.01));
    r.add(0, Vec3::new(0.0, 5.0, 1.0));
    r.add(0, Vec3::new(0.0, 5.0, 10.0));
    r.add(1, Vec3::new(0.0, 5.0, 0.015));
    for _ in 0..10 {
        r.tick(&[]);
    }
    let h = r.health();
    // Two samples (ticks 5 and 10), each: fish 0–1, fish 0–eel, fish 1–eel coincide;
    // fish pairs 0–1, 0–2, 1–2 are neighbors, 0–1 overlaps.
    assert_eq!(h.coincident.samples, 2);
    assert_eq!((h.coincident.max, h.coincident.mean), (3, 3.0));
    assert_eq!(h.coincident.max_at, Some(Spot { tick: 5, agent: 0 }));
    let fish = h.species("fish").unwrap();
    assert_eq!((fish.neighbor_pairs, fish.overlapping_pairs), (6, 2));
    assert!(close(fish.overlap_share, 1.0 / 3.0, 1e-12));
    let eel = h.species("eel").unwrap();
    assert_eq!((eel.neighbor_pairs, eel.overlap_share), (0, 0.0));
}

#[test]
fn the_pair_grid_finds_what_a_scan_finds() {
    let mut r = Rig::new(&["fish", "eel"]);
    let mut rng = crate::world::Rng::new(9, 0);
    for k in 0..400 {
        let p = Vec3::new(
            rng.range(-6.0, 6.0),
            rng.range(-3.0, 3.0),
            rng.range(-6.0, 6.0),
        );
        let i = r.add(k % 2, p);
        if k.is_multiple_of(7) {
            // Some exact duplicates; some eels three times longer, so that eels look
            // three cells out in a grid sized for fish.
            r.agent(i).pos = Vec3::ZERO;
            if k % 2 == 1 {
                r.agent(i).size.z = 3.0;
            }
        }
    }
    let mut grid = PairGrid::default();
    let mut counts = PairCounts::new(2);
    grid.sample(&r.world.agents, &mut counts);
    let (c, n, o) = super::super::pairs::brute_force(&r.world.agents, 2);
    assert_eq!(counts.coincident, c);
    assert_eq!(counts.neighbors, n);
    assert_eq!(counts.overlapping, o);
    assert!(c > 0 && o.iter().all(|&x| x > 0));
}

#[test]
fn agents_inside_or_against_obstacles() {
    // With a few obstacles (each tested), and with many (through the grid): the same.
    let few = obstacle_case(0);
    let many = obstacle_case(2 * SCAN_OBSTACLES);
    assert_eq!(few, many);
    let h = few;
    let o = &h.species[0].obstacles;
    assert_eq!(
        (o.agent_ticks, o.inside_ticks, o.agents_inside),
        (30, 20, 2)
    );
    assert!(close(o.closest.unwrap() as f64, -1.5, 1e-6));
    assert_eq!(o.closest_obstacle.as_deref(), Some("sphere 0"));
    assert_eq!(o.closest_at, Some(Spot { tick: 1, agent: 0 }));
    let w = h.warnings();
    let pen = w
        .iter()
        .find(|w| w.figure == Figure::ObstaclePenetration)
        .unwrap();
    assert!(
        pen.message.starts_with(
            "fish: 30 agent-ticks inside an obstacle or within half a body width of it"
        ),
        "{}",
        pen.message
    );
    assert!(pen
        .message
        .contains("20 inside, 2 agents ever inside; deepest 1.50 inside sphere 0"));
}

/// Five fish among a sphere, a box and a removed sphere, plus `far` small rocks out of
/// their way, for ten ticks.
fn obstacle_case(far: usize) -> Health {
    let mut r = Rig::new(&["fish"]);
    r.world.add_obstacle(Shape::Sphere {
        center: Vec3::new(0.0, 5.0, 0.0),
        radius: 2.0,
    });
    r.world.add_obstacle(Shape::Box(Aabb::new(
        Vec3::new(10.0, 0.0, 0.0),
        Vec3::new(12.0, 2.0, 2.0),
    )));
    let gone = r.world.add_obstacle(Shape::Sphere {
        center: Vec3::new(-10.0, 5.0, 0.0),
        radius: 2.0,
    });
    r.world.obstacles[gone as usize].active = false;
    // Fish are 0.2 wide: within 0.1 of a surface is against it.
    r.add(0, Vec3::new(0.0, 5.0, 0.5)); // inside the sphere, 1.5 deep
    r.add(0, Vec3::new(0.0, 5.0, 2.05)); // against it
    r.add(0, Vec3::new(0.0, 5.0, 3.0)); // clear
    r.add(0, Vec3::new(11.0, 1.0, 1.95)); // inside the box, near a face
    r.add(0, Vec3::new(-10.0, 5.0, 0.0)); // inside a removed sphere: clear
    for k in 0..far {
        r.world.add_obstacle(Shape::Sphere {
            center: Vec3::new(-40.0 + k as f32, 40.0, 40.0),
            radius: 0.3,
        });
    }
    for _ in 0..10 {
        r.tick(&[]);
    }
    r.health()
}

#[test]
fn signed_distance_of_boxes_and_spheres() {
    let b = Shape::Box(Aabb::new(Vec3::ZERO, Vec3::new(4.0, 2.0, 2.0)));
    assert!(close(
        signed_distance(&b, Vec3::new(1.0, 1.0, 1.0)) as f64,
        -1.0,
        1e-6
    ));
    assert!(close(
        signed_distance(&b, Vec3::new(3.8, 1.0, 1.0)) as f64,
        -0.2,
        1e-6
    ));
    assert!(close(
        signed_distance(&b, Vec3::new(7.0, 6.0, 1.0)) as f64,
        5.0,
        1e-6
    ));
    let s = Shape::Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
    };
    assert!(close(
        signed_distance(&s, Vec3::new(0.0, 0.25, 0.0)) as f64,
        -0.75,
        1e-6
    ));
}

#[test]
fn messages_per_agent_second() {
    let mut r = Rig::new(&["fish"]);
    r.add(0, Vec3::ZERO);
    r.add(0, Vec3::X * 4.0);
    let msg = Event::Message {
        from: AgentId(1),
        kind: MessageKind::Danger,
        radius: 5.0,
    };
    for t in 1..=20u64 {
        r.tick(if t.is_multiple_of(5) {
            std::slice::from_ref(&msg)
        } else {
            &[]
        });
    }
    // 4 messages over 2 agents × 1 s.
    assert!(close(
        r.health().species[0].messages_per_agent_second,
        2.0,
        1e-12
    ));
}

#[test]
fn tick_zero_and_repeated_ticks_are_not_counted() {
    let mut r = Rig::new(&["fish"]);
    r.add(0, Vec3::ZERO);
    r.monitor.observe_events(&r.world, &[]);
    r.tick(&[]);
    r.monitor.observe_events(&r.world, &[]);
    let h = r.health();
    assert_eq!((h.ticks, h.species[0].agent_ticks), (1, 1));
}

#[test]
fn the_report_reads_back_from_json() {
    let mut r = Rig::new(&["fish"]);
    r.world.add_obstacle(Shape::Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
    });
    let a = r.add(0, Vec3::ZERO);
    for t in 1..=130u64 {
        r.agent(a).speed = 0.0;
        r.tick(&if t == 3 {
            vec![transition(0, SWIM, REST)]
        } else {
            vec![]
        });
        r.agent(a).mind.current = SWIM;
    }
    let h = r.health();
    let json = h.to_json();
    assert!(json["warnings"].as_array().is_some_and(|w| !w.is_empty()));
    let back: Health = serde_json::from_value(json).unwrap();
    assert_eq!(back, h);
}
