//! `shoal watch SCENARIO [--port P]`: runs a scenario live with hot reload, serves the live viewer
//! on the loopback interface and prints every reload (accepted or rejected) with a timestamp.

use shoal::live::server::{live_page, Server};
use shoal::live::{LiveEvent, LiveOptions, Session};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// Arguments of `shoal watch`.
#[derive(clap::Args, Debug, Default)]
pub struct WatchArgs {
    /// Scenario file.
    pub scenario: PathBuf,
    /// Port of the live viewer on 127.0.0.1 (0: any free port).
    #[arg(long, default_value_t = 7471)]
    pub port: u16,
    /// Seed (default: the scenario's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Simulated seconds per wall-clock second.
    #[arg(long, default_value_t = 1.0)]
    pub speed: f32,
    /// Start paused.
    #[arg(long)]
    pub paused: bool,
    /// Record every version and reload in this folder, so the session can be re-run exactly.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Watcher debounce in milliseconds.
    #[arg(long, default_value_t = 50, hide = true)]
    pub debounce_ms: u64,
    /// Longest a reload may take before it is rejected as timed out, in milliseconds.
    #[arg(long, default_value_t = 10_000, hide = true)]
    pub reload_timeout_ms: u64,
}

/// `HH:MM:SS.mmm` (UTC) of `t`.
fn clock(t: SystemTime) -> String {
    let ms = t.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_millis());
    let s = ms / 1000;
    format!(
        "{:02}:{:02}:{:02}.{:03}",
        (s / 3600) % 24,
        (s / 60) % 60,
        s % 60,
        ms % 1000
    )
}

fn print_event(e: &LiveEvent) {
    match e {
        LiveEvent::Accepted(a) => {
            let files: Vec<String> = a.changed.iter().map(|p| p.display().to_string()).collect();
            println!(
                "[{}] accepted: version {} takes effect at tick {} ({})",
                clock(a.time),
                a.version,
                a.tick,
                if files.is_empty() {
                    "changed".to_string()
                } else {
                    files.join(", ")
                }
            );
            for (name, n) in &a.fell_back {
                println!(
                    "    {n} {name} agent{} fell back to the initial behavior (current behavior renamed or removed)",
                    if *n == 1 { "" } else { "s" }
                );
            }
            for (name, n) in &a.spawned {
                println!("    spawned {n} {name}");
            }
            if a.removed > 0 {
                println!(
                    "    removed {} agents of species no longer in the scenario",
                    a.removed
                );
            }
        }
        LiveEvent::Rejected(r) => {
            println!(
                "[{}] rejected: version {} keeps running",
                clock(r.time),
                r.running
            );
            for d in &r.diagnostics {
                for line in d.lines() {
                    println!("    {line}");
                }
            }
        }
        LiveEvent::Restored { time, version } => println!(
            "[{}] restored: the files match version {version} again",
            clock(*time)
        ),
        LiveEvent::ScriptError {
            time,
            tick,
            message,
            agent,
            species,
            function,
        } => {
            let function = function
                .as_deref()
                .map_or(String::new(), |f| format!(" in `{f}()`"));
            println!(
                "[{}] script error at tick {tick}, agent {agent} ({species}){function}:",
                clock(*time)
            );
            for line in message.lines() {
                println!("    {line}");
            }
        }
        LiveEvent::Breakpoint(hit) => println!(
            "[{}] paused at tick {} by breakpoint {}: {}",
            clock(SystemTime::now()),
            hit.tick,
            hit.breakpoint,
            hit.reason
        ),
        LiveEvent::WatchError { time, message } => {
            println!("[{}] watcher: {message}", clock(*time))
        }
        LiveEvent::RecordError { time, message } => {
            println!("[{}] record: {message}", clock(*time))
        }
        LiveEvent::FirstTick { .. } => {}
    }
}

/// Runs `shoal watch`.
pub fn watch(args: WatchArgs) -> anyhow::Result<ExitCode> {
    if !args.scenario.is_file() {
        eprintln!("{}: no such file", args.scenario.display());
        return Ok(ExitCode::from(super::BAD_INPUT));
    }
    let options = LiveOptions {
        debounce: Duration::from_millis(args.debounce_ms.max(1)),
        speed: args.speed,
        paused: args.paused,
        seed: args.seed,
        record: args.record.clone(),
        reload_timeout: Duration::from_millis(args.reload_timeout_ms.max(1)),
        ..LiveOptions::default()
    };
    let session = match Session::start(&args.scenario, options) {
        Ok(s) => s,
        Err(d) => return Ok(super::report(&d)),
    };
    let server = Server::start(session.handle(), live_page(), args.port).map_err(|e| {
        anyhow::anyhow!(
            "cannot serve the live viewer on 127.0.0.1:{}: {e}",
            args.port
        )
    })?;
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // Ctrl-C or SIGTERM stops the session; a second one exits at once, whatever is stuck.
        ctrlc::set_handler(move || {
            if stop.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        })?;
    }
    let species: Vec<String> = session
        .started_with
        .iter()
        .map(|(s, n)| format!("{n} {s}"))
        .collect();
    println!(
        "[{}] watching {} ({}); edits to its species, scripts and imports reload live",
        clock(SystemTime::now()),
        args.scenario.display(),
        species.join(", ")
    );
    if let Some(dir) = &args.record {
        println!("recording versions and reloads in {}", dir.display());
    }
    println!("live view: {}  (Ctrl-C to stop)", server.url());
    while !stop.load(Ordering::SeqCst) {
        match session.events().recv_timeout(Duration::from_millis(100)) {
            Ok(e) => print_event(&e),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    let reason = if stop.load(Ordering::SeqCst) {
        "interrupted (Ctrl-C or SIGTERM)"
    } else {
        "the session ended"
    };
    drop(server);
    let status = session.status();
    let all_stopped = session.stop_because(reason);
    println!(
        "[{}] stopped at tick {} (version {})",
        clock(SystemTime::now()),
        status.tick,
        status.version
    );
    if let Some(dir) = &args.record {
        println!("record in {} marked incomplete: {reason}", dir.display());
    }
    if !all_stopped {
        // A thread stuck in a system call (a reload left behind) must not keep the process up.
        println!("(a reload still running was abandoned)");
    }
    Ok(ExitCode::SUCCESS)
}
