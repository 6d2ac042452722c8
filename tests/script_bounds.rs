//! Scripts do bounded, deterministic work: imports are compiled once each and stay inside the
//! behaviors folder, nothing a script can call reads the clock, every call is checked at load,
//! and a call that runs past its wall-time budget is a located error, never a silent change.

mod common;

use common::{folder, Sim};
use glam::Vec3;
use shoal::scenario::script_limits;
use shoal::script::{calls, AgentView, Exceeded, SandboxLimits, Script, TickClock, TimeBudget};
use shoal::species::load_species;
use shoal::world::Aabb;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A species `NAME.ron` whose script is `NAME.rhai` and whose one behavior reads `when`.
fn species(name: &str, when: &str) -> String {
    format!(
        r#"Species(
    name: "{name}",
    script: Some("{name}.rhai"),
    initial: "idle",
    behaviors: [
        Behavior(name: "idle", priority: 2, steer: Wander()),
        Behavior(name: "go", priority: 1, when: Script("{when}"), steer: Cruise(speed: 1.0)),
    ],
)
"#
    )
}

/// The `file:line:col: message` lines of loading `name.ron` from `dir`, paths relative to it.
fn errors(dir: &Path, name: &str) -> Vec<String> {
    let err = load_species(&dir.join(format!("{name}.ron")), dir, &script_limits())
        .expect_err("the files are bad");
    err.0
        .iter()
        .map(|d| {
            let file = d.file.strip_prefix(dir).unwrap_or(&d.file).display();
            format!("{file}:{}:{}: {}", d.line, d.col, d.message)
        })
        .collect()
}

#[test]
fn a_script_that_imports_itself_fails_at_once_naming_the_cycle() {
    let ron = species("me", "ok");
    let rhai = "import \"me\" as a;\nimport \"me\" as b;\nimport \"me\" as c;\nfn ok() { true }\n";
    let dir = folder(&[("me.ron", &ron), ("me.rhai", rhai)]);
    let start = Instant::now();
    let e = errors(dir.path(), "me");
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "took {:?}",
        start.elapsed()
    );
    assert_eq!(e.len(), 3, "{e:#?}");
    assert!(
        e[0].starts_with("me.rhai:1:1: import cycle: me.rhai → me.rhai"),
        "{e:#?}"
    );
}

#[test]
fn an_import_cycle_through_other_modules_names_the_whole_chain() {
    let ron = species("top", "ok");
    let dir = folder(&[
        ("top.ron", &ron),
        ("top.rhai", "import \"a\" as a;\nfn ok() { a::f() }\n"),
        ("a.rhai", "import \"b\" as b;\nfn f() { true }\n"),
        ("b.rhai", "\nimport \"a\" as a;\nfn g() { 1 }\n"),
    ]);
    let e = errors(dir.path(), "top");
    assert!(
        e.iter()
            .any(|l| l.starts_with("b.rhai:2:1: import cycle: a.rhai → b.rhai → a.rhai")),
        "{e:#?}"
    );
}

/// Levels 0..depth of two modules each (`mK`, `nK`), each importing both modules of the next
/// level: 2^depth paths from the top to the last level.
fn diamond(depth: usize) -> Vec<(String, String)> {
    let mut files = Vec::new();
    for i in 0..depth {
        let n = i + 1;
        for x in ["m", "n"] {
            files.push((
                format!("{x}{i}.rhai"),
                format!(
                    "import \"m{n}\" as p{n};\nimport \"n{n}\" as q{n};\nfn d{x}{i}() {{ p{n}::dm{n}() + 1 }}\n"
                ),
            ));
        }
    }
    for x in ["m", "n"] {
        files.push((
            format!("{x}{depth}.rhai"),
            format!("fn d{x}{depth}() {{ 0 }}\n"),
        ));
    }
    files
}

#[test]
fn a_diamond_of_imports_compiles_each_module_once_and_runs() {
    let depth = 16; // 65,536 paths: one compile per path would take hours.
    let files = diamond(depth);
    let refs: Vec<(&str, &str)> = files
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    let dir = folder(&refs);
    let start = Instant::now();
    let script = Script::load(
        &dir.path().join("m0.rhai"),
        dir.path(),
        &SandboxLimits::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "took {:?}",
        start.elapsed()
    );
    assert_eq!(script.imports.len(), 2 * depth);
    // Module functions call through the nested modules.
    let mut this = rhai::Dynamic::from(AgentView::default());
    let got: rhai::INT = script
        .call(&mut rhai::Scope::new(), &mut this, "dm0")
        .unwrap_or_else(|e| panic!("{}", e.diagnostic));
    assert_eq!(got, depth as rhai::INT);
}

