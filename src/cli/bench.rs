//! `shoal bench`: runs the standard benchmark workloads of [`shoal::bench`] and prints a table.

use shoal::bench::{self, Workload};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `shoal bench`.
#[derive(clap::Args, Debug, Default)]
pub struct BenchArgs {
    /// Workload: boids, reference, flock, reef, reef-native, decide, decide-native, perceive,
    /// plan, plan-weighted (default: all of them); or `sweep`: the overhead of `shoal sweep run`
    /// over 100 runs of scenarios/tiny.ron (`--runs`, `--scenario`).
    pub workload: Option<String>,
    /// Agent counts, comma-separated (default: the workload's standard sizes).
    #[arg(long, value_delimiter = ',')]
    pub agents: Vec<usize>,
    /// Ticks to time per size (default: about two million agent-updates, 20 to 500 ticks).
    #[arg(long)]
    pub ticks: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Folder of the reef species (default: the source tree's `behaviors/`).
    #[arg(long)]
    pub behaviors: Option<PathBuf>,
    /// Measure each size this many times (a fresh world each time, the same work) and print
    /// the run of median speed, with the slowest and fastest runs' ticks/s; B/agent is then
    /// the first run's (later runs reuse memory the first one freed).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
    /// Under each row of the tick workloads and `perceive`, the wall time per tick of each
    /// stage of the pipeline (index, perception, agents: drives to locomotion, events), for
    /// the run of the row.
    #[arg(long)]
    pub stages: bool,
    /// Heuristic weight of `plan-weighted` (default 1.25; 1 is the exact search).
    #[arg(long, value_name = "W", value_parser = search_weight)]
    pub search_weight: Option<f32>,
    /// `sweep` only: how many runs.
    #[arg(long, default_value_t = 100)]
    pub runs: u32,
    /// `sweep` only: the scenario (default: scenarios/tiny.ron).
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// `sweep` only: each run's duration in seconds (default: the scenario's).
    #[arg(long)]
    pub duration: Option<f32>,
}

/// A heuristic weight in [1, 10].
fn search_weight(s: &str) -> Result<f32, String> {
    let w: f32 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    let max = shoal::formation::astar::MAX_SEARCH_WEIGHT;
    if (1.0..=max).contains(&w) {
        Ok(w)
    } else {
        Err(format!(
            "the search weight must be from 1 to {max}, not {s}"
        ))
    }
}

/// Runs `shoal bench`.
pub fn bench(args: BenchArgs) -> anyhow::Result<ExitCode> {
    if args.workload.as_deref() == Some("sweep") {
        let scenario = args
            .scenario
            .clone()
            .unwrap_or_else(|| PathBuf::from("scenarios/tiny.ron"));
        return super::sweep::bench_overhead(&scenario, args.runs, args.duration);
    }
    let workloads: Vec<Workload> = match &args.workload {
        None => Workload::ALL.to_vec(),
        Some(name) => match Workload::parse(name) {
            Some(w) => vec![w],
            None => {
                let known: Vec<&str> = Workload::ALL.iter().map(|w| w.name()).collect();
                eprintln!(
                    "error: unknown workload \"{name}\" (workloads: {})",
                    known.join(", ")
                );
                return Ok(ExitCode::from(super::BAD_INPUT));
            }
        },
    };
    let behaviors = args
        .behaviors
        .clone()
        .unwrap_or_else(bench::default_behaviors_dir);
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        pool = pool.num_threads(n.max(1));
    }
    let pool = pool.build()?;
    println!(
        "threads: {}   agent-upd/s = agents × ticks/s; ns/upd = wall time per agent-update; \
         nbrs = kin perceived per agent; B/agent = peak RSS while running, per agent",
        pool.current_num_threads()
    );
    let repeat = args.repeat.max(1) as usize;
    if repeat > 1 {
        println!(
            "each row: the run of median ticks/s among {repeat}, then the slowest and fastest runs' ticks/s"
        );
    }
    println!(
        "{:<14} {:>8} {:>6} {:>10} {:>14} {:>10} {:>9} {:>8} {:>10}{}",
        "workload",
        "agents",
        "ticks",
        "ticks/s",
        "agent-upd/s",
        "ms/tick",
        "ns/upd",
        "nbrs",
        "B/agent",
        if repeat > 1 {
            format!(" {:>10} {:>10}", "slowest", "fastest")
        } else {
            String::new()
        }
    );
    for w in workloads {
        let sizes: Vec<usize> = if args.agents.is_empty() {
            w.default_agents().to_vec()
        } else {
            args.agents.clone()
        };
        for n in sizes {
            let ticks = args.ticks.unwrap_or_else(|| w.default_ticks(n)).max(1);
            let mut samples = Vec::with_capacity(repeat);
            for _ in 0..repeat {
                let measured = match (w, args.search_weight) {
                    (Workload::PlanWeighted, Some(weight)) => {
                        Ok(bench::plan::measure(ticks, weight))
                    }
                    _ => pool.install(|| bench::measure(w, n, ticks, &behaviors)),
                };
                match measured {
                    Ok(Some(s)) => samples.push(s),
                    Ok(None) => break,
                    Err(d) => return Ok(super::report(&d)),
                }
            }
            let first_memory = samples.first().and_then(|s| s.bytes_per_agent);
            let (slowest, fastest) = samples.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), s| {
                (lo.min(s.ticks_per_s()), hi.max(s.ticks_per_s()))
            });
            match bench::median_sample(samples) {
                Some(s) => {
                    println!(
                        "{:<14} {:>8} {:>6} {:>10.1} {:>14.0} {:>10.3} {:>9.0} {:>8.1} {:>10}{}",
                        s.workload,
                        s.agents,
                        s.ticks,
                        s.ticks_per_s(),
                        s.updates_per_s(),
                        s.ms_per_tick(),
                        1e9 / s.updates_per_s().max(1e-9),
                        s.neighbors,
                        first_memory.map_or("-".to_string(), |b| format!("{b:.0}")),
                        if repeat > 1 {
                            format!(" {slowest:>10.1} {fastest:>10.1}")
                        } else {
                            String::new()
                        }
                    );
                    if let Some(t) = s.stages.filter(|_| args.stages) {
                        let parts: Vec<String> = t
                            .ms_per_tick()
                            .iter()
                            .map(|(name, ms)| format!("{name} {ms:.3}"))
                            .collect();
                        println!("  stages, ms/tick: {}", parts.join(", "));
                    }
                    if let Some((first, last)) = s.steady {
                        println!(
                            "  steady: {first:.1} ticks/s over the first tenth, {last:.1} over the \
                             last ({:.2}×)",
                            last / first.max(1e-12)
                        );
                    }
                    if let Some(note) = &s.note {
                        println!("  {note}");
                    }
                }
                None => {
                    println!(
                        "{:<14} no plan: the benchmark map has no path between its corners \
                         (see src/bench/plan.rs)",
                        w.name()
                    );
                    break;
                }
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
