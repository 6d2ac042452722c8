//! Hot reload end to end: real files in a temporary folder, the real watcher, a session running
//! in real time. The tests run one at a time (they measure latencies on a shared machine).

mod live_support;

use live_support::*;
use shoal::live::{Control, LiveEvent, LiveOptions, Session};
use shoal::species::{Cond, DriveKind, Value};
use shoal::world::World;
use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

fn start(p: &Project) -> Session {
    Session::start(&p.scenario(), LiveOptions::default()).unwrap_or_else(|d| panic!("{d}"))
}

fn behavior_of(s: &Session, w: &World) -> BTreeMap<u32, String> {
    let run = s.fork().unwrap();
    w.agents
        .iter()
        .map(|a| {
            let sp = &run.pipeline.species.species[a.species.0 as usize];
            (a.id.0, sp.behavior_name(a.mind.current).to_string())
        })
        .collect()
}

fn memory_n(a: &shoal::world::Agent) -> i64 {
    a.memory
        .iter()
        .find(|(k, _)| &**k == "n")
        .map_or(0, |(_, v)| match v {
            shoal::world::MemValue::Int(i) => *i,
            other => panic!("n is {other:?}"),
        })
}

/// The fish expected to graze with threshold `t`.
fn grazers(w: &World, t: f32) -> Vec<u32> {
    w.agents
        .iter()
        .filter(|a| a.drives.hunger > t)
        .map(|a| a.id.0)
        .collect()
}

fn threshold(s: &Session) -> f32 {
    let run = s.fork().unwrap();
    match &run.scenario.species.species[0].def.behaviors[0].when {
        Cond::Above(Value::Drive(DriveKind::Hunger), x) => *x,
        other => panic!("unexpected condition {other:?}"),
    }
}

#[test]
fn editing_a_threshold_changes_behavior_within_a_second_and_agents_keep_their_state() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    wait_past_tick(&s, 10);
    let before = s.world().unwrap();
    assert!(behavior_of(&s, &before).values().all(|b| b == "wander"));
    let expected = grazers(&before, 0.5);
    assert!(
        expected.len() > 3 && expected.len() < before.agents.len() - 3,
        "{expected:?}"
    );

    p.write(
        "behaviors/fish.ron",
        &p.read("behaviors/fish.ron").replace("0.95", "0.5"),
    );
    let saved = Instant::now();
    let latency = poll(Duration::from_secs(10), "fish to start grazing", || {
        let w = s.world()?;
        let b = behavior_of(&s, &w);
        let grazing: Vec<u32> = b
            .iter()
            .filter(|(_, v)| *v == "graze")
            .map(|(k, _)| *k)
            .collect();
        (grazing == expected).then(|| (saved.elapsed(), w))
    });
    let (elapsed, after) = latency;
    println!(
        "threshold edit: behavior changed {:.0} ms after the save",
        elapsed.as_secs_f64() * 1e3
    );
    assert!(elapsed < Duration::from_secs(1), "took {elapsed:?}");
    let a = accepted(&s);
    assert_eq!(a.version, 1);
    assert_eq!(a.fell_back_total(), 0);
    assert!(a.changed.iter().any(|f| name(f) == "fish.ron"));

    // Same agents, same drives, memory carried on, no teleport.
    assert_eq!(
        before.agents.iter().map(|a| a.id).collect::<Vec<_>>(),
        after.agents.iter().map(|a| a.id).collect::<Vec<_>>()
    );
    let secs = (after.tick - before.tick) as f32 * after.dt;
    for (x, y) in before.agents.iter().zip(&after.agents) {
        assert_eq!(x.drives.hunger.to_bits(), y.drives.hunger.to_bits());
        assert_eq!(x.attrs, y.attrs);
        assert!(
            x.pos.distance(y.pos) <= 2.0 * secs + 1e-3,
            "agent {} moved {} in {secs} s",
            x.id.0,
            x.pos.distance(y.pos)
        );
        assert!(
            memory_n(y) > memory_n(x) && memory_n(x) > 0,
            "memory restarted: {} then {}",
            memory_n(x),
            memory_n(y)
        );
    }
    // The switch is a decision with its cause and condition.
    let info = s.inspect(expected[0]).unwrap();
    assert_eq!(info.behavior, "graze");
    let d = info.decisions.last().unwrap();
    assert_eq!(
        (d.from.as_str(), d.to.as_str(), d.cause),
        ("wander", "graze", "interrupted")
    );
    assert_eq!(d.condition.as_deref(), Some("hunger > 0.5"));
    assert!(d.tick >= a.tick);
    s.stop();
}

