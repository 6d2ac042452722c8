//! `shoal run` and `shoal rerun`: headless recorded runs.

use anyhow::Context as _;
use shoal::health::Monitor;
use shoal::record::Recorder;
use shoal::scenario::{Overrides, Run, Scenario};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Arguments of `shoal run`.
#[derive(clap::Args, Debug, Default)]
pub struct RunArgs {
    /// Scenario file (default: scenarios/reef.ron).
    pub scenario: Option<PathBuf>,
    /// Seed (default: the scenario's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Duration in seconds (default: the scenario's).
    #[arg(long)]
    pub duration: Option<f32>,
    /// Override a key of the scenario or of a species file it loads, with a RON value:
    /// `scenario.groups[0].count=50`, `sardine.senses.vision_radius=6` (repeatable; see
    /// docs/scenarios.md, "Overriding keys").
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Output folder (default: runs/<scenario>-<seed>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Record every this many ticks (default: the scenario's).
    #[arg(long)]
    pub interval: Option<u32>,
    /// Print nothing but errors and the output folder.
    #[arg(long, short)]
    pub quiet: bool,
    /// Do not follow the run's health (no `health.json`, no health section).
    #[arg(long)]
    pub no_health: bool,
    /// Longest a script call may run, in milliseconds (0: no limit). A call stopped by it makes
    /// the run fail: its results would depend on the machine's speed.
    #[arg(long, value_name = "MS")]
    pub script_call_ms: Option<u64>,
    /// Script time the calls of one tick may add up to on one thread, in milliseconds (0: no
    /// limit); like `--script-call-ms`, a guard that fails the run.
    #[arg(long, value_name = "MS")]
    pub script_tick_ms: Option<u64>,
    /// Also record `explain.jsonl`: why each agent moves as it does on every recorded frame
    /// (the steering term in control, its target, pressures, ...) and every decision's clauses.
    #[arg(long)]
    pub explain: bool,
}

/// Arguments of `shoal rerun`.
#[derive(clap::Args, Debug, Default)]
pub struct RerunArgs {
    /// A run folder written by `shoal run`.
    pub dir: PathBuf,
    /// Worker threads.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Where to write the re-run (default: <DIR>/rerun).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// What a finished (or stopped) run reports.
pub struct Outcome {
    /// The run folder.
    pub dir: PathBuf,
    /// Whether all ticks ran.
    pub complete: bool,
    /// Script calls stopped by a wall-time budget (the results then depend on the machine).
    pub script_timeouts: u64,
}

/// A thread pool of `threads` workers (default: all cores), and its size.
pub fn pool(threads: Option<usize>) -> anyhow::Result<(rayon::ThreadPool, usize)> {
    let n = threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    Ok((rayon::ThreadPoolBuilder::new().num_threads(n).build()?, n))
}

fn interrupted() -> Arc<AtomicBool> {
    static FLAG: std::sync::OnceLock<Arc<AtomicBool>> = std::sync::OnceLock::new();
    FLAG.get_or_init(|| {
        let f = Arc::new(AtomicBool::new(false));
        let g = f.clone();
        let _ = ctrlc::set_handler(move || g.store(true, Ordering::SeqCst));
        f
    })
    .clone()
}

/// Script errors `shoal run` prints in full (the summary counts them all).
const ERRORS_PRINTED: usize = 5;

/// Runs `run` to its end, recording into `dir`; prints a progress bar on a terminal. With
/// `health`, a [`Monitor`] follows the run: its report goes to `health.json` and the manifest's
/// summary, and (unless `quiet`) its section is printed after the summary.
pub fn execute(
    run: Run,
    dir: &Path,
    interval: u32,
    threads: Option<usize>,
    quiet: bool,
    health: bool,
) -> anyhow::Result<Outcome> {
    execute_with_versions(run, Vec::new(), dir, interval, threads, quiet, health)
}

/// [`execute`], swapping in each of `versions` (`(tick, scenario)`, ascending) at its tick, as
/// a live session did (a live record re-run: see [`rerun`]).
fn execute_with_versions(
    mut run: Run,
    versions: Vec<(u64, Scenario)>,
    dir: &Path,
    interval: u32,
    threads: Option<usize>,
    quiet: bool,
    health: bool,
) -> anyhow::Result<Outcome> {
    let mut versions = versions.into_iter().peekable();
    let mut first_errors: Vec<String> = Vec::new();
    let (pool, n_threads) = pool(threads)?;
    let stop = interrupted();
    let mut rec = Recorder::start(dir, &run, interval, n_threads)?;
    rec.states(&run)?;
    // Expectations the scenario declares are judged along the way and reported in the summary.
    // Loading checked them, so this fails only for a scenario built some other way: say so.
    let mut tracker = Some(
        shoal::scenario::expect::Tracker::new(&run.scenario)
            .map_err(|d| anyhow::anyhow!("expectations: {d}"))?,
    );
    let mut monitor = health.then(|| Monitor::new(&run.pipeline.species, run.world.dt));
    let mut monitoring = Duration::ZERO;
    let progress = !quiet && std::io::stderr().is_terminal();
    run.pipeline.reset_stage_times();
    let start = Instant::now();
    let mut recording = Duration::ZERO;
    let mut last_draw = Instant::now();
    let total = run.total_ticks.max(1);
    let result: anyhow::Result<()> = pool.install(|| {
        while !run.finished() {
            if stop.load(Ordering::SeqCst) {
                anyhow::bail!("interrupted (Ctrl-C or SIGTERM)");
            }
            while let Some((_, scenario)) = versions.next_if(|v| v.0 <= run.world.tick) {
                if let Err(d) = run.reload(scenario) {
                    anyhow::bail!("a recorded version could not be swapped in:\n{d}");
                }
            }
            run.step();
            if first_errors.len() < ERRORS_PRINTED {
                first_errors.extend(script_errors(&run).take(ERRORS_PRINTED - first_errors.len()));
            }
            let stepped = Instant::now();
            rec.record_tick(&run)?;
            recording += stepped.elapsed();
            if let Some(t) = tracker.as_mut() {
                t.observe_run(&run);
            }
            if let Some(m) = monitor.as_mut() {
                let t0 = Instant::now();
                m.observe(&run.world, &run.pipeline);
                monitoring += t0.elapsed();
            }
            if progress && last_draw.elapsed().as_millis() >= 100 {
                last_draw = Instant::now();
                let done = run.world.tick;
                let rate = done as f64 / start.elapsed().as_secs_f64().max(1e-9);
                let eta = (total - done.min(total)) as f64 / rate.max(1e-9);
                let width = 30;
                let filled = (done as usize * width / total as usize).min(width);
                eprint!(
                    "\r[{}{}] {:>3}% {:>8.0} ticks/s  ETA {:>5.1}s ",
                    "#".repeat(filled),
                    " ".repeat(width - filled),
                    done * 100 / total,
                    rate,
                    eta
                );
                let _ = std::io::stderr().flush();
            }
        }
        Ok(())
    });
    if progress {
        eprint!("\r{}\r", " ".repeat(70));
    }
    let elapsed = start.elapsed().as_secs_f64();
    match result {
        Ok(()) => {
            let mut summary = run.summary(elapsed);
            summary["time_shares"] = time_shares(&run, elapsed, recording);
            let verdicts = tracker
                .filter(|t| !t.is_empty())
                .map(|t| t.finish(&run.world, &run.pipeline))
                .unwrap_or_default();
            summary["expectations"] = serde_json::Value::Array(
                verdicts
                    .iter()
                    .map(|v| serde_json::json!({"expected": v.expected, "passed": v.passed, "observed": v.observed}))
                    .collect(),
            );
            let report = monitor.map(|m| m.report());
            if let Some(h) = &report {
                summary["health"] = h.headline();
                rec.add_output(
                    shoal::health::FILE,
                    serde_json::to_string_pretty(&h.to_json())?.as_bytes(),
                )?;
            }
            print_errors(&first_errors, run.pipeline.stats.script_errors, quiet);
            if !quiet {
                print_summary(&run, &summary);
                for v in &verdicts {
                    let mark = if v.passed { "met" } else { "NOT MET" };
                    println!("  expectation {mark}: {} ({})", v.expected, v.observed);
                }
                if let Some(h) = &report {
                    let cost = monitoring.as_secs_f64() / elapsed.max(1e-9);
                    super::health::print(h, Some(cost));
                }
            }
            let dir = rec.finish(&run, n_threads, summary)?;
            Ok(Outcome {
                dir,
                complete: true,
                script_timeouts: run.pipeline.stats.script_timeouts,
            })
        }
        Err(e) => {
            let dir = rec.abort(&run, n_threads, &format!("{e:#}"))?;
            eprintln!(
                "run stopped at tick {} of {}: {e:#}",
                run.world.tick, run.total_ticks
            );
            Ok(Outcome {
                dir,
                complete: false,
                script_timeouts: run.pipeline.stats.script_timeouts,
            })
        }
    }
}

/// This tick's script errors, one line each: tick, agent, species and the located message.
fn script_errors(run: &Run) -> impl Iterator<Item = String> + '_ {
    let tick = run.world.tick.saturating_sub(1);
    let names = &run.pipeline.species.species;
    run.pipeline.events.iter().filter_map(move |e| match e {
        shoal::events::Event::ScriptError {
            agent,
            species,
            message,
        } => {
            let sp = names
                .get(*species as usize)
                .map_or("?", |s| s.name.as_str());
            Some(format!(
                "tick {tick}, agent {} ({sp}): {}",
                agent.0,
                message.trim_end().replace('\n', "\n      ")
            ))
        }
        _ => None,
    })
}

/// Prints the first script errors of a run (each agent's first error is an event; `total`
/// counts every failed call), on stderr when `quiet`.
fn print_errors(first: &[String], total: u64, quiet: bool) {
    if first.is_empty() {
        return;
    }
    let head = format!(
        "script errors: {total} failed call(s); the first {} reported:",
        first.len()
    );
    let lines = std::iter::once(head).chain(first.iter().map(|l| format!("  {l}")));
    for l in lines {
        if quiet {
            eprintln!("{l}");
        } else {
            println!("{l}");
        }
    }
}

/// Where the run's wall time went: each stage of the tick, the recording, and the rest (what
/// the scenario does around the pipeline: its timed events, food, squads' plans; the tick's
/// own setup, such as waking a helper thread; expectations; the health monitor; the progress
/// bar), as shares of the whole, rounded to 0.1 %. The whole ends with the last tick: the
/// final flush of the recording is not in it.
fn time_shares(run: &Run, elapsed: f64, recording: Duration) -> serde_json::Value {
    let whole = elapsed.max(1e-9);
    let share = |d: Duration| (d.as_secs_f64() / whole * 1000.0).round() / 1000.0;
    let stages = run.pipeline.stage_times().parts();
    let timed = stages.iter().map(|p| p.1).sum::<Duration>() + recording;
    let other = Duration::from_secs_f64(elapsed).saturating_sub(timed);
    let parts = stages
        .into_iter()
        .chain([("recording", recording), ("other", other)]);
    serde_json::Value::Object(
        parts
            .map(|(name, d)| (name.to_string(), serde_json::json!(share(d))))
            .collect(),
    )
}

/// The names of [`time_shares`] in pipeline order (its JSON object sorts them).
fn time_part_names() -> impl Iterator<Item = &'static str> {
    shoal::tick::StageTimes::NAMES
        .into_iter()
        .chain(["recording", "other"])
}

fn print_summary(run: &Run, s: &serde_json::Value) {
    println!(
        "scenario {} (seed {}): {} ticks, {:.1} s simulated",
        run.scenario.name,
        run.world.seed,
        run.world.tick,
        run.world.time()
    );
    println!("  alive:");
    for (name, n) in run.alive() {
        println!("    {name:<14} {n}");
    }
    println!(
        "  food eaten {}, catches {}, matings {}, transitions {}, script errors {}",
        s["food_eaten"], s["catches"], s["matings"], s["transitions"], s["script_errors"]
    );
    println!("  behavior time shares:");
    if let Some(m) = s["behavior_shares"].as_object() {
        for (sp, shares) in m {
            let mut parts: Vec<(String, f64)> = shares
                .as_object()
                .map(|o| {
                    o.iter()
                        .map(|(k, v)| (k.clone(), v.as_f64().unwrap_or(0.0)))
                        .collect()
                })
                .unwrap_or_default();
            parts.retain(|p| p.1 > 0.0);
            parts.sort_by(|a, b| b.1.total_cmp(&a.1));
            let text: Vec<String> = parts
                .iter()
                .map(|(k, v)| format!("{k} {:.0}%", v * 100.0))
                .collect();
            println!("    {sp:<14} {}", text.join(", "));
        }
    }
    println!(
        "  speed: {:.0} ticks/s",
        s["ticks_per_second"].as_f64().unwrap_or(0.0)
    );
    let shares = &s["time_shares"];
    if shares.is_object() {
        // In pipeline order (the JSON object's keys are sorted).
        let parts: Vec<String> = time_part_names()
            .map(|k| format!("{k} {:.1}%", shares[k].as_f64().unwrap_or(0.0) * 100.0))
            .collect();
        println!("  wall time: {}", parts.join(", "));
    }
}

/// Runs `shoal run`.
pub fn run(args: RunArgs) -> anyhow::Result<ExitCode> {
    let file = args
        .scenario
        .clone()
        .unwrap_or_else(|| PathBuf::from("scenarios/reef.ron"));
    let mut set = Vec::new();
    for s in &args.set {
        match shoal::scenario::Setting::parse(s) {
            Ok(s) => set.push(s),
            Err(e) => {
                eprintln!("error: --set {e}");
                return Ok(ExitCode::from(2));
            }
        }
    }
    let scenario = match Scenario::load_with(&file, &set) {
        Ok(s) => s,
        Err(d) => return Ok(super::report(&d)),
    };
    let seed = args.seed.unwrap_or(scenario.def.seed);
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{}-{seed}", scenario.name)));
    let interval = args.interval.unwrap_or(scenario.def.record.interval).max(1);
    let mut run = Run::new(
        scenario,
        Overrides {
            seed: Some(seed),
            duration: args.duration,
            set,
        },
    );
    run.pipeline.set_time_budget(time_budget(&args));
    if args.explain || run.scenario.def.record.explain {
        run.pipeline.explain.every = interval;
    }
    let out = execute(
        run,
        &dir,
        interval,
        args.threads,
        args.quiet,
        !args.no_health,
    )?;
    if out.script_timeouts > 0 {
        eprintln!(
            "error: {} script call(s) ran past their time budget (see the script_error events): the results in {} depend on the machine's speed",
            out.script_timeouts,
            out.dir.display()
        );
        Ok(ExitCode::from(1))
    } else if out.complete {
        println!("output written to {}", out.dir.display());
        Ok(ExitCode::SUCCESS)
    } else {
        println!(
            "incomplete output left in {} (marked INCOMPLETE)",
            out.dir.display()
        );
        Ok(ExitCode::from(130))
    }
}

/// The script time budgets `args` ask for (the defaults where they say nothing; 0 turns one off).
fn time_budget(args: &RunArgs) -> shoal::script::TimeBudget {
    let default = shoal::script::TimeBudget::default();
    let ms = |v: Option<u64>, d: Option<Duration>| match v {
        None => d,
        Some(0) => None,
        Some(ms) => Some(Duration::from_millis(ms)),
    };
    shoal::script::TimeBudget {
        per_call: ms(args.script_call_ms, default.per_call),
        per_tick: ms(args.script_tick_ms, default.per_tick),
    }
}

/// Why the run folder `dir` with `manifest` is incomplete (interrupted, or still running), if it
/// is: its manifest does not say `complete`, or an `INCOMPLETE` marker is there.
pub fn incomplete(dir: &Path, manifest: &serde_json::Value) -> Option<String> {
    let marker = std::fs::read_to_string(dir.join("INCOMPLETE")).ok();
    if manifest["status"] == "complete" && marker.is_none() {
        return None;
    }
    let why = match (&marker, manifest["summary"]["stopped"].as_str()) {
        (Some(m), _) if !m.trim().is_empty() => m.trim().to_string(),
        (_, Some(reason)) => format!(
            "stopped at tick {} of {}: {reason}",
            manifest["ticks"], manifest["total_ticks"]
        ),
        _ => format!(
            "marked {} at tick {} of {}",
            manifest["status"], manifest["ticks"], manifest["total_ticks"]
        ),
    };
    Some(why)
}

/// Runs `shoal rerun`: replays the resolved scenario with the stored inputs and compares the
/// recorded files byte for byte.
pub fn rerun(args: RerunArgs) -> anyhow::Result<ExitCode> {
    if shoal::live::record::is_record(&args.dir) && !args.dir.join("manifest.json").exists() {
        let out = args.out.clone().unwrap_or_else(|| args.dir.join("rerun"));
        return match replay_live(&args.dir, &out, args.threads, false)? {
            Ok(o) if o.complete => {
                println!(
                    "live record {} re-run into {}",
                    args.dir.display(),
                    o.dir.display()
                );
                Ok(ExitCode::SUCCESS)
            }
            Ok(_) => Ok(ExitCode::from(130)),
            Err(d) => Ok(super::report(&d)),
        };
    }
    let manifest_file = args.dir.join("manifest.json");
    let manifest: serde_json::Value = serde_json::from_slice(&read(&manifest_file)?)
        .with_context(|| format!("{}: not a run manifest", manifest_file.display()))?;
    let scenario_file = args.dir.join("scenario.ron");
    let scenario = match Scenario::load(&scenario_file) {
        Ok(s) => s,
        Err(d) => return Ok(super::report(&d)),
    };
    // Inputs changed since the run? Report it (the stored copies are what is re-run).
    if let Some(files) = manifest["files"].as_object() {
        for (rel, hash) in files {
            let stored = args.dir.join("inputs").join(rel);
            let now = shoal::record::sha256_file(&stored).unwrap_or_default();
            if Some(now.as_str()) != hash.as_str() {
                eprintln!(
                    "warning: stored input {} does not match its recorded hash",
                    stored.display()
                );
            }
        }
    }
    let interval = manifest["record_interval"].as_u64().unwrap_or(1) as u32;
    let out = args.out.clone().unwrap_or_else(|| args.dir.join("rerun"));
    let mut run = Run::new(scenario, Overrides::default());
    // An interrupted run is re-run as far as it got, and said to be incomplete up front.
    let stopped_at = match incomplete(&args.dir, &manifest) {
        Some(why) => {
            println!("{} is an incomplete run: {why}", args.dir.display());
            let Some(ticks) = manifest["ticks"].as_u64() else {
                anyhow::bail!(
                    "{}: the manifest does not say how many ticks it ran; nothing to compare",
                    args.dir.display()
                );
            };
            println!("re-running only the {ticks} ticks it recorded");
            run.total_ticks = run.total_ticks.min(ticks);
            Some(ticks)
        }
        None => None,
    };
    let o = execute(run, &out, interval, args.threads, true, true)?;
    if !o.complete {
        return Ok(ExitCode::from(130));
    }
    if o.script_timeouts > 0 {
        eprintln!(
            "error: {} script call(s) of the re-run ran past their time budget: it cannot be compared",
            o.script_timeouts
        );
        return Ok(ExitCode::from(1));
    }
    let mut same = true;
    for f in ["trajectories.csv", "food.csv", "events.jsonl"] {
        let a = read(&args.dir.join(f))?;
        let b = read(&out.join(f))?;
        if a == b {
            println!("{f}: identical ({} bytes)", a.len());
        } else {
            same = false;
            println!("{f}: DIFFERENT ({} vs {} bytes)", a.len(), b.len());
        }
    }
    let scope = match stopped_at {
        Some(t) => format!(" over the {t} ticks of the incomplete run"),
        None => String::new(),
    };
    if same {
        println!("re-run matches bit for bit{scope}: {}", out.display());
        Ok(ExitCode::SUCCESS)
    } else {
        println!(
            "re-run differs{scope}; see `shoal diff {} {}`",
            args.dir.display(),
            out.display()
        );
        Ok(ExitCode::from(1))
    }
}

/// Re-runs the live session recorded in `dir` (a `shoal watch --record` folder) into the run
/// folder `out`: its first version from tick 0 with the session's seed, each later version swapped
/// in at the tick it took effect at, as far as the session ran (or the scenario's duration, when
/// the record does not say). The outer error is a failure to write; the inner one names the
/// record's file at fault.
pub fn replay_live(
    dir: &Path,
    out: &Path,
    threads: Option<usize>,
    quiet: bool,
) -> anyhow::Result<Result<Outcome, shoal::diag::Diagnostics>> {
    let rec = match shoal::live::record::read(dir) {
        Ok(r) => r,
        Err(d) => return Ok(Err(d)),
    };
    let mut scenarios = Vec::new();
    for (tick, file) in &rec.versions {
        match Scenario::load(file) {
            Ok(s) => scenarios.push((*tick, s)),
            Err(d) => return Ok(Err(d)),
        }
    }
    let (_, first) = scenarios.remove(0);
    let interval = first.def.record.interval.max(1);
    let mut run = Run::new(
        first,
        Overrides {
            seed: Some(rec.seed),
            duration: None,
            set: Vec::new(),
        },
    );
    if let Some(t) = rec.ticks {
        run.total_ticks = t;
    }
    scenarios.retain(|v| v.0 < run.total_ticks);
    if !quiet {
        println!(
            "{} is a live session record: re-running its {} version(s) over {} ticks",
            dir.display(),
            scenarios.len() + 1,
            run.total_ticks
        );
    }
    execute_with_versions(run, scenarios, out, interval, threads, quiet, true).map(Ok)
}

/// The bytes of a run-folder file; an error names the file.
fn read(path: &Path) -> anyhow::Result<Vec<u8>> {
    std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))
}
