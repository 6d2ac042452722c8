//! Hot-reload benchmark: latency from a file save to the first tick run with the new version,
//! and what a reload costs the running simulation (tick durations while a new version is
//! prepared and the tick a swap happens in, against normal ticks).
//!
//! A species with a 500-line Rhai script and a script condition, a few hundred agents, the
//! default debounce; the species file and the script are edited in turn, once every 0.70–0.75 s
//! (spread over the tick period). The edits change thresholds on whole-number counts
//! (`> 8.003`), so every version behaves the same and the tick durations measure the reload
//! itself, not a change of behavior.
//!
//! ```text
//! cargo run --release --example reload_latency [-- --agents 400 --reloads 20 --speed 1 --around]
//! ```
//!
//! `--around` also prints the step durations of the ticks around each swap (`*` = the swap's).

use shoal::live::{LiveEvent, LiveOptions, Session};
use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

/// A script of about 500 lines: helper functions the condition calls.
fn script(variant: u32) -> String {
    let mut s = String::from("// Benchmark fish script (generated).\n\n");
    let mut k = 0;
    while s.lines().count() < 490 {
        writeln!(
            s,
            "fn helper_{k}(x) {{\n    let a = x * 1.5;\n    let b = a + {k}.0;\n    if b > 100.0 {{\n        b - 100.0\n    }} else {{\n        b\n    }}\n}}\n"
        )
        .unwrap();
        k += 1;
    }
    writeln!(
        s,
        "// Crowded and not hungry (threshold edited by the benchmark; counts are whole numbers,\n// so every version behaves the same and only the reload itself is measured).\nfn crowded() {{\n    this.kin.count > 8.{variant:03} && helper_3(this.hunger) < 4.0\n}}"
    )
    .unwrap();
    s
}

fn species(variant: u32) -> String {
    format!(
        r##"Species(
    name: "bench_fish",
    color: "#40a0e0",
    body: (limits: (max_speed: 3.0)),
    senses: (vision_radius: 6.0, smell_radius: 0.0),
    drives: (native: false, hunger: Uniform(0.0, 1.0)),
    script: Some("bench_fish.rhai"),
    decision_interval: 4,
    initial: "wander",
    behaviors: [
        Behavior(name: "leave", priority: 2, when: Script("crowded"), done: TimeIn(2.0),
            steer: Priority([Contain(), Flee(target: Centroid(Kin))])),
        Behavior(name: "school", priority: 3, when: Above(Count(Kin), 2.{variant:03}), done: Below(Count(Kin), 2),
            steer: Priority([Contain(), Blend([(w: 1.0, steer: Separation()), (w: 1.0, steer: Alignment()), (w: 0.4, steer: Cohesion())])])),
        Behavior(name: "wander", priority: 4, steer: Priority([Contain(), Wander()])),
    ],
)
"##
    )
}

fn scenario(agents: usize) -> String {
    format!(
        r#"Scenario(
    seed: 11,
    dt: 0.05,
    duration: 60.0,
    bounds: (min: (-40.0, 0.0, -40.0), max: (40.0, 20.0, 40.0)),
    species: ["bench_fish"],
    groups: [(species: "bench_fish", count: {agents}, region: (min: (-30.0, 2.0, -30.0), max: (30.0, 18.0, 30.0)))],
)
"#
    )
}