#[test]
fn a_broken_ron_edit_is_rejected_while_the_run_continues_and_the_fix_applies() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    wait_past_tick(&s, 2);
    let broken = p
        .read("behaviors/fish.ron")
        .replace("Above(Drive(Hunger), 0.95)", "Abov(Drive(Hunger), 0.95)");
    p.write("behaviors/fish.ron", &broken);
    let r = rejected(&s);
    assert_eq!(r.running, 0);
    let (line, _) = line_col(&broken, "Abov(");
    let d = &r.diagnostics[0];
    println!("{d}");
    let head = d.lines().next().unwrap();
    let prefix = format!("{}:{line}:", p.path("behaviors/fish.ron").display());
    assert!(
        head.starts_with(&prefix),
        "{head} does not start with {prefix}"
    );
    assert!(head.contains("`Abov`"), "{head}");
    assert!(d.contains("when: Abov(Drive(Hunger), 0.95),"), "{d}");
    // Shown to viewers; the run goes on with version 0.
    let st = s.status();
    assert_eq!(st.diagnostics, r.diagnostics);
    wait_past_tick(&s, st.tick + 3);
    assert_eq!(s.status().version, 0);

    p.write(
        "behaviors/fish.ron",
        &broken.replace("Abov(Drive(Hunger), 0.95)", "Above(Drive(Hunger), 0.5)"),
    );
    let a = accepted(&s);
    assert_eq!(a.version, 1);
    assert!(s.status().diagnostics.is_empty());
    assert_eq!(threshold(&s), 0.5);
    s.stop();
}

#[test]
fn broken_rhai_edits_are_rejected_with_their_location_and_fixing_them_applies() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    wait_past_tick(&s, 2);

    // A syntax error in the species' script.
    let broken = FISH_RHAI.replace("util::next(n);", "util::next(n;");
    p.write("behaviors/fish.rhai", &broken);
    let r = rejected(&s);
    let (line, _) = line_col(&broken, "util::next(n;");
    let head = r.diagnostics[0].lines().next().unwrap().to_string();
    println!("{}", r.diagnostics[0]);
    let prefix = format!("{}:{line}:", p.path("behaviors/fish.rhai").display());
    assert!(
        head.starts_with(&prefix),
        "{head} does not start with {prefix}"
    );
    assert!(r.diagnostics[0].contains("this[\"n\"] = util::next(n;"));
    p.write("behaviors/fish.rhai", FISH_RHAI);
    // Put back exactly as running: nothing to swap, the diagnostics go away.
    let (e, _) = wait_for(&s, Duration::from_secs(10), "restore", |e| {
        matches!(e, LiveEvent::Restored { .. } | LiveEvent::Accepted(_))
    });
    assert!(matches!(e, LiveEvent::Restored { version: 0, .. }), "{e:?}");
    assert!(s.status().diagnostics.is_empty());

    // An imported module that compiles but fails when run: caught by the dry run on a copy of
    // the live agents, located in the module.
    let failing = "fn next(n) {\n    n + n.len()\n}\n";
    p.write("behaviors/common/util.rhai", failing);
    let r = rejected(&s);
    println!("{}", r.diagnostics[0]);
    let prefix = format!("{}:2:", p.path("behaviors/common/util.rhai").display());
    assert!(
        r.diagnostics[0].starts_with(&prefix),
        "{} does not start with {prefix}",
        r.diagnostics[0]
    );
    assert!(s.status().version == 0 && !s.status().diagnostics.is_empty());
    let before = s.world().unwrap();
    // The live agents never ran it: their counters keep counting by one.
    let fixed = "fn next(n) {\n    n + 10\n}\n";
    p.write("behaviors/common/util.rhai", fixed);
    let a = accepted(&s);
    assert_eq!(a.version, 1);
    assert!(a.changed.iter().any(|f| name(f) == "util.rhai"));
    assert!(s.status().diagnostics.is_empty());
    wait_past_tick(&s, a.tick + 4);
    let after = s.world().unwrap();
    for (x, y) in before.agents.iter().zip(&after.agents) {
        assert!(
            memory_n(y) >= memory_n(x) + 10,
            "the new module does not run"
        );
    }
    s.stop();
}

