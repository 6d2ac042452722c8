//! `shoal diff RUN_A RUN_B`: where two runs of the same scenario diverge — the first tick, which
//! agents, which decisions differed, and which input files changed.

use shoal::record::schema::{TrajColumn, TRAJECTORY_COLUMNS};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `shoal diff`.
#[derive(clap::Args, Debug, Default)]
pub struct DiffArgs {
    /// First run folder.
    pub a: PathBuf,
    /// Second run folder.
    pub b: PathBuf,
    /// Most agents and decisions to list.
    #[arg(long, default_value_t = 10)]
    pub limit: usize,
}

/// Rows of one recorded tick: id → the row's fields after `tick,time,id`.
type Tick = BTreeMap<u32, Vec<String>>;

fn read_ticks(path: &Path) -> anyhow::Result<Vec<(u64, Tick)>> {
    let mut reader =
        csv::Reader::from_path(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let mut out: Vec<(u64, Tick)> = Vec::new();
    for record in reader.records() {
        let r = record.map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let line = r.position().map_or(0, |p| p.line());
        let field = |c: TrajColumn| r.get(c as usize).unwrap_or("");
        let t: u64 = field(TrajColumn::Tick)
            .parse()
            .map_err(|_| anyhow::anyhow!("{}:{line}: bad tick", path.display()))?;
        let id: u32 = field(TrajColumn::Id)
            .parse()
            .map_err(|_| anyhow::anyhow!("{}:{line}: bad id", path.display()))?;
        if out.last().is_none_or(|(lt, _)| *lt != t) {
            out.push((t, Tick::new()));
        }
        out.last_mut().expect("pushed").1.insert(
            id,
            r.iter()
                .skip(TrajColumn::Species as usize)
                .map(str::to_string)
                .collect(),
        );
    }
    Ok(out)
}

/// Transitions by tick: (agent, "from → to (cause: condition)").
fn read_decisions(path: &Path) -> anyhow::Result<BTreeMap<u64, Vec<(u64, String)>>> {
    let text =
        std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let mut out: BTreeMap<u64, Vec<(u64, String)>> = BTreeMap::new();
    for line in text.lines() {
        let v: serde_json::Value = serde_json::from_str(line)?;
        if v["kind"] == "transition" {
            let d = format!(
                "{} -> {} ({}{})",
                v["from"].as_str().unwrap_or("?"),
                v["to"].as_str().unwrap_or("?"),
                v["cause"].as_str().unwrap_or("?"),
                v["condition"]
                    .as_str()
                    .map(|c| format!(": {c}"))
                    .unwrap_or_default()
            );
            out.entry(v["tick"].as_u64().unwrap_or(0))
                .or_default()
                .push((v["agent"].as_u64().unwrap_or(0), d));
        }
    }
    Ok(out)
}

/// Names of the fields a [`Tick`] row holds (those after `tick,time,id`).
const FIELDS: &[&str] = TRAJECTORY_COLUMNS.split_at(TrajColumn::Species as usize).1;

/// Runs `shoal diff`.
pub fn diff(args: DiffArgs) -> anyhow::Result<ExitCode> {
    let manifest = |d: &Path| -> serde_json::Value {
        std::fs::read(d.join("manifest.json"))
            .ok()
            .and_then(|b| serde_json::from_slice(&b).ok())
            .unwrap_or_default()
    };
    let (ma, mb) = (manifest(&args.a), manifest(&args.b));
    // An interrupted run is compared as far as it got, and said to be incomplete up front.
    let mut stops: Vec<(&str, u64)> = Vec::new();
    for (name, dir, m) in [("A", &args.a, &ma), ("B", &args.b, &mb)] {
        if let Some(why) = super::run::incomplete(dir, m) {
            println!(
                "note: {name} ({}) is an incomplete run: {why}; compared as far as it got",
                dir.display()
            );
            stops.push((name, m["ticks"].as_u64().unwrap_or(0)));
        }
    }
    let horizon = stops.iter().map(|s| s.1).min();
    if ma["scenario"] != mb["scenario"] {
        println!(
            "note: different scenarios ({} vs {})",
            ma["scenario"], mb["scenario"]
        );
    }
    for key in ["seed", "dt", "record_interval"] {
        if ma[key] != mb[key] {
            println!("note: {key} differs: {} vs {}", ma[key], mb[key]);
        }
    }
    // Which inputs changed.
    if let (Some(fa), Some(fb)) = (ma["files"].as_object(), mb["files"].as_object()) {
        for (k, h) in fa {
            match fb.get(k) {
                Some(h2) if h2 == h => {}
                Some(_) => println!("input changed: {k}"),
                None => println!("input only in A: {k}"),
            }
        }
        for k in fb.keys().filter(|k| !fa.contains_key(*k)) {
            println!("input only in B: {k}");
        }
    }
    let ta = read_ticks(&args.a.join("trajectories.csv"))?;
    let tb = read_ticks(&args.b.join("trajectories.csv"))?;
    let mut diverged = false;
    for ((t, ra), (t2, rb)) in ta.iter().zip(tb.iter()) {
        if t != t2 {
            println!("recorded ticks differ: {t} vs {t2} (different record intervals?)");
            diverged = true;
            break;
        }
        if ra == rb {
            continue;
        }
        diverged = true;
        let ids: Vec<u32> = ra
            .keys()
            .chain(rb.keys())
            .copied()
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        let differing: Vec<u32> = ids
            .into_iter()
            .filter(|id| ra.get(id) != rb.get(id))
            .collect();
        println!(
            "first divergence at tick {t}: {} agent(s) differ",
            differing.len()
        );
        for id in differing.iter().take(args.limit) {
            match (ra.get(id), rb.get(id)) {
                (Some(a), Some(b)) => {
                    let fields: Vec<String> = FIELDS
                        .iter()
                        .zip(a.iter().zip(b.iter()))
                        .filter(|(_, (x, y))| x != y)
                        .map(|(name, (x, y))| format!("{name} {x} vs {y}"))
                        .collect();
                    println!("  agent {id}: {}", fields.join(", "));
                }
                (Some(_), None) => println!("  agent {id}: only in A (dead or not spawned in B)"),
                (None, Some(_)) => println!("  agent {id}: only in B"),
                _ => {}
            }
        }
        break;
    }
    if !diverged && ta.len() != tb.len() {
        let shorter = if ta.len() < tb.len() { "A" } else { "B" };
        match stops.iter().find(|s| s.0 == shorter) {
            Some((name, t)) => println!(
                "no divergence in the {} recorded ticks both runs have; {name} is incomplete (stopped at tick {t}), so nothing after that is compared",
                ta.len().min(tb.len())
            ),
            None => println!(
                "one run is longer: {} vs {} recorded ticks",
                ta.len(),
                tb.len()
            ),
        }
        diverged = true;
    }
    let da = read_decisions(&args.a.join("events.jsonl"))?;
    let db = read_decisions(&args.b.join("events.jsonl"))?;
    // Decisions after an incomplete run stopped are not a difference.
    let ticks: std::collections::BTreeSet<u64> = da
        .keys()
        .chain(db.keys())
        .copied()
        .filter(|t| horizon.is_none_or(|h| *t < h))
        .collect();
    for t in ticks {
        let (a, b) = (da.get(&t), db.get(&t));
        if a == b {
            continue;
        }
        diverged = true;
        println!("first differing decisions at tick {t}:");
        let empty = Vec::new();
        let (a, b) = (a.unwrap_or(&empty), b.unwrap_or(&empty));
        let mut shown = 0;
        for (agent, d) in a.iter().filter(|x| !b.contains(x)) {
            if shown < args.limit {
                println!("  A: agent {agent}: {d}");
            }
            shown += 1;
        }
        for (agent, d) in b.iter().filter(|x| !a.contains(x)) {
            if shown < args.limit {
                println!("  B: agent {agent}: {d}");
            }
            shown += 1;
        }
        break;
    }
    if diverged {
        Ok(ExitCode::from(1))
    } else {
        println!("runs are identical ({} recorded ticks)", ta.len());
        Ok(ExitCode::SUCCESS)
    }
}
