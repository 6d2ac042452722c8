//! Squads at run time on a small synthetic terrain: scenario errors are located, a member held
//! away from its slot is found blocked and the squad re-plans, a script's `plan_path` changes the
//! squad's plan and the tables are readable, and walking agents follow the ground.

use glam::Vec2;
use shoal::events::Event;
use shoal::scenario::{Overrides, Run, Scenario};
use shoal::world::MemValue;
use std::path::{Path, PathBuf};

/// 60 × 40 cells of 2 m, flat at height 1 with a ramp rising 0.2 per metre east of x = 80 and a
/// wall (cells 30–31) from the north edge down to row 27, leaving a passage in the south.
fn terrain_text() -> String {
    let (cols, rows) = (60usize, 40usize);
    let mut s = format!(
        "ncols {cols}\nnrows {rows}\nxllcorner 0\nyllcorner -{}\ncellsize 2\nNODATA_value -9999\n",
        rows * 2
    );
    for r in 0..rows {
        let line: Vec<String> = (0..cols)
            .map(|c| {
                let x = c as f32 * 2.0 + 1.0;
                let h = if (30..32).contains(&c) && r < 28 {
                    40.0
                } else if x > 80.0 {
                    1.0 + 0.2 * (x - 80.0)
                } else {
                    1.0
                };
                format!("{h:.2}")
            })
            .collect();
        s.push_str(&line.join(" "));
        s.push('\n');
    }
    s
}

struct Fixture {
    _dir: tempfile::TempDir,
    path: PathBuf,
}

fn behaviors() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors")
}

/// A scenario in a temporary folder with the synthetic terrain; `squad` is the squad entry and
/// `species` the species the scenario loads from `behaviors` (the repository's by default).
fn fixture(species: &str, behaviors_dir: &Path, squad: &str) -> Fixture {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.asc"), terrain_text()).unwrap();
    let text = format!(
        r#"Scenario(
    duration: 200.0,
    bounds: (min: (0.0, -5.0, 0.0), max: (120.0, 60.0, 80.0)),
    behaviors: Some("{}"),
    species: ["{species}"],
    terrain: Some(dem: "t.asc"),
    squads: [
        {squad}
    ],
)
"#,
        behaviors_dir.display()
    );
    let path = dir.path().join("s.ron");
    std::fs::write(&path, text).unwrap();
    Fixture { _dir: dir, path }
}

const SQUAD: &str = r#"(species: "squad_member", count: 3, start: (11.0, 11.0), goal: (101.0, 11.0), formations: ["line", "column"], task: "MayChangeRarely", spacing: 3.0),"#;

fn run_of(f: &Fixture) -> Run {
    let sc = Scenario::load(&f.path).unwrap_or_else(|e| panic!("{e}"));
    Run::new(sc, Overrides::default())
}

#[test]
fn the_plan_goes_around_the_wall_and_members_walk_on_the_ramp() {
    let f = fixture("squad_member", &behaviors(), SQUAD);
    let mut run = run_of(&f);
    let sq = &run.squads.squads[0];
    // Around the wall: the path reaches the passage south of row 27 (z ≥ 56).
    assert!(sq.plan.leader_path.iter().any(|p| p.y > 56.0));
    assert!(sq
        .plan
        .leader_path
        .iter()
        .all(|p| !(60.0..64.0).contains(&p.x) || p.y > 56.0));
    let members = sq.members.clone();
    let t = run.world.terrain.clone().unwrap();
    while !run.finished() {
        run.step();
        for id in &members {
            let a = run.world.agent(*id).unwrap();
            assert!((a.pos.y - t.height_at(a.pos.x, a.pos.z)).abs() < 1e-4);
            // On the ramp, facing east, the body pitches up the slope (atan 0.2), down facing west.
            if a.pos.x > 84.0 && a.speed > 0.5 {
                let east = -shoal::math::sin(a.yaw);
                let expected = shoal::math::atan(0.2 * east);
                assert!(
                    (a.pitch - expected).abs() < 0.02,
                    "pitch {} vs {expected}",
                    a.pitch
                );
            }
        }
    }
    let sq = &run.squads.squads[0];
    eprintln!(
        "around the wall: {} ticks, mean formation error {:.3} m, max {:.2} m",
        run.world.tick,
        sq.stats.mean_error(),
        sq.stats.error_max
    );
    assert!(sq.progress.finished, "arrived");
    assert_eq!(sq.stats.blocked_steps, 0);
    for (m, id) in members.iter().enumerate() {
        let a = run.world.agent(*id).unwrap();
        let d = Vec2::new(a.pos.x, a.pos.z).distance(sq.final_slot(m));
        assert!(d < 1.0, "member {m} {d} m from its goal slot");
    }
}

