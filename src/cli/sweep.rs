//! `shoal sweep`: `plan` lists a sweep file's numbered runs, `run` runs some or all of them into
//! an output folder (resuming: finished runs are kept), `collect` merges the finished runs into
//! `results.csv`. The work is [`shoal::sweep`]'s; this is its command line.

use shoal::sweep::{self, EntryStatus, Plan};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Arguments of `shoal sweep`.
#[derive(clap::Args, Debug)]
pub struct SweepArgs {
    #[command(subcommand)]
    cmd: SweepCmd,
}

#[derive(clap::Subcommand, Debug)]
enum SweepCmd {
    /// Print the numbered runs of a sweep file (index, seed, axis values); writes nothing.
    Plan {
        /// The sweep file.
        file: PathBuf,
        /// Print only the number of runs (for scripts: `seq 0 $((N - 1))`).
        #[arg(long)]
        count: bool,
    },
    /// Run entries of a sweep into an output folder (finished runs there are skipped).
    Run(RunArgs),
    /// Merge the finished runs of an output folder into DIR/results.csv, in index order.
    Collect {
        /// The output folder of `shoal sweep run`.
        dir: PathBuf,
        /// Collect what is finished even if some runs are not.
        #[arg(long)]
        partial: bool,
    },
}

/// Arguments of `shoal sweep run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// The sweep file.
    file: PathBuf,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Only these entries: `3`, `3,5,8-11` (what a job array's task runs).
    #[arg(long)]
    index: Option<String>,
    /// Only shard K of N (K from 0): the entries whose index is K modulo N.
    #[arg(long, value_name = "K/N")]
    shard: Option<String>,
    /// Runs at a time.
    #[arg(short = 'j', long = "jobs", default_value_t = 1)]
    jobs: usize,
    /// Worker threads of each run (runs, not threads, are the unit of a sweep).
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

/// Runs `shoal sweep`.
pub fn sweep(args: SweepArgs) -> anyhow::Result<ExitCode> {
    match args.cmd {
        SweepCmd::Plan { file, count } => plan(&file, count),
        SweepCmd::Run(a) => run(a),
        SweepCmd::Collect { dir, partial } => collect(&dir, partial),
    }
}

fn plan(file: &Path, count: bool) -> anyhow::Result<ExitCode> {
    let p = match Plan::load(file) {
        Ok(p) => p,
        Err(d) => return Ok(super::report(&d)),
    };
    if count {
        println!("{}", p.len());
        return Ok(ExitCode::SUCCESS);
    }
    println!(
        "{}: {} run(s) = {} point(s) × {} seed(s)",
        file.display(),
        p.len(),
        p.points(),
        p.def.seeds
    );
    let mut head = vec!["index".to_string(), "seed".to_string()];
    head.extend(p.keys.iter().cloned());
    println!("{}", head.join("\t"));
    for e in p.entries() {
        let mut line = vec![e.index.to_string(), e.seed.to_string()];
        line.extend(e.values().map(str::to_string));
        println!("{}", line.join("\t"));
    }
    Ok(ExitCode::SUCCESS)
}

/// Indices from `3,5,8-11`; the error says what is wrong.
pub fn parse_indices(s: &str, len: usize) -> Result<Vec<usize>, String> {
    let mut out = Vec::new();
    for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let num = |t: &str| {
            t.trim()
                .parse::<usize>()
                .map_err(|_| format!("--index: `{t}` is not an index (expected e.g. 3,5,8-11)"))
        };
        let (a, b) = match part.split_once('-') {
            Some((a, b)) => (num(a)?, num(b)?),
            None => (num(part)?, num(part)?),
        };
        if a > b {
            return Err(format!("--index: `{part}` runs backwards"));
        }
        if b >= len {
            return Err(format!(
                "--index: {b} is past the last run (the sweep has {len}: 0-{})",
                len.saturating_sub(1)
            ));
        }
        out.extend(a..=b);
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

fn run(a: RunArgs) -> anyhow::Result<ExitCode> {
    let p = match Plan::load(&a.file) {
        Ok(p) => p,
        Err(d) => return Ok(super::report(&d)),
    };
    let mut todo: Vec<usize> = match &a.index {
        Some(s) => match parse_indices(s, p.len()) {
            Ok(v) => v,
            Err(e) => {
                eprintln!("error: {e}");
                return Ok(ExitCode::from(super::BAD_INPUT));
            }
        },
        None => (0..p.len()).collect(),
    };
    if let Some(s) = &a.shard {
        let parsed = s.split_once('/').and_then(|(k, n)| {
            Some((
                k.trim().parse::<usize>().ok()?,
                n.trim().parse::<usize>().ok()?,
            ))
        });
        match parsed {
            Some((k, n)) if n > 0 && k < n => todo.retain(|i| i % n == k),
            _ => {
                eprintln!("error: --shard `{s}`: expected K/N with 0 ≤ K < N (e.g. 0/4)");
                return Ok(ExitCode::from(super::BAD_INPUT));
            }
        }
    }
    if let Err(e) = sweep::prepare(&p, &a.out) {
        eprintln!("error: {e}");
        return Ok(ExitCode::from(1));
    }
    let total = todo.len();
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let running = AtomicUsize::new(0);
    let failed: Mutex<Vec<(usize, String)>> = Mutex::new(Vec::new());
    let fatal: Mutex<Option<String>> = Mutex::new(None);
    let progress = !a.quiet && std::io::stderr().is_terminal();
    let start = Instant::now();
    let draw = |finished: bool| {
        let d = done.load(Ordering::SeqCst);
        let rate = d as f64 / start.elapsed().as_secs_f64().max(1e-9);
        let eta = (total - d.min(total)) as f64 / rate.max(1e-9);
        eprint!(
            "\r{d}/{total} done, {} running, {} failed, ETA {:.0} s   {}",
            running.load(Ordering::SeqCst),
            failed.lock().map_or(0, |f| f.len()),
            if d == 0 { 0.0 } else { eta },
            if finished { "\n" } else { "" }
        );
        let _ = std::io::stderr().flush();
    };
    std::thread::scope(|s| {
        for _ in 0..a.jobs.max(1).min(total.max(1)) {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                if k >= total || fatal.lock().map_or(true, |f| f.is_some()) {
                    break;
                }
                running.fetch_add(1, Ordering::SeqCst);
                let r = sweep::run_entry(&p, todo[k], &a.out, a.threads);
                running.fetch_sub(1, Ordering::SeqCst);
                match r {
                    Ok(EntryStatus::Failed(e)) => {
                        if let Ok(mut f) = failed.lock() {
                            f.push((todo[k], e));
                        }
                    }
                    Ok(_) => {}
                    Err(e) => {
                        if let Ok(mut f) = fatal.lock() {
                            f.get_or_insert(e.0);
                        }
                    }
                }
                done.fetch_add(1, Ordering::SeqCst);
                if progress {
                    draw(false);
                }
            });
        }
    });
    if progress {
        draw(true);
    }
    if let Some(e) = fatal.into_inner().ok().flatten() {
        eprintln!("error: {e}");
        return Ok(ExitCode::from(1));
    }
    let mut failed = failed.into_inner().unwrap_or_default();
    failed.sort();
    for (i, e) in &failed {
        eprintln!("run {i} failed: {}", e.trim_end());
    }
    if !a.quiet {
        println!(
            "{} run(s) of {} in {}: {} failed",
            total,
            p.len(),
            a.out.display(),
            failed.len()
        );
    }
    Ok(if failed.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn collect(dir: &Path, partial: bool) -> anyhow::Result<ExitCode> {
    let t = if partial {
        sweep::collect_partial(dir)
    } else {
        sweep::collect(dir)
    };
    let t = match t {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return Ok(ExitCode::from(1));
        }
    };
    let csv = dir.join("results.csv");
    t.write_csv(&csv)?;
    if !t.missing.is_empty() {
        eprintln!(
            "warning: {} run(s) not finished, left out: {}",
            t.missing.len(),
            sweep::exec::ranges(&t.missing)
        );
    }
    println!(
        "{} run(s), {} column(s): {}",
        t.rows.len(),
        t.names.len(),
        csv.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// `shoal bench sweep`: the throughput of `runs` runs of `scenario` through `shoal sweep run -j 1`
/// (a process, a plan, a folder and a row per run) against the same runs back to back in this
/// process (load, run, nothing kept), and their ratio.
pub fn bench_overhead(
    scenario: &Path,
    runs: u32,
    duration: Option<f32>,
) -> anyhow::Result<ExitCode> {
    let tmp = std::env::temp_dir().join(format!("shoal-sweep-bench-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp)?;
    let abs = std::fs::canonicalize(scenario)?;
    let text = std::fs::read_to_string(&abs)?;
    let def: shoal::scenario::ScenarioDef = shoal::load::ron_options().from_str(&text)?;
    let duration = duration.unwrap_or(def.duration);
    let file = tmp.join("bench.ron");
    std::fs::write(
        &file,
        format!(
            "Sweep(scenario: {:?}, duration: Some({duration:?}), seeds: {runs}, \
             axes: [(key: \"scenario.dt\", values: [{:?}])])",
            abs.display().to_string(),
            def.dt
        ),
    )?;
    let plan = match Plan::load(&file) {
        Ok(p) => p,
        Err(d) => return Ok(super::report(&d)),
    };
    // Back to back in one process: the same seeds, nothing written.
    let t0 = Instant::now();
    for e in plan.entries() {
        let sc = shoal::scenario::Scenario::load(&abs).map_err(|d| anyhow::anyhow!("{d}"))?;
        let mut r = shoal::scenario::Run::new(
            sc,
            shoal::scenario::Overrides {
                seed: Some(e.seed),
                duration: Some(duration),
                set: Vec::new(),
            },
        );
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
        pool.install(|| {
            while !r.finished() {
                r.step();
            }
        });
    }
    let inline = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let status = std::process::Command::new(std::env::current_exe()?)
        .args(["sweep", "run", "-q", "-j", "1", "--out"])
        .arg(tmp.join("out"))
        .arg(&file)
        .status()?;
    let swept = t1.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(&tmp);
    anyhow::ensure!(status.success(), "shoal sweep run failed: {status}");
    let n = f64::from(runs);
    println!(
        "{runs} runs of {} ({duration} s each), one thread per run:",
        scenario.display()
    );
    println!(
        "  back to back in one process: {:>8.1} runs/s ({:.2} s)",
        n / inline,
        inline
    );
    println!(
        "  shoal sweep run -j 1:        {:>8.1} runs/s ({:.2} s)",
        n / swept,
        swept
    );
    println!(
        "  ratio {:.3} (target ≥ 0.90); sweep overhead {:.1} ms per run",
        inline / swept,
        (swept - inline) / n * 1000.0
    );
    Ok(ExitCode::SUCCESS)
}
