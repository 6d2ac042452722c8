//! `shoal bench`: runs the standard benchmark workloads of [`shoal::bench`] and prints a table.

use shoal::bench::{self, Workload};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `shoal bench`.
#[derive(clap::Args, Debug, Default)]
pub struct BenchArgs {
    /// Workload: boids, flock, reef, reef-native, decide, decide-native, perceive, plan (default:
    /// all of them).
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
}

/// Runs `shoal bench`.
pub fn bench(args: BenchArgs) -> anyhow::Result<ExitCode> {
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
    println!(
        "{:<14} {:>8} {:>6} {:>10} {:>14} {:>10} {:>9} {:>8} {:>10}",
        "workload",
        "agents",
        "ticks",
        "ticks/s",
        "agent-upd/s",
        "ms/tick",
        "ns/upd",
        "nbrs",
        "B/agent"
    );
    for w in workloads {
        let sizes: Vec<usize> = if args.agents.is_empty() {
            w.default_agents().to_vec()
        } else {
            args.agents.clone()
        };
        for n in sizes {
            let ticks = args.ticks.unwrap_or_else(|| w.default_ticks(n)).max(1);
            let sample = match pool.install(|| bench::measure(w, n, ticks, &behaviors)) {
                Ok(s) => s,
                Err(d) => return Ok(super::report(&d)),
            };
            match sample {
                Some(s) => println!(
                    "{:<14} {:>8} {:>6} {:>10.1} {:>14.0} {:>10.3} {:>9.0} {:>8.1} {:>10}",
                    s.workload,
                    s.agents,
                    s.ticks,
                    s.ticks_per_s(),
                    s.updates_per_s(),
                    s.ms_per_tick(),
                    1e9 / s.updates_per_s().max(1e-9),
                    s.neighbors,
                    s.bytes_per_agent
                        .map_or("-".to_string(), |b| format!("{b:.0}")),
                ),
                None => {
                    println!(
                        "{:<14} not available in this build: the formation planner is not wired \
                         yet (see src/bench/plan.rs)",
                        w.name()
                    );
                    break;
                }
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