#[test]
fn renaming_a_behavior_falls_back_to_the_initial_one_and_says_how_many() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    p.write("behaviors/fish.ron", &FISH.replace("0.95", "0.5"));
    accepted(&s);
    let w = s.world().unwrap();
    let expected = grazers(&w, 0.5);
    poll(Duration::from_secs(10), "fish to graze", || {
        let w = s.world()?;
        let b = behavior_of(&s, &w);
        (b.values().filter(|v| *v == "graze").count() == expected.len()).then_some(())
    });
    s.control(Control::Pause);
    poll(Duration::from_secs(5), "pause", || {
        s.status().paused.then_some(())
    });
    p.write(
        "behaviors/fish.ron",
        &FISH
            .replace("0.95", "0.5")
            .replace("name: \"graze\"", "name: \"feed\""),
    );
    let a = accepted(&s);
    assert_eq!(a.fell_back, vec![("fish".to_string(), expected.len())]);
    assert!(
        a.summary()
            .contains(&format!("{} fish agents fell back", expected.len())),
        "{}",
        a.summary()
    );
    // Paused: the swap happened at a tick boundary, nothing ran since.
    let w = s.world().unwrap();
    assert!(behavior_of(&s, &w).values().all(|b| b == "wander"));
    let info = s.inspect(expected[0]).unwrap();
    let d = info.decisions.last().unwrap();
    assert_eq!(
        (d.from.as_str(), d.to.as_str(), d.cause),
        ("graze", "wander", "fallback")
    );
    assert!(d.condition.as_deref().unwrap().contains("\"graze\""));
    // One tick later the renamed behavior takes them again.
    s.control(Control::Step);
    poll(Duration::from_secs(5), "a step", || {
        let w = s.world()?;
        let b = behavior_of(&s, &w);
        (b.values().filter(|v| *v == "feed").count() == expected.len()).then_some(())
    });
    s.stop();
}

#[test]
fn an_atomic_save_is_picked_up_every_time() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    for (k, t) in ["0.5", "0.6", "0.7"].iter().enumerate() {
        p.save_atomic("behaviors/fish.ron", &FISH.replace("0.95", t));
        let saved = Instant::now();
        let a = accepted(&s);
        println!(
            "atomic save {}: accepted {:.0} ms after the save",
            k + 1,
            a.at.duration_since(saved).as_secs_f64() * 1e3
        );
        assert_eq!(a.version, k as u32 + 1);
        assert_eq!(threshold(&s), t.parse::<f32>().unwrap());
        // No reload for the temporary file itself.
        std::thread::sleep(Duration::from_millis(450));
    }
    let extra: Vec<LiveEvent> = s.events().try_iter().collect();
    assert!(
        extra
            .iter()
            .all(|e| matches!(e, LiveEvent::FirstTick { .. })),
        "{extra:#?}"
    );
    s.stop();
}

#[test]
fn deleting_and_recreating_files_works() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    // The script disappears: rejected, located at the species file's reference to it.
    std::fs::remove_file(p.path("behaviors/fish.rhai")).unwrap();
    let r = rejected(&s);
    println!("{}", r.diagnostics[0]);
    let (line, col) = line_col(FISH, "\"fish.rhai\"");
    let prefix = format!("{}:{line}:{col}:", p.path("behaviors/fish.ron").display());
    assert!(
        r.diagnostics[0].starts_with(&prefix),
        "{}",
        r.diagnostics[0]
    );
    assert!(r.diagnostics[0].contains("not found"));
    // Re-created as it was: back to normal without a swap.
    p.write("behaviors/fish.rhai", FISH_RHAI);
    let (e, _) = wait_for(&s, Duration::from_secs(10), "restore", |e| {
        matches!(e, LiveEvent::Restored { .. } | LiveEvent::Accepted(_))
    });
    assert!(matches!(e, LiveEvent::Restored { .. }), "{e:?}");
    assert!(s.status().diagnostics.is_empty());

    // The species file is deleted, then re-created with a change.
    std::fs::remove_file(p.path("behaviors/fish.ron")).unwrap();
    let r = rejected(&s);
    assert!(
        r.diagnostics[0].starts_with(&p.scenario().display().to_string()),
        "{}",
        r.diagnostics[0]
    );
    std::thread::sleep(Duration::from_millis(100));
    p.write("behaviors/fish.ron", &FISH.replace("0.95", "0.4"));
    let a = accepted(&s);
    assert_eq!(a.version, 1);
    assert_eq!(threshold(&s), 0.4);
    assert!(s.status().diagnostics.is_empty());
    s.stop();
}