#[test]
fn imports_cannot_leave_the_behaviors_folder() {
    let outside = folder(&[("secret.rhai", "fn leak() { 42 }\n")]);
    let rel = format!(
        "../{}/secret",
        outside.path().file_name().unwrap().to_string_lossy()
    );
    let ron = species("esc", "ok");
    let rhai = format!("import \"{rel}\" as s;\nfn ok() {{ s::leak() > 0 }}\n");
    let dir = folder(&[("esc.ron", &ron), ("esc.rhai", &rhai)]);
    let e = errors(dir.path(), "esc");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(e[0].starts_with("esc.rhai:1:1: imported module"), "{e:#?}");
    assert!(e[0].contains("outside the behaviors folder"), "{e:#?}");
}

#[cfg(unix)]
#[test]
fn a_symbolic_link_cannot_take_an_import_outside_the_behaviors_folder() {
    let outside = folder(&[("secret.rhai", "fn leak() { 42 }\n")]);
    let ron = species("esc", "ok");
    let rhai = "import \"common/secret\" as s;\nfn ok() { s::leak() > 0 }\n";
    let dir = folder(&[("esc.ron", &ron), ("esc.rhai", rhai)]);
    std::fs::create_dir(dir.path().join("common")).unwrap();
    std::os::unix::fs::symlink(
        outside.path().join("secret.rhai"),
        dir.path().join("common/secret.rhai"),
    )
    .unwrap();
    let e = errors(dir.path(), "esc");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(e[0].contains("outside the behaviors folder"), "{e:#?}");
}

#[test]
fn nothing_a_script_can_call_reads_the_clock() {
    let registered = calls::registered();
    // The listing works: Rhai's packages and the shoal API are in it.
    for name in ["sin", "len", "vec3", "seek"] {
        assert!(
            registered.iter().any(|(n, _)| n == name),
            "`{name}` is not listed"
        );
    }
    let deny = ["timestamp", "elapsed", "sleep", "exit"];
    for name in deny.iter().chain(calls::DENIED.iter()) {
        let found: Vec<_> = registered.iter().filter(|(n, _)| n == name).collect();
        assert!(found.is_empty(), "`{name}` is callable: {found:?}");
    }
    // And at run time, even through a function pointer.
    let engine = shoal::script::new_engine(&SandboxLimits::default());
    for src in ["timestamp()", "sleep(0)", "Fn(\"timestamp\").call()"] {
        assert!(engine.eval::<rhai::Dynamic>(src).is_err(), "{src} ran");
    }
}

#[test]
fn a_script_that_calls_timestamp_fails_to_load_with_a_located_error() {
    let ron = species("clock", "late");
    let rhai = "fn late() {\n    let t = timestamp();\n    t.elapsed > 1.0\n}\n";
    let dir = folder(&[("clock.ron", &ron), ("clock.rhai", rhai)]);
    let e = errors(dir.path(), "clock");
    assert!(!e.is_empty());
    assert!(
        e[0].starts_with("clock.rhai:2:13: `timestamp()` is not available to scripts"),
        "{e:#?}"
    );
}

#[test]
fn a_script_using_eval_fails_to_load_with_a_located_error() {
    let ron = species("evil", "ok");
    let rhai = "fn ok() {\n    eval(\"true\")\n}\n";
    let dir = folder(&[("evil.ron", &ron), ("evil.rhai", rhai)]);
    let e = errors(dir.path(), "evil");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(e[0].starts_with("evil.rhai:2:5: "), "{e:#?}");
    assert!(e[0].contains("eval"), "{e:#?}");
}

#[test]
fn a_function_name_written_with_escapes_is_still_located() {
    // RON unescapes `\u{6b}`, so the name as parsed is not in the text as written.
    let ron = species("esc", "o\\u{6b}2");
    let dir = folder(&[("esc.ron", &ron), ("esc.rhai", "fn ok() { true }\n")]);
    let e = errors(dir.path(), "esc");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(
        e[0].starts_with("esc.ron:7:") && e[0].contains("script function `ok2()` is not defined"),
        "{e:#?}"
    );
}