#[test]
fn a_member_held_back_is_found_blocked_and_the_squad_replans() {
    let f = fixture("squad_member", &behaviors(), SQUAD);
    let mut run = run_of(&f);
    let held = run.squads.squads[0].members[2];
    let i = run.world.agent_index(held).unwrap();
    let spot = run.world.agents[i].pos;
    let dt = run.world.dt;
    let mut first_stuck = None;
    let mut first_replan = None;
    for _ in 0..(20.0 / dt) as usize {
        run.step();
        // Something holds member 2 where it started.
        let a = &mut run.world.agents[i];
        a.pos = spot;
        a.prev_pos = spot;
        let s = &run.squads.squads[0].stats;
        if s.stuck > 0 && first_stuck.is_none() {
            first_stuck = Some(run.world.time() as f32);
        }
        if s.replans > 0 && first_replan.is_none() {
            first_replan = Some(run.world.time() as f32);
        }
    }
    let s = &run.squads.squads[0].stats;
    eprintln!("stuck at {first_stuck:?} s, re-planned at {first_replan:?} s, {s:?}");
    // It falls 2 m behind its slot after a couple of seconds, then 3 s without getting closer:
    // blocked; a 5 s detour does not help either: second strike, re-plan.
    let stuck = first_stuck.expect("found blocked");
    assert!((3.0..8.0).contains(&stuck), "{stuck}");
    let replan = first_replan.expect("re-planned");
    assert!(replan >= stuck + 2.9 && replan < stuck + 8.0, "{replan}");
    assert!(s.detour_ticks > 0);
    // The leader waited for it: it did not get far.
    let leader = run.world.agent(run.squads.squads[0].members[0]).unwrap();
    assert!(leader.pos.x < 40.0, "{}", leader.pos);
}

const SCOUT_SCRIPT: &str = r#"
fn is_leader() { this.is_leader }
fn arrived() { this.at_goal && this.slot_dist < 3.0 }
fn far_from_slot() { false }
fn near_slot() { true }
fn on_tick() {
    let asked_before = this.has("asked");
    if this.is_leader && !asked_before {
        this["asked"] = true;
        this["keys"] = this.key_points.len();
        this["first_key"] = this.key_points[0];
        this["formation"] = this.formation;
        this["goal"] = this.squad_goal;
        this["in_squad"] = this.in_squad && !this.at_goal;
        this["slot_dist"] = this.slot_dist;
        this["bad"] = this.plan_path(vec3(-50.0, 0.0, 0.0), "", "");
        this["err"] = this.plan_error;
        this["ok"] = this.plan_path(vec3(11.0, 0.0, 71.0), "column", "ShortestFirst");
        this["sees_wall_side"] = this.can_see(vec3(91.0, 1.0, 11.0));
        this["sees_near"] = this.can_see(vec3(31.0, 1.0, 11.0));
        this["ground"] = this.ground_height(101.0, 11.0);
    }
    // On a later call: the plan asked for is adopted after the tick that asked.
    if this.is_leader && asked_before && !this.has("transitions_read") {
        this["transitions_read"] = true;
        let t = this.transitions;
        this["n_transitions"] = t.len();
        if t.len() > 0 { this["t0_to"] = t[0].to; }
    }
}
fn on_event(kind) {}
"#;