fn arg(name: &str, default: f64) -> f64 {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let agents = arg("--agents", 400.0) as usize;
    let reloads = arg("--reloads", 20.0) as u32;
    let speed = arg("--speed", 1.0) as f32;
    let dir = tempfile::tempdir().expect("temp dir");
    let root = dir.path();
    std::fs::create_dir_all(root.join("behaviors")).unwrap();
    std::fs::create_dir_all(root.join("scenarios")).unwrap();
    let write = |rel: &str, text: &str| std::fs::write(root.join(rel), text).unwrap();
    write("behaviors/bench_fish.ron", &species(0));
    write("behaviors/bench_fish.rhai", &script(0));
    write("scenarios/bench.ron", &scenario(agents));
    let lines = script(0).lines().count();
    let options = LiveOptions {
        tick_times: true,
        speed,
        ..LiveOptions::default()
    };
    let debounce = options.debounce;
    let s = Session::start(Path::new(&root.join("scenarios/bench.ron")), options)
        .unwrap_or_else(|d| panic!("{d}"));
    std::thread::sleep(Duration::from_secs(2));

    struct Sample {
        saved: Instant,
        detected: Instant,
        accepted: Instant,
        first_tick: Instant,
        swap: Duration,
        load: Duration,
        dry_run: Duration,
        file: &'static str,
    }
    let mut samples = Vec::new();
    for k in 1..=reloads {
        let file = if k % 2 == 0 {
            write("behaviors/bench_fish.ron", &species(k));
            "species file"
        } else {
            write("behaviors/bench_fish.rhai", &script(k));
            "script"
        };
        let saved = Instant::now();
        let mut acc = None;
        let deadline = saved + Duration::from_secs(10);
        let first_tick = loop {
            match s
                .events()
                .recv_timeout(deadline.saturating_duration_since(Instant::now()))
            {
                Ok(LiveEvent::Accepted(a)) => acc = Some(a),
                Ok(LiveEvent::FirstTick { version, at, .. }) if version == k => break at,
                Ok(LiveEvent::Rejected(r)) => panic!("edit {k} rejected: {:?}", r.diagnostics),
                Ok(_) => {}
                Err(_) => panic!("edit {k} not applied within 10 s"),
            }
        };
        let a = acc.expect("accepted before its first tick");
        samples.push(Sample {
            saved,
            detected: a.detected_at,
            accepted: a.at,
            first_tick,
            swap: a.swap_duration,
            load: a.load_duration,
            dry_run: a.dry_run_duration,
            file,
        });
        // Spread the saves over the tick period (a designer saves at any moment).
        std::thread::sleep(Duration::from_millis(700 + (k as u64 * 37) % 50));
    }
    let ticks = s.tick_times();
    s.stop();
    if std::env::args().any(|a| a == "--around") {
        for (i, t) in ticks.iter().enumerate() {
            if !t.swap.is_zero() {
                let around: Vec<String> = ticks[i.saturating_sub(3)..(i + 3).min(ticks.len())]
                    .iter()
                    .map(|t| {
                        format!(
                            "{:.2}{}",
                            ms(t.step),
                            if t.swap.is_zero() { "" } else { "*" }
                        )
                    })
                    .collect();
                eprintln!("around swap at tick {}: {}", t.tick, around.join(" "));
            }
        }
    }

    let mut total: Vec<f64> = samples.iter().map(|x| ms(x.first_tick - x.saved)).collect();
    let mut watcher: Vec<f64> = samples.iter().map(|x| ms(x.detected - x.saved)).collect();
    let mut prepare: Vec<f64> = samples
        .iter()
        .map(|x| ms(x.accepted.saturating_duration_since(x.detected)))
        .collect();
    let mut to_tick: Vec<f64> = samples
        .iter()
        .map(|x| ms(x.first_tick - x.accepted))
        .collect();
    let mut swaps: Vec<f64> = samples.iter().map(|x| ms(x.swap)).collect();
    let mut loads: Vec<f64> = samples.iter().map(|x| ms(x.load)).collect();
    let mut dry_runs: Vec<f64> = samples.iter().map(|x| ms(x.dry_run)).collect();
    let by = |f: &str| -> Vec<f64> {
        samples
            .iter()
            .filter(|x| x.file == f)
            .map(|x| ms(x.first_tick - x.saved))
            .collect()
    };
    let (mut script_edits, mut species_edits) = (by("script"), by("species file"));

    // Ticks: normal ones, those that ran while a new version was being prepared (between the
    // watcher's report and the swap), and those a swap happened just before.
    let busy = |t: &shoal::live::TickTime| {
        samples
            .iter()
            .any(|x| t.started + t.step >= x.detected && t.started <= x.accepted)
    };
    let mut normal: Vec<f64> = ticks
        .iter()
        .filter(|t| t.swap.is_zero() && !busy(t))
        .map(|t| ms(t.step))
        .collect();
    let mut during: Vec<f64> = ticks
        .iter()
        .filter(|t| t.swap.is_zero() && busy(t))
        .map(|t| ms(t.step))
        .collect();
    let mut swap_ticks: Vec<f64> = ticks
        .iter()
        .filter(|t| !t.swap.is_zero())
        .map(|t| ms(t.step + t.swap))
        .collect();
    let median = percentile(&mut normal, 0.5);
    let row = |name: &str, v: &mut Vec<f64>| {
        let n = v.len();
        println!(
            "| {name} | {n} | {:.1} | {:.1} | {:.1} | {:.1} |",
            percentile(v, 0.0),
            percentile(v, 0.5),
            percentile(v, 0.9),
            percentile(v, 1.0)
        );
    };
    println!(
        "reload latency: {agents} agents, {lines}-line script, debounce {} ms, speed {speed}, {reloads} reloads (script and species file in turn)\n",
        debounce.as_millis()
    );
    println!("| save → first tick with the new version (ms) | n | min | median | p90 | max |");
    println!("|---|---|---|---|---|---|");
    row("all edits", &mut total);
    row("script edits (500 lines recompiled)", &mut script_edits);
    row("species file edits", &mut species_edits);
    row("  of which: save → watcher reports it", &mut watcher);
    row("  of which: load, compile, dry run", &mut prepare);
    row("    read, parse, validate, compile", &mut loads);
    row("    dry run (one tick, every script)", &mut dry_runs);
    row("  of which: swap → end of the next tick", &mut to_tick);
    row("  the swap itself (simulation thread)", &mut swaps);
    println!();
    println!("| tick duration (ms) | n | min | median | p90 | max |");
    println!("|---|---|---|---|---|---|");
    row("normal ticks", &mut normal);
    row("ticks while a reload is prepared", &mut during);
    row("tick with a swap (swap + step)", &mut swap_ticks);
    // Paired comparison, robust to a noisy machine: each tick against the median of the two
    // ticks before and the two after it.
    let ratio = |i: usize| -> Option<f64> {
        if i < 2 || i + 2 >= ticks.len() {
            return None;
        }
        let mut n: Vec<f64> = [i - 2, i - 1, i + 1, i + 2]
            .iter()
            .map(|&j| ms(ticks[j].step))
            .collect();
        Some(ms(ticks[i].step + ticks[i].swap) / percentile(&mut n, 0.5))
    };
    let (mut r_swap, mut r_normal) = (Vec::new(), Vec::new());
    for (i, t) in ticks.iter().enumerate() {
        if let Some(r) = ratio(i) {
            if t.swap.is_zero() {
                r_normal.push(r);
            } else {
                r_swap.push(r);
            }
        }
    }
    let over = |v: &[f64]| v.iter().filter(|r| **r > 2.0).count();
    println!();
    println!("| tick / median of its 4 neighbors | n | median | p90 | max | share above 2× |");
    println!("|---|---|---|---|---|---|");
    for (name, v) in [
        ("tick with a swap", &mut r_swap),
        ("normal tick", &mut r_normal),
    ] {
        let n = v.len();
        let above = over(v);
        println!(
            "| {name} | {n} | {:.2} | {:.2} | {:.2} | {} ({:.0}%) |",
            percentile(v, 0.5),
            percentile(v, 0.9),
            percentile(v, 1.0),
            above,
            100.0 * above as f64 / n.max(1) as f64
        );
    }
    let worst = percentile(&mut during, 1.0).max(percentile(&mut swap_ticks, 1.0));
    println!(
        "\nworst tick during a reload: {:.2} ms = {:.2}× the median normal tick ({:.2} ms)",
        worst,
        worst / median,
        median
    );
}