#[cfg(unix)]
#[test]
fn a_named_pipe_as_an_imported_module_is_refused_by_name_not_waited_on() {
    let ron = species("piped", "ok");
    let rhai = "import \"helpers\" as h;\nfn ok() { true }\n";
    let dir = folder(&[("piped.ron", &ron), ("piped.rhai", rhai)]);
    let pipe = dir.path().join("helpers.rhai");
    let made = std::process::Command::new("mkfifo")
        .arg(&pipe)
        .status()
        .unwrap();
    assert!(made.success(), "mkfifo");
    // Opening a pipe with no writer blocks: a load that opened it would never return.
    let (tx, rx) = std::sync::mpsc::channel();
    let d = dir.path().to_path_buf();
    std::thread::spawn(move || tx.send(errors(&d, "piped")).ok());
    let e = rx
        .recv_timeout(Duration::from_secs(10))
        .expect("the load waited on the pipe");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(
        e[0].starts_with("piped.rhai:1:1: imported module")
            && e[0].ends_with("helpers.rhai\" is a named pipe, not a regular file"),
        "{e:#?}"
    );
    // The script itself as a pipe, loaded directly, is refused the same way.
    let own = dir.path().join("own.rhai");
    std::process::Command::new("mkfifo")
        .arg(&own)
        .status()
        .unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let d = dir.path().to_path_buf();
    std::thread::spawn(move || {
        tx.send(Script::load(&d.join("own.rhai"), &d, &script_limits()).err())
            .ok()
    });
    let err = rx
        .recv_timeout(Duration::from_secs(10))
        .expect("the load waited on the pipe")
        .expect("a pipe is refused");
    assert!(
        err.0[0]
            .message
            .contains("cannot read script: it is a named pipe"),
        "{err:?}"
    );
}

#[test]
fn calls_to_functions_that_exist_nowhere_are_located_at_load() {
    let ron = species("typo", "ok");
    let rhai = "import \"lib\" as lib;\n\
                fn ok() {\n    helper(1) > 0\n}\n\
                fn on_tick() {\n    nowhere();\n    this.nope();\n    lib::hidden();\n    lib::twice(1);\n    ok(3);\n}\n\
                fn helper(x) { x }\n";
    let lib = "fn twice(a, b) { a + b }\nprivate fn hidden() { 0 }\n";
    let dir = folder(&[("typo.ron", &ron), ("typo.rhai", rhai), ("lib.rhai", lib)]);
    let e = errors(dir.path(), "typo");
    let at: Vec<&str> = e.iter().map(|l| l.split(": ").next().unwrap()).collect();
    assert_eq!(
        at,
        [
            "typo.rhai:6:5",
            "typo.rhai:7:10",
            "typo.rhai:8:10",
            "typo.rhai:9:10",
            "typo.rhai:10:5"
        ],
        "{e:#?}"
    );
    assert!(e[0].contains("undefined function `nowhere`"), "{e:#?}");
    assert!(e[1].contains("undefined method `nope`"), "{e:#?}");
    assert!(e[2].contains("`lib::hidden`") && e[2].contains("private"));
    assert!(e[3].contains("it takes 2 parameters"), "{e:#?}");
    assert!(
        e[4].contains("the script's `ok` takes 0 parameters"),
        "{e:#?}"
    );
}