#[test]
fn twenty_saves_in_one_second_cause_a_few_reloads_and_the_last_one_wins() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    wait_past_tick(&s, 2);
    let t0 = Instant::now();
    for k in 0..20 {
        let t = format!("0.{}", 50 + k);
        p.write("behaviors/fish.ron", &FISH.replace("0.95", &t));
        let next = t0 + Duration::from_millis(50 * (k + 1));
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
    }
    println!("20 saves took {:.0} ms", t0.elapsed().as_secs_f64() * 1e3);
    // Let everything settle.
    let tick = s.status().tick;
    std::thread::sleep(Duration::from_millis(1500));
    wait_past_tick(&s, tick + 5);
    let events: Vec<LiveEvent> = s.events().try_iter().collect();
    let reloads: Vec<&LiveEvent> = events
        .iter()
        .filter(|e| matches!(e, LiveEvent::Accepted(_) | LiveEvent::Rejected(_)))
        .collect();
    println!("reloads: {}", reloads.len());
    assert!(
        (1..=5).contains(&reloads.len()),
        "{} reloads: {reloads:#?}",
        reloads.len()
    );
    assert!(matches!(reloads.last(), Some(LiveEvent::Accepted(_))));
    assert_eq!(threshold(&s), 0.69);
    s.stop();
}

#[test]
fn a_species_the_scenario_starts_to_reference_spawns_live() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    wait_past_tick(&s, 2);
    let before = s.world().unwrap();
    // Referenced before it exists: rejected, naming the scenario line.
    let scen = SCENARIO.replace("species: [\"fish\"]", "species: [\"fish\", \"crab\"]").replace(
        "    ],\n)",
        "        (species: \"crab\", count: 5, region: (min: (-5.0, 0.0, -5.0), max: (5.0, 1.0, 5.0))),\n    ],\n)",
    );
    p.write("scenarios/live.ron", &scen);
    let r = rejected(&s);
    println!("{}", r.diagnostics[0]);
    let (line, col) = line_col(&scen, "\"crab\"");
    let prefix = format!("{}:{line}:{col}:", p.scenario().display());
    assert!(
        r.diagnostics[0].starts_with(&prefix),
        "{}",
        r.diagnostics[0]
    );
    // The new file appears: picked up although nothing running used it.
    p.write("behaviors/crab.ron", CRAB);
    let a = accepted(&s);
    assert_eq!(a.spawned, vec![("crab".to_string(), 5)]);
    let w = s.world().unwrap();
    let crabs = w.agents.iter().filter(|a| a.species.0 == 1).count();
    assert_eq!(crabs, 5);
    for x in &before.agents {
        let y = w.agent(x.id).expect("fish kept");
        assert_eq!(y.species.0, 0);
        assert_eq!(x.drives.hunger.to_bits(), y.drives.hunger.to_bits());
    }
    // And the new species file is watched from now on.
    p.write(
        "behaviors/crab.ron",
        &CRAB.replace("cruise: 0.3", "cruise: 0.6"),
    );
    let a = accepted(&s);
    assert_eq!(a.version, 2);
    assert!(a.changed.iter().any(|f| name(f) == "crab.ron"));
    s.stop();
}

#[test]
fn pause_step_and_speed_control_the_clock() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    wait_past_tick(&s, 2);
    s.control(Control::Pause);
    poll(Duration::from_secs(5), "pause", || {
        s.status().paused.then_some(())
    });
    let t = s.status().tick;
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(s.status().tick, t);
    s.control(Control::Step);
    poll(Duration::from_secs(5), "one step", || {
        (s.status().tick == t + 1).then_some(())
    });
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(s.status().tick, t + 1);
    assert!(s.status().paused);
    s.control(Control::Speed(4.0));
    s.control(Control::Resume);
    let t0 = Instant::now();
    wait_past_tick(&s, t + 40);
    // 40 ticks of 0.05 s at 4× take 0.5 s of wall clock: more than a tenth of that at least.
    assert!(t0.elapsed() > Duration::from_millis(50));
    assert_eq!(s.status().speed, 4.0);
    s.stop();
}