/// A copy of the repository's squad member named `scout`, with [`SCOUT_SCRIPT`].
fn scout_dir() -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    let ron = std::fs::read_to_string(behaviors().join("squad_member.ron"))
        .unwrap()
        .replace("\"squad_member\"", "\"scout\"")
        .replace("squad_member.rhai", "scout.rhai")
        .replace(
            "memory: {",
            r#"memory: {
        "asked": Bool(None), "keys": Int(None), "first_key": Vec3(None), "goal": Vec3(None),
        "in_squad": Bool(None), "slot_dist": Float(None), "bad": Bool(None), "err": String(None),
        "ok": Bool(None), "sees_wall_side": Bool(None), "sees_near": Bool(None),
        "ground": Float(None), "transitions_read": Bool(None), "n_transitions": Int(None),
        "t0_to": String(None),"#,
        );
    std::fs::write(d.path().join("scout.ron"), ron).unwrap();
    std::fs::write(d.path().join("scout.rhai"), SCOUT_SCRIPT).unwrap();
    d
}

#[test]
fn a_script_plans_a_new_path_and_reads_the_tables() {
    let b = scout_dir();
    let squad = SQUAD.replace("squad_member", "scout");
    let f = fixture("scout", b.path(), &squad);
    let mut run = run_of(&f);
    let before = run.squads.squads[0].plan.clone();
    let leader = run.squads.squads[0].members[0];
    for _ in 0..10 {
        run.step();
        for e in &run.pipeline.events {
            if let Event::ScriptError { message, .. } = e {
                panic!("{message}");
            }
        }
    }
    let mem = |k: &str| {
        run.world
            .agent(leader)
            .unwrap()
            .memory
            .iter()
            .find(|(key, _)| &**key == k)
            .map(|(_, v)| v.clone())
    };
    assert_eq!(
        mem("keys"),
        Some(MemValue::Int(before.key_points.len() as i64))
    );
    let k0 = before.key_points[0].pos;
    assert_eq!(
        mem("first_key"),
        Some(MemValue::Vec3(glam::Vec3::new(k0.x, 1.0, k0.y)))
    );
    assert_eq!(mem("formation"), Some(MemValue::Str("line".into())));
    assert_eq!(
        mem("goal"),
        Some(MemValue::Vec3(glam::Vec3::new(101.0, 5.2, 11.0)))
    );
    assert_eq!(mem("in_squad"), Some(MemValue::Bool(true)));
    let Some(MemValue::Float(d)) = mem("slot_dist") else {
        panic!()
    };
    assert!(d < 0.1, "the leader is on its path: {d}");
    assert_eq!(mem("bad"), Some(MemValue::Bool(false)));
    assert_eq!(
        mem("err"),
        Some(MemValue::Str(
            "the goal (-50, 0) lies outside the terrain".into()
        ))
    );
    assert_eq!(mem("ok"), Some(MemValue::Bool(true)));
    // The wall (40 m high at x = 60–64) hides the far side; open ground does not.
    assert_eq!(mem("sees_wall_side"), Some(MemValue::Bool(false)));
    assert_eq!(mem("sees_near"), Some(MemValue::Bool(true)));
    let Some(MemValue::Float(g)) = mem("ground") else {
        panic!("{:?}", mem("ground"))
    };
    assert!((g - 5.2).abs() < 1e-4, "{g}");
    let sq = &run.squads.squads[0];
    assert_eq!(sq.stats.script_plans, 1);
    assert_eq!(sq.goal, Vec2::new(11.0, 71.0));
    assert_eq!(sq.formations[sq.order[0]].name(), "column");
    assert_eq!(sq.task, shoal::formation::TaskClass::ShortestFirst);
    assert_ne!(sq.plan, before);
    assert_eq!(
        *sq.plan.key_points.last().map(|k| &k.pos).unwrap(),
        Vec2::new(11.0, 71.0)
    );
    // The tables were read again after the new plan: a straight walk south, no transition.
    assert_eq!(
        mem("n_transitions"),
        Some(MemValue::Int(sq.plan.transitions.len() as i64))
    );
    // The squad now heads south to the new goal.
    for _ in 0..400 {
        run.step();
    }
    let l = run.world.agent(leader).unwrap();
    assert!(l.pos.z > 25.0 && l.pos.x < 20.0, "{}", l.pos);
}

