//! The compact columnar payload the page reads: frame tables, typed-array columns (base64) and the
//! name tables, world and decision histories as JSON.
//!
//! Size is bounded: when the encoded frames would not fit the budget, only every `stride`-th recorded
//! frame (and the last) is kept, and the page says so.

use std::collections::{BTreeSet, HashSet};
use std::path::Path;

use serde_json::{json, Value};

use super::csv::{self, NameTable};
use super::events::Events;
use super::manifest::{Manifest, RunStatus};
use super::world::{SpeciesInfo, World};
use super::ViewError;
use base64::Engine as _;

/// Encoded bytes per agent row before base64: id u32, species u8, behavior u16, pos 3×f32,
/// forward 3×f32, speed f32, stack depth u8, three drives u8, swim phase u8, tail bend f32.
pub(crate) const ROW_BYTES: usize = 4 + 1 + 2 + 12 + 12 + 4 + 1 + 3 + 1 + 4;

/// Encoded bytes per history record before base64: seven u32.
const TRANSITION_BYTES: usize = 7 * 4;

/// Fallback colors for species that the world does not describe.
const SPARE_COLORS: [&str; 6] = [
    "#5fb4e0", "#e07a5f", "#81b29a", "#f2cc8f", "#b07ad0", "#d0d0d0",
];

/// Length of the standard (padded) base64 encoding of `n` bytes, which the page decodes with
/// `atob`.
fn encoded_len(n: usize) -> usize {
    base64::encoded_len(n, true).unwrap_or(usize::MAX)
}

/// One binary column: its name, element type (as the page names it) and base64 text.
#[derive(Debug, Clone)]
pub(crate) struct Column {
    pub name: &'static str,
    pub kind: &'static str,
    pub base64: String,
}

/// Everything the page embeds for one run.
#[derive(Debug, Clone)]
pub(crate) struct Payload {
    /// Tables, world and run facts as JSON.
    pub meta: Value,
    /// Typed-array columns.
    pub columns: Vec<Column>,
}

fn column<T: Copy>(
    name: &'static str,
    kind: &'static str,
    values: &[T],
    to_le: impl Fn(T, &mut Vec<u8>),
) -> Column {
    let mut bytes = Vec::with_capacity(std::mem::size_of_val(values));
    for &v in values {
        to_le(v, &mut bytes);
    }
    let mut base64 = String::with_capacity(encoded_len(bytes.len()));
    base64::engine::general_purpose::STANDARD.encode_string(&bytes, &mut base64);
    Column { name, kind, base64 }
}

fn f32s(name: &'static str, v: &[f32]) -> Column {
    column(name, "f32", v, |x, b| b.extend_from_slice(&x.to_le_bytes()))
}

fn u32s(name: &'static str, v: &[u32]) -> Column {
    column(name, "u32", v, |x, b| b.extend_from_slice(&x.to_le_bytes()))
}

fn u16s(name: &'static str, v: &[u16]) -> Column {
    column(name, "u16", v, |x, b| b.extend_from_slice(&x.to_le_bytes()))
}

fn u8s(name: &'static str, v: &[u8]) -> Column {
    column(name, "u8", v, |x, b| b.push(x))
}

/// A unit quantity in [0, 1] as a byte (the page divides by 255).
fn unit_u8(name: &'static str, v: &[f32]) -> Column {
    column(name, "unorm8", v, |x, b| {
        b.push((x.clamp(0.0, 1.0) * 255.0).round() as u8)
    })
}

/// The smallest stride whose kept frames (every `stride`-th and the last) fit `budget` encoded bytes.
pub(crate) fn choose_stride(frame_bytes: &[usize], budget: usize) -> usize {
    let n = frame_bytes.len();
    if n == 0 {
        return 1;
    }
    let cost = |s: usize| -> usize {
        let mut sum = 0;
        for (i, b) in frame_bytes.iter().enumerate() {
            if i % s == 0 || i == n - 1 {
                sum += b;
            }
        }
        encoded_len(sum)
    };
    let total = encoded_len(frame_bytes.iter().sum());
    let mut s = total.div_ceil(budget.max(1)).max(1);
    while s < n && cost(s) > budget {
        s += 1;
    }
    s.min(n)
}

