//! `shoal health RUN_DIR`: the run-health section of a recorded run, from its `health.json`, or
//! (a folder recorded before runs kept one) by re-running its stored inputs with the monitor on.
//! Also prints that section for `shoal run`.

use shoal::health::{self, Health, Monitor};
use shoal::scenario::{Overrides, Run, Scenario};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `shoal health`.
#[derive(clap::Args, Debug, Default)]
pub struct HealthArgs {
    /// A run folder written by `shoal run`.
    pub dir: PathBuf,
    /// Worker threads for a re-run (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

/// A share as a percentage with one decimal.
fn pct(x: f64) -> String {
    format!("{:.1}%", x * 100.0)
}

/// `text`, with a `!` when `bad`, right-aligned in `width`.
fn cell(text: String, bad: bool, width: usize) -> String {
    let t = if bad {
        format!("{text}!")
    } else {
        format!("{text} ")
    };
    format!("{t:>width$}")
}

/// Prints the run-health section: a table of the figures per species (with their bounds; `!`
/// marks a figure out of bounds), the coincident pairs and the warnings. `cost` is the share of
/// the run's wall time the monitor took, when known.
pub fn print(h: &Health, cost: Option<f64>) {
    let cost = cost.map_or(String::new(), |c| {
        format!("; monitor {:.1}% of wall time", c * 100.0)
    });
    println!("run health ({} ticks{cost}; ! = past the bound):", h.ticks);
    let widths = [9, 8, 11, 10, 10, 12, 9, 11, 8];
    let head = [
        "stopped",
        "frozen",
        "pitch limit",
        "switch/s",
        "short ep.",
        "turn waste",
        "overlap",
        "obstacles",
        "msg/s",
    ];
    let name_w = h
        .species
        .iter()
        .map(|s| s.name.chars().count())
        .max()
        .unwrap_or(0)
        .max(7);
    let row = |name: &str, cells: Vec<String>| {
        let mut line = format!("  {name:<name_w$}");
        for c in cells {
            line.push_str(&c);
        }
        println!("{}", line.trim_end());
    };
    row(
        "species",
        head.iter()
            .zip(widths)
            .map(|(t, w)| format!("{t:>w$} "))
            .collect(),
    );
    let bounds = [
        format!("≤{}", pct(health::MAX_STOPPED_SHARE)),
        format!("≤{}", health::MAX_FROZEN),
        format!("≤{}", pct(health::MAX_PITCH_LIMIT_SHARE)),
        format!("≤{}", health::MAX_SWITCH_RATE),
        format!("≤{}", pct(health::MAX_SHORT_EPISODE_SHARE)),
        format!("≤{:.1}×", health::MAX_TURNING_WASTE),
        format!("≤{}", pct(health::MAX_OVERLAP_SHARE)),
        format!("≤{}", health::MAX_OBSTACLE_PENETRATION),
        String::new(),
    ];
    row(
        "(bound)",
        bounds
            .into_iter()
            .zip(widths)
            .map(|(t, w)| cell(t, false, w + 1))
            .collect(),
    );
    // Figures shown but not held to their bound get a star and a line under the table.
    let mut unjudged: Vec<String> = Vec::new();
    for s in &h.species {
        let o = s.obstacles.agent_ticks;
        let star = |f: health::Figure| if s.judged(f) { "" } else { "*" };
        for (f, what) in [
            (health::Figure::PitchLimit, "pitch limit"),
            (health::Figure::ShortEpisodes, "short episodes"),
        ] {
            if let Some(why) = s.not_judged_because(f) {
                unjudged.push(format!("{} {what} ({why})", s.name));
            }
        }
        let cells = [
            (
                pct(s.stopped_share),
                s.stopped_share > health::MAX_STOPPED_SHARE,
            ),
            (
                health::thousands(s.frozen_agents),
                s.frozen_agents > health::MAX_FROZEN,
            ),
            (
                pct(s.pitch_limit_share) + star(health::Figure::PitchLimit),
                s.judged(health::Figure::PitchLimit)
                    && s.pitch_limit_share > health::MAX_PITCH_LIMIT_SHARE,
            ),
            (
                format!("{:.2}", s.switch_rate),
                s.switch_rate > health::MAX_SWITCH_RATE,
            ),
            (
                pct(s.short_episode_share) + star(health::Figure::ShortEpisodes),
                s.judged(health::Figure::ShortEpisodes)
                    && s.short_episode_share > health::MAX_SHORT_EPISODE_SHARE,
            ),
            (
                s.turning_waste.map_or("-".into(), |w| format!("{w:.2}×")),
                s.turning_waste
                    .is_some_and(|w| w > health::MAX_TURNING_WASTE),
            ),
            (
                pct(s.overlap_share),
                s.overlap_share > health::MAX_OVERLAP_SHARE,
            ),
            (health::thousands(o), o > health::MAX_OBSTACLE_PENETRATION),
            (format!("{:.2}", s.messages_per_agent_second), false),
        ];
        row(
            &s.name,
            cells
                .into_iter()
                .zip(widths)
                .map(|((t, bad), w)| cell(t, bad, w + 1))
                .collect(),
        );
    }
    if !unjudged.is_empty() {
        println!("  * not held to its bound: {}", unjudged.join("; "));
    }
    let c = &h.coincident;
    println!(
        "  coincident pairs (closer than {}): mean {:.2}, max {} per sampled tick (every {} ticks)",
        health::COINCIDENT_DISTANCE,
        c.mean,
        c.max,
        h.pair_interval
    );
    let warnings = h.warnings();
    if warnings.is_empty() {
        println!("  no warnings");
    } else {
        println!("  warnings:");
        for w in &warnings {
            println!("    {w}");
        }
    }
}

/// Runs `shoal health`.
pub fn health(args: HealthArgs) -> anyhow::Result<ExitCode> {
    let file = args.dir.join(health::FILE);
    let incomplete = args.dir.join("INCOMPLETE").exists();
    if file.is_file() {
        let text = std::fs::read_to_string(&file)?;
        let h: Health = serde_json::from_str(&text)
            .map_err(|e| anyhow::anyhow!("{}: not a health report: {e}", file.display()))?;
        print(&h, None);
        return Ok(ExitCode::SUCCESS);
    }
    let scenario_file = args.dir.join("scenario.ron");
    if !scenario_file.is_file() {
        anyhow::bail!(
            "{} is not a run folder (no {} and no scenario.ron)",
            args.dir.display(),
            health::FILE
        );
    }
    let scenario = match Scenario::load(&scenario_file) {
        Ok(s) => s,
        Err(d) => return Ok(super::report(&d)),
    };
    // An interrupted run is re-run as far as it got.
    let manifest: Option<serde_json::Value> = std::fs::read(args.dir.join("manifest.json"))
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok());
    let ticks = manifest
        .as_ref()
        .filter(|_| incomplete)
        .and_then(|m| m["ticks"].as_u64());
    eprintln!(
        "{} has no {}: re-running its stored inputs with the monitor on",
        args.dir.display(),
        health::FILE
    );
    if let Some(t) = ticks {
        eprintln!("the run did not finish (INCOMPLETE): its first {t} ticks are re-run");
    }
    let mut run = Run::new(scenario, Overrides::default());
    if let Some(t) = ticks {
        run.total_ticks = run.total_ticks.min(t);
    }
    let (pool, _) = super::run::pool(args.threads)?;
    let mut monitor = Monitor::new(&run.pipeline.species, run.world.dt);
    pool.install(|| {
        while !run.finished() {
            run.step();
            monitor.observe(&run.world, &run.pipeline);
        }
    });
    print(&monitor.report(), None);
    Ok(ExitCode::SUCCESS)
}