#[test]
fn an_unknown_formation_in_plan_path_is_a_located_script_error() {
    let b = scout_dir();
    let script = SCOUT_SCRIPT.replace("\"column\", \"ShortestFirst\"", "\"phalanx\", \"\"");
    std::fs::write(b.path().join("scout.rhai"), script).unwrap();
    let f = fixture("scout", b.path(), &SQUAD.replace("squad_member", "scout"));
    let mut run = run_of(&f);
    let mut messages = Vec::new();
    for _ in 0..10 {
        run.step();
        for e in &run.pipeline.events {
            if let Event::ScriptError { message, .. } = e {
                messages.push(message.clone());
            }
        }
    }
    assert_eq!(messages.len(), 1, "{messages:?}");
    assert!(
        messages[0].contains("scout.rhai:")
            && messages[0].contains("the squad has no formation \"phalanx\": it has line, column"),
        "{}",
        messages[0]
    );
    assert_eq!(run.squads.squads[0].stats.script_plans, 0);
}

fn load_error(squad: &str, terrain: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.asc"), terrain_text()).unwrap();
    let text = format!(
        "Scenario(\n    duration: 1.0,\n    bounds: (min: (0.0, -5.0, 0.0), max: (120.0, 60.0, 80.0)),\n    behaviors: Some(\"{}\"),\n    species: [\"squad_member\"],\n{terrain}    squads: [\n        {squad}\n    ],\n)\n",
        behaviors().display()
    );
    let path = dir.path().join("s.ron");
    std::fs::write(&path, &text).unwrap();
    let e = Scenario::load(&path).expect_err("must fail");
    e.0.iter()
        .map(|d| {
            format!(
                "{}:{}: {}",
                d.line,
                d.col,
                d.message.replace(&dir.path().display().to_string(), "DIR")
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn scenario_errors_about_terrain_and_squads_are_located() {
    let t = "    terrain: Some(dem: \"t.asc\"),\n";
    assert_eq!(
        load_error(SQUAD, ""),
        "6:5: squads need a `terrain: (dem: \"…\")` to plan over"
    );
    assert_eq!(
        load_error(SQUAD, "    terrain: Some(dem: \"missing.asc\"),\n"),
        "6:24: terrain file \"DIR/missing.asc\" not found"
    );
    assert_eq!(
        load_error(&SQUAD.replace("\"line\"", "\"blob\""), t),
        "8:100: unknown formation \"blob\": expected one of line, column, wedge, triangle, diamond"
    );
    assert_eq!(
        load_error(&SQUAD.replace("MayChangeRarely", "Sometimes"), t),
        "8:119: unknown task class \"Sometimes\": expected MustKeep, MayChangeRarely, ShortestFirst or Custom(k1: …, k2: …, may_change: …)"
    );
    assert_eq!(
        load_error(&SQUAD.replace("(11.0, 11.0)", "(61.0, 11.0)"), t),
        "8:45: squad of \"squad_member\": the start (61, 11) is on a blocked cell"
    );
    assert_eq!(
        load_error(&SQUAD.replace("(101.0, 11.0)", "(101.0, 500.0)"), t),
        "8:66: squad of \"squad_member\": the goal (101, 500) lies outside the terrain"
    );
    assert_eq!(
        load_error(&SQUAD.replace("count: 3", "count: 0"), t),
        "8:35: `count` must be at least 1"
    );
}