/// Reads the run folder at `dir` and builds its payload within `budget` encoded bytes of frames.
pub(crate) fn build(dir: &Path, budget: usize) -> Result<Payload, ViewError> {
    let manifest = Manifest::read(&dir.join("manifest.json"))?;
    let world = World::read(&dir.join("world.json"))?;
    let incomplete = manifest.status == RunStatus::Incomplete;
    let traj_path = dir.join("trajectories.csv");
    let counts = csv::scan_trajectories(&traj_path, incomplete)?;
    let food = csv::read_food(&dir.join("food.csv"), incomplete)?;
    let events = Events::read(&dir.join("events.jsonl"), incomplete)?;

    let mut notes: Vec<String> = Vec::new();
    for (file, line) in [
        ("trajectories.csv", counts.truncated_line),
        ("food.csv", food.truncated_line),
        ("events.jsonl", events.truncated_line),
    ] {
        if let Some(line) = line {
            notes.push(format!("{file}: skipped the unfinished last line ({line})"));
        }
    }

    // Frames are the recorded ticks that have agents or food.
    let rows_at: std::collections::HashMap<u64, usize> = counts.ticks.iter().copied().collect();
    let all_ticks: Vec<u64> = counts
        .ticks
        .iter()
        .map(|&(t, _)| t)
        .chain(food.by_tick.keys().copied())
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect();
    let frame_bytes: Vec<usize> = all_ticks
        .iter()
        .map(|t| {
            rows_at.get(t).copied().unwrap_or(0) * ROW_BYTES
                + food.by_tick.get(t).map_or(0, |v| v.len() * 4)
        })
        .collect();
    let history_bytes = encoded_len(events.transitions.len() * TRANSITION_BYTES);
    let stride = choose_stride(
        &frame_bytes,
        budget.saturating_sub(history_bytes).max(budget / 4),
    );
    let last = all_ticks.len().saturating_sub(1);
    let kept: Vec<u64> = all_ticks
        .iter()
        .enumerate()
        .filter(|&(i, _)| i % stride == 0 || i == last)
        .map(|(_, &t)| t)
        .collect();
    if stride > 1 {
        notes.push(format!(
            "showing every {stride}th of {} recorded frames to keep this page small",
            all_ticks.len()
        ));
    }

    let mut species = NameTable::default();
    let mut behaviors = NameTable::default();
    for s in &world.species {
        species.intern(&s.name);
        for b in &s.behaviors {
            behaviors.intern(b);
        }
    }
    let keep: HashSet<u64> = kept.iter().copied().collect();
    let agents =
        csv::read_trajectories(&traj_path, incomplete, &keep, &mut species, &mut behaviors)?;

    let mut species_info: Vec<SpeciesInfo> = world.species.clone();
    for (i, name) in species.names.iter().enumerate().skip(world.species.len()) {
        species_info.push(SpeciesInfo {
            name: name.clone(),
            color: SPARE_COLORS[i % SPARE_COLORS.len()].to_string(),
            length: 1.0,
            behaviors: Vec::new(),
            look: None,
            behavior_info: Vec::new(),
        });
    }

    // Merge agent frames and food-only frames into one frame table.
    let mut tick_col = Vec::with_capacity(kept.len());
    let mut time_col = Vec::with_capacity(kept.len());
    let mut offset_col = Vec::with_capacity(kept.len() + 1);
    let mut food_offset_col = Vec::with_capacity(kept.len() + 1);
    let mut food_pos: Vec<f32> = Vec::new();
    let mut a = 0usize;
    for &t in &kept {
        tick_col.push(t);
        if agents.ticks.get(a) == Some(&t) {
            time_col.push(agents.times[a]);
            offset_col.push(agents.offsets[a]);
            a += 1;
        } else {
            time_col.push(t as f64 * manifest.dt);
            offset_col.push(agents.offsets[a]);
        }
        food_offset_col.push((food_pos.len() / 3) as u32);
        if let Some(v) = food.by_tick.get(&t) {
            food_pos.extend_from_slice(v);
        }
    }
    offset_col.push(agents.rows() as u32);
    food_offset_col.push((food_pos.len() / 3) as u32);

    let tr = &events.transitions;
    let columns = vec![
        u32s("id", &agents.id),
        u8s("species", &agents.species),
        u16s("behavior", &agents.behavior),
        f32s("pos", &agents.pos),
        f32s("fwd", &agents.fwd),
        f32s("speed", &agents.speed),
        u8s("stack_depth", &agents.stack_depth),
        unit_u8("hunger", &agents.hunger),
        unit_u8("libido", &agents.libido),
        unit_u8("fear", &agents.fear),
        unit_u8("swim_phase", &agents.swim_phase),
        f32s("tail_bend", &agents.tail_bend),
        f32s("food", &food_pos),
        u32s("h_agent", &tr.iter().map(|t| t.agent).collect::<Vec<_>>()),
        u32s("h_tick", &tr.iter().map(|t| t.tick).collect::<Vec<_>>()),
        u32s("h_from", &tr.iter().map(|t| t.from).collect::<Vec<_>>()),
        u32s("h_to", &tr.iter().map(|t| t.to).collect::<Vec<_>>()),
        u32s("h_cause", &tr.iter().map(|t| t.cause).collect::<Vec<_>>()),
        u32s(
            "h_cond",
            &tr.iter().map(|t| t.condition).collect::<Vec<_>>(),
        ),
        u32s("h_stack", &tr.iter().map(|t| t.stack).collect::<Vec<_>>()),
    ];

    let deaths: serde_json::Map<String, Value> = events
        .deaths
        .iter()
        .map(|(id, (tick, cause))| (id.to_string(), json!([tick, cause])))
        .collect();
    let health = super::health::section(dir, &mut notes);
    let meta = json!({
        "format": super::manifest::FORMAT,
        "run": manifest,
        "incomplete": incomplete,
        "notes": notes,
        "stride": stride,
        "recorded_frames": all_ticks.len(),
        "world": world,
        "species": species_info,
        "behaviors": behaviors.names,
        "frames": {
            "count": kept.len(),
            "tick": tick_col,
            "time": time_col,
            "offset": offset_col,
            "food_offset": food_offset_col,
        },
        "rows": agents.rows(),
        "history": { "count": tr.len(), "strings": events.strings.names },
        "deaths": deaths,
        "script_errors": events.script_errors,
        "named_events": events.named,
        "reloads": events.reloads,
        "event_counts": events.counts,
        "transition_counts": events.edge_list(),
        "health": health,
    });
    Ok(Payload { meta, columns })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stride_is_one_when_everything_fits() {
        assert_eq!(choose_stride(&[100; 10], 10_000), 1);
    }

    #[test]
    fn stride_grows_until_kept_frames_fit() {
        let frames = [300usize; 100];
        let s = choose_stride(&frames, 4000);
        let kept = (0..100).filter(|i| i % s == 0 || *i == 99).count();
        assert!(encoded_len(kept * 300) <= 4000, "stride {s}");
        let s1 = s - 1;
        let kept1 = (0..100).filter(|i| i % s1 == 0 || *i == 99).count();
        assert!(encoded_len(kept1 * 300) > 4000);
    }

    #[test]
    fn stride_never_exceeds_frame_count() {
        assert_eq!(choose_stride(&[1_000_000; 3], 10), 3);
        assert_eq!(choose_stride(&[], 10), 1);
    }
}