#[test]
fn undefined_calls_in_many_functions_are_reported_in_the_order_of_the_text() {
    // Rhai keeps functions in a table whose order differs between processes; the errors (and
    // so the first one a designer sees) must not.
    let ron = species("many", "ok");
    let mut rhai = String::from("fn ok() { true }\n");
    for i in 0..24 {
        rhai.push_str(&format!("fn f{i}() {{ missing{i}() }}\n"));
    }
    rhai.push_str("fn m() { this.nope() }\n");
    let dir = folder(&[("many.ron", &ron), ("many.rhai", &rhai)]);
    let e = errors(dir.path(), "many");
    let lines: Vec<usize> = e
        .iter()
        .map(|l| l.split(':').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(lines, (2..=26).collect::<Vec<_>>(), "{e:#?}");
    assert!(e[24].contains("undefined method `nope`"), "{e:#?}");
}

#[test]
fn a_module_calling_a_function_that_exists_nowhere_is_located_in_the_module() {
    let ron = species("user", "ok");
    let dir = folder(&[
        ("user.ron", &ron),
        (
            "user.rhai",
            "import \"common/m\" as m;\nfn ok() { m::f() }\n",
        ),
        ("common/m.rhai", "fn f() {\n    missing_helper(2)\n}\n"),
    ]);
    let e = errors(dir.path(), "user");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(
        e[0].starts_with("common/m.rhai:2:5: call to undefined function `missing_helper`"),
        "{e:#?}"
    );
}

#[test]
fn a_species_file_naming_a_function_the_script_lacks_is_located() {
    let ron = species("lack", "not_there");
    let dir = folder(&[("lack.ron", &ron), ("lack.rhai", "fn there() { true }\n")]);
    let e = errors(dir.path(), "lack");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(
        e[0].starts_with("lack.ron:7:56: script function `not_there()` is not defined"),
        "{e:#?}"
    );
}

/// A script whose `spin()` runs far past any sensible time within a generous operation limit.
fn spinner() -> (tempfile::TempDir, Script) {
    let dir = folder(&[(
        "spin.rhai",
        "fn spin() {\n    let m = #{};\n    for i in 0..10000000 { m[\"k\"] = i; }\n    true\n}\nfn quick() { 1 }\n",
    )]);
    let limits = SandboxLimits {
        max_operations: 1_000_000_000,
        ..SandboxLimits::default()
    };
    let s = Script::load(&dir.path().join("spin.rhai"), dir.path(), &limits)
        .unwrap_or_else(|e| panic!("{e}"));
    (dir, s)
}

fn agent(id: i64) -> rhai::Dynamic {
    rhai::Dynamic::from(AgentView {
        id,
        ..AgentView::default()
    })
}

#[test]
fn a_call_past_its_time_budget_is_stopped_with_an_error_naming_script_function_and_agent() {
    let (_dir, script) = spinner();
    let clock = Arc::new(TickClock::new(TimeBudget {
        per_call: Some(Duration::from_millis(20)),
        per_tick: None,
    }));
    let start = Instant::now();
    let r = shoal::script::with_tick(&clock, || {
        script.call::<bool>(&mut rhai::Scope::new(), &mut agent(7), "spin")
    });
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "not stopped: {:?}",
        start.elapsed()
    );
    let e = r.expect_err("stopped");
    assert_eq!(
        e.time_budget,
        Some(Exceeded::Call(Duration::from_millis(20)))
    );
    let text = e.diagnostic.to_string();
    assert!(
        text.contains("spin.rhai:1:1: `spin()` of agent 7 ran longer than the 20 ms"),
        "{text}"
    );
    assert_eq!(clock.take_exceeded(), 1);
}

#[test]
fn the_calls_of_one_tick_share_the_tick_budget() {
    let (_dir, script) = spinner();
    let clock = Arc::new(TickClock::new(TimeBudget {
        per_call: None,
        per_tick: Some(Duration::from_millis(30)),
    }));
    shoal::script::with_tick(&clock, || {
        let e = script
            .call::<bool>(&mut rhai::Scope::new(), &mut agent(3), "spin")
            .expect_err("stopped");
        assert_eq!(
            e.time_budget,
            Some(Exceeded::Tick(Duration::from_millis(30)))
        );
        assert!(e.diagnostic.message.contains(
            "`spin()` of agent 3 was stopped: the tick's script calls took more than 30 ms"
        ));
        // The tick's time is spent: the next call of the tick is stopped at its first check,
        // a call of the next tick runs.
        clock.reset();
        let ok: rhai::INT = script
            .call(&mut rhai::Scope::new(), &mut agent(3), "quick")
            .unwrap_or_else(|e| panic!("{}", e.diagnostic));
        assert_eq!(ok, 1);
    });
}

#[test]
fn a_slow_on_tick_in_a_run_is_reported_and_counted_apart() {
    let ron = species("slow", "never");
    let rhai = "fn never() { false }\n\
                fn on_tick() {\n    let m = #{};\n    for i in 0..100000 { m[\"k\"] = i; }\n}\n";
    let dir = folder(&[("slow.ron", &ron), ("slow.rhai", rhai)]);
    let limits = SandboxLimits {
        max_operations: 100_000_000,
        ..SandboxLimits::default()
    };
    let sp = load_species(&dir.path().join("slow.ron"), dir.path(), &limits)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0)));
    sim.pipeline.set_time_budget(TimeBudget {
        per_call: Some(Duration::from_millis(1)),
        per_tick: None,
    });
    let id = sim.spawn("slow", Vec3::ZERO, 0.0);
    sim.run(2);
    assert!(sim.pipeline.stats.script_timeouts >= 1);
    assert_eq!(
        sim.pipeline.stats.script_timeouts,
        sim.pipeline.stats.script_errors
    );
    let errors = sim.script_errors();
    assert_eq!(errors.len(), 1, "{errors:#?}");
    assert!(
        errors[0].contains(&format!(
            "`on_tick()` of agent {} ran longer than the 1 ms",
            id.0
        )),
        "{errors:#?}"
    );
    assert!(errors[0].contains("slow.rhai:2:1:"), "{errors:#?}");
    // Without the guard the same run has no error: the budget never changes what a run computes
    // silently.
    sim.pipeline.set_time_budget(TimeBudget {
        per_call: None,
        per_tick: None,
    });
    let before = sim.pipeline.stats.script_errors;
    sim.run(2);
    assert_eq!(sim.pipeline.stats.script_errors, before);
}