#[test]
fn the_record_reruns_the_session_exactly() {
    let _g = serial();
    let p = Project::new();
    let rec = p.path("record");
    let s = Session::start(
        &p.scenario(),
        LiveOptions {
            record: Some(rec.clone()),
            speed: 2.0,
            ..LiveOptions::default()
        },
    )
    .unwrap_or_else(|d| panic!("{d}"));
    wait_past_tick(&s, 5);
    p.write("behaviors/fish.ron", &FISH.replace("0.95", "0.5"));
    let a1 = accepted(&s);
    wait_past_tick(&s, a1.tick + 5);
    p.write(
        "behaviors/fish.rhai",
        &FISH_RHAI.replace("util::next(n);", "util::next(n;"),
    );
    rejected(&s);
    p.write(
        "behaviors/fish.ron",
        &FISH
            .replace("0.95", "0.3")
            .replace("name: \"graze\"", "name: \"feed\""),
    );
    std::thread::sleep(Duration::from_millis(100));
    p.write("behaviors/fish.rhai", FISH_RHAI);
    let a2 = accepted(&s);
    wait_past_tick(&s, a2.tick + 5);
    s.control(Control::Pause);
    poll(Duration::from_secs(5), "pause", || {
        s.status().paused.then_some(())
    });
    let live = s.world().unwrap();
    s.stop();

    let log = std::fs::read_to_string(rec.join("reloads.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = log
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let statuses: Vec<&str> = lines
        .iter()
        .map(|l| l["status"].as_str().unwrap())
        .collect();
    assert_eq!(statuses.first(), Some(&"initial"));
    assert!(statuses.contains(&"rejected"));
    assert_eq!(
        statuses.iter().filter(|s| **s == "accepted").count(),
        a2.version as usize
    );
    assert!(lines
        .iter()
        .all(|l| l["time_ms"].as_u64().unwrap() > 1_600_000_000_000));
    let ticks: Vec<u64> = lines
        .iter()
        .filter(|l| l["status"] == "accepted")
        .map(|l| l["tick"].as_u64().unwrap())
        .collect();
    assert_eq!(ticks.first(), Some(&a1.tick));
    assert_eq!(ticks.last(), Some(&a2.tick));

    let rerun = shoal::live::record::rerun(&rec, live.tick).unwrap_or_else(|d| panic!("{d}"));
    assert_eq!(rerun.world.tick, live.tick);
    assert_eq!(rerun.world.agents, live.agents, "the re-run diverged");
    println!(
        "re-ran {} ticks with {} versions: identical",
        live.tick,
        a2.version + 1
    );
}

#[test]
fn a_group_count_change_is_refused_with_its_location_and_the_run_keeps_its_agents() {
    let _g = serial();
    let p = Project::new();
    let s = start(&p);
    wait_past_tick(&s, 2);
    let scen = SCENARIO.replace("count: 24", "count: 30");
    p.write("scenarios/live.ron", &scen);
    let r = rejected(&s);
    let d = &r.diagnostics[0];
    println!("{d}");
    let (line, col) = line_col(&scen, "30,");
    let head = format!(
        "{}:{line}:{col}: group `fish` count 24 → 30: restart to apply",
        p.scenario().display()
    );
    assert!(d.starts_with(&head), "{d} does not start with {head}");
    // Shown to viewers (the page's error area reads the status); the run goes on with its 24.
    let st = s.status();
    assert_eq!(st.diagnostics, r.diagnostics);
    wait_past_tick(&s, st.tick + 3);
    assert_eq!(s.status().version, 0);
    assert_eq!(s.world().unwrap().agents.len(), 24);
    // Putting the count back is an ordinary edit.
    p.write(
        "scenarios/live.ron",
        &SCENARIO.replace("(hunger:", "(hunger: "),
    );
    let a = accepted(&s);
    assert_eq!(a.version, 1);
    assert!(s.status().diagnostics.is_empty());
    s.stop();
}