#[test]
fn shoal_check_reports_a_self_import_at_once() {
    let ron = species("me", "ok");
    let rhai = "import \"me\" as a;\nimport \"me\" as b;\nimport \"me\" as c;\nfn ok() { true }\n";
    let dir = folder(&[("me.ron", &ron), ("me.rhai", rhai)]);
    let start = Instant::now();
    let (code, out, err) = common::shoal(&["check", dir.path().to_str().unwrap()]);
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "took {:?}",
        start.elapsed()
    );
    assert_ne!(code, 0);
    let all = format!("{out}{err}");
    assert!(
        all.contains("me.rhai:1:1: import cycle: me.rhai → me.rhai"),
        "{all}"
    );
    assert!(all.contains("3 errors"), "{all}");
}

#[test]
fn shoal_run_fails_when_a_call_runs_past_its_time_budget() {
    let species = r#"Species(
    name: "slow",
    script: Some("slow.rhai"),
    initial: "idle",
    behaviors: [Behavior(name: "idle", priority: 1, steer: Wander())],
)
"#;
    let script = "fn on_tick() {\n    let m = #{};\n    for i in 0..20000 { m[\"k\"] = i; }\n}\n";
    let scenario = r#"Scenario(
    seed: 1,
    dt: 0.05,
    duration: 0.5,
    bounds: (min: (-20.0, 0.0, -20.0), max: (20.0, 12.0, 20.0)),
    species: ["slow"],
    groups: [(species: "slow", count: 2, region: (min: (-5.0, 2.0, -5.0), max: (5.0, 8.0, 5.0)))],
)
"#;
    let dir = folder(&[
        ("behaviors/slow.ron", species),
        ("behaviors/slow.rhai", script),
        ("scenarios/slow.ron", scenario),
    ]);
    let sc = dir.path().join("scenarios/slow.ron");
    let run = |out: &str, budget: &str| {
        common::shoal(&[
            "run",
            sc.to_str().unwrap(),
            "-q",
            "--no-health",
            "--out",
            dir.path().join(out).to_str().unwrap(),
            "--script-call-ms",
            budget,
        ])
    };
    // A loop of 20,000 map writes (well within 200,000 operations) takes more than 1 ms.
    let (code, _, err) = run("tight", "1");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("ran past their time budget"), "{err}");
    let events = std::fs::read_to_string(dir.path().join("tight/events.jsonl")).unwrap();
    assert!(
        events.contains("`on_tick()` of agent 0 ran longer than the 1 ms"),
        "{events}"
    );
    let (code, _, err) = run("off", "0");
    assert_eq!(code, 0, "{err}");
}

/// A block of do-nothing statements costs Rhai's optimizer time quadratic in their number: a
/// file past the size limit is refused at once, by name, and one just under it still loads.
#[test]
fn an_oversized_script_is_refused_before_it_is_compiled() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("big.rhai");
    let body = |n: usize| format!("fn f() {{ {}1 }}\n", "();".repeat(n));
    let big = body(shoal::script::MAX_SCRIPT_BYTES / 3 + 10);
    std::fs::write(&file, &big).unwrap();
    let refused = |f: &Path| match Script::load(f, dir.path(), &SandboxLimits::default()) {
        Ok(_) => panic!("{} loaded", f.display()),
        Err(e) => e.to_string(),
    };
    let t = Instant::now();
    let err = refused(&file);
    assert!(
        t.elapsed() < Duration::from_millis(500),
        "{:?}",
        t.elapsed()
    );
    assert!(
        err.contains("big.rhai") && err.contains("script of 257 KiB: at most 256 KiB"),
        "{err}"
    );
    // A module over the limit is refused where it is read, naming it.
    let main = dir.path().join("main.rhai");
    std::fs::write(&main, "import \"big\" as b;\nfn g() { b::f() }\n").unwrap();
    let err = refused(&main);
    assert!(err.contains("module of 257 KiB"), "{err}");
    let small = body(1000);
    std::fs::write(&file, &small).unwrap();
    assert!(Script::load(&file, dir.path(), &SandboxLimits::default()).is_ok());
}
