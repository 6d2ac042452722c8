//! `trajectories.csv` and `food.csv` of a run folder, read into columns.
//!
//! Fields never hold quotes or commas, so a line is split on `,` and nothing more. Trajectories are
//! read in two passes: a cheap scan that counts rows per tick (so the payload can choose a frame
//! stride before anything large is held), then a full parse of the kept ticks only.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

use super::ViewError;
use crate::diag::Diagnostic;

/// The exact header of `trajectories.csv`.
pub(crate) const TRAJECTORIES_HEADER: &str = "tick,time,id,species,x,y,z,fx,fy,fz,speed,behavior,stack_depth,hunger,libido,fear,swim_phase,tail_bend";

/// The exact header of `food.csv`.
pub(crate) const FOOD_HEADER: &str = "tick,id,x,y,z";

/// Calls `each(line_number, line)` for every non-empty data line of the CSV file at `path` after
/// checking its header. When `allow_truncated_tail` is set, a last line that lacks its newline (a
/// recorder stopped mid-write) is skipped and its number returned instead of being parsed.
pub(crate) fn for_each_line(
    path: &Path,
    header: &str,
    allow_truncated_tail: bool,
    mut each: impl FnMut(usize, &str) -> Result<(), ViewError>,
) -> Result<Option<usize>, ViewError> {
    let file = File::open(path).map_err(|e| ViewError::io(path, e))?;
    let mut reader = BufReader::with_capacity(1 << 20, file);
    let mut line = String::new();
    let mut number = 0usize;
    loop {
        line.clear();
        let n = reader
            .read_line(&mut line)
            .map_err(|e| ViewError::io(path, e))?;
        if n == 0 {
            if number == 0 {
                return Err(Diagnostic::new(
                    path,
                    1,
                    1,
                    format!("file is empty; expected the header `{header}`"),
                    None,
                )
                .into());
            }
            return Ok(None);
        }
        number += 1;
        let complete = line.ends_with('\n');
        let text = line.trim_end_matches(['\n', '\r']);
        if number == 1 {
            if text != header {
                return Err(located(
                    path,
                    1,
                    1,
                    format!("unexpected header; expected exactly `{header}`"),
                    text,
                ));
            }
            continue;
        }
        if !complete && allow_truncated_tail {
            return Ok(Some(number));
        }
        if text.is_empty() {
            continue;
        }
        each(number, text)?;
    }
}

/// A diagnostic at `line:col` of `path` showing `text` as the offending line.
pub(crate) fn located(
    path: &Path,
    line: usize,
    col: usize,
    message: impl Into<String>,
    text: &str,
) -> ViewError {
    let mut d = Diagnostic::new(path, line, col, message, None);
    d.source_line = Some(text.to_string());
    d.into()
}

/// The fields of one CSV line, with their 1-based columns for error messages.
pub(crate) struct Fields<'a> {
    path: &'a Path,
    line: usize,
    text: &'a str,
    fields: Vec<(usize, &'a str)>,
}

impl<'a> Fields<'a> {
    /// Splits `text` and checks it has exactly `names.len()` fields.
    pub(crate) fn split(
        path: &'a Path,
        line: usize,
        text: &'a str,
        names: &[&str],
    ) -> Result<Fields<'a>, ViewError> {
        let mut fields = Vec::with_capacity(names.len());
        let mut start = 0;
        for part in text.split(',') {
            fields.push((start + 1, part));
            start += part.len() + 1;
        }
        if fields.len() != names.len() {
            return Err(located(
                path,
                line,
                1,
                format!(
                    "expected {} comma-separated fields ({}), found {}",
                    names.len(),
                    names.join(","),
                    fields.len()
                ),
                text,
            ));
        }
        Ok(Fields {
            path,
            line,
            text,
            fields,
        })
    }

    /// Field `i` as text.
    pub(crate) fn str(&self, i: usize) -> &'a str {
        self.fields[i].1
    }

    /// Field `i` parsed as `T`; `what` names the field and its expected type in the error.
    pub(crate) fn parse<T: std::str::FromStr>(&self, i: usize, what: &str) -> Result<T, ViewError> {
        let (col, s) = self.fields[i];
        s.trim().parse::<T>().map_err(|_| {
            located(
                self.path,
                self.line,
                col,
                format!("expected {what}, found `{s}`"),
                self.text,
            )
        })
    }

    /// Field `i` as a finite number.
    pub(crate) fn num(&self, i: usize, name: &str) -> Result<f32, ViewError> {
        let v: f32 = self.parse(i, &format!("a number for `{name}`"))?;
        if !v.is_finite() {
            let (col, s) = self.fields[i];
            return Err(located(
                self.path,
                self.line,
                col,
                format!("expected a finite number for `{name}`, found `{s}`"),
                self.text,
            ));
        }
        Ok(v)
    }

    /// A diagnostic at field `i` of this line.
    pub(crate) fn error(&self, i: usize, message: impl Into<String>) -> ViewError {
        located(self.path, self.line, self.fields[i].0, message, self.text)
    }
}

/// How many agent rows each recorded tick has, from the scan pass.
#[derive(Debug, Clone, Default)]
pub(crate) struct TickCounts {
    /// `(tick, rows)` in ascending tick order.
    pub ticks: Vec<(u64, usize)>,
    /// Line number of a truncated last line that was skipped, if any.
    pub truncated_line: Option<usize>,
}

/// Scan pass over `trajectories.csv`: rows per tick, checking ticks only ascend.
pub(crate) fn scan_trajectories(
    path: &Path,
    allow_truncated_tail: bool,
) -> Result<TickCounts, ViewError> {
    let mut counts: Vec<(u64, usize)> = Vec::new();
    let truncated_line = for_each_line(
        path,
        TRAJECTORIES_HEADER,
        allow_truncated_tail,
        |line, text| {
            let field = text.split(',').next().unwrap_or("");
            let tick: u64 = field.trim().parse().map_err(|_| {
                located(
                    path,
                    line,
                    1,
                    format!("expected a tick (whole number), found `{field}`"),
                    text,
                )
            })?;
            match counts.last_mut() {
                Some((t, n)) if *t == tick => *n += 1,
                Some((t, _)) if *t > tick => {
                    return Err(located(
                        path,
                        line,
                        1,
                        format!(
                            "tick {tick} after tick {t}: rows must be grouped by ascending tick"
                        ),
                        text,
                    ))
                }
                _ => counts.push((tick, 1)),
            }
            Ok(())
        },
    )?;
    Ok(TickCounts {
        ticks: counts,
        truncated_line,
    })
}

/// Interns names to small indices, keeping first-seen order.
#[derive(Debug, Clone, Default)]
pub(crate) struct NameTable {
    /// Names by index.
    pub names: Vec<String>,
    index: HashMap<String, usize>,
}

impl NameTable {
    /// Index of `name`, adding it when new.
    pub(crate) fn intern(&mut self, name: &str) -> usize {
        if let Some(&i) = self.index.get(name) {
            return i;
        }
        let i = self.names.len();
        self.names.push(name.to_string());
        self.index.insert(name.to_string(), i);
        i
    }
}

/// Agent rows of the kept ticks, one column per field, frames back to back.
#[derive(Debug, Clone, Default)]
pub(crate) struct AgentColumns {
    /// Kept ticks in order.
    pub ticks: Vec<u64>,
    /// Simulation time of each kept tick.
    pub times: Vec<f64>,
    /// `offsets[f]..offsets[f + 1]` are the rows of frame `f`.
    pub offsets: Vec<u32>,
    pub id: Vec<u32>,
    pub species: Vec<u8>,
    pub behavior: Vec<u16>,
    pub pos: Vec<f32>,
    pub fwd: Vec<f32>,
    pub speed: Vec<f32>,
    pub stack_depth: Vec<u8>,
    pub hunger: Vec<f32>,
    pub libido: Vec<f32>,
    pub fear: Vec<f32>,
    pub swim_phase: Vec<f32>,
    pub tail_bend: Vec<f32>,
}

impl AgentColumns {
    /// Number of agent rows held.
    pub(crate) fn rows(&self) -> usize {
        self.id.len()
    }
}

const TRAJECTORY_FIELDS: [&str; 18] = [
    "tick",
    "time",
    "id",
    "species",
    "x",
    "y",
    "z",
    "fx",
    "fy",
    "fz",
    "speed",
    "behavior",
    "stack_depth",
    "hunger",
    "libido",
    "fear",
    "swim_phase",
    "tail_bend",
];

/// Parse pass over `trajectories.csv`: the rows of the ticks in `keep`, in order. Species and
/// behavior names are interned into the given tables (which may be pre-filled from the world).
pub(crate) fn read_trajectories(
    path: &Path,
    allow_truncated_tail: bool,
    keep: &HashSet<u64>,
    species: &mut NameTable,
    behaviors: &mut NameTable,
) -> Result<AgentColumns, ViewError> {
    let mut c = AgentColumns::default();
    let mut last_id: Option<u32> = None;
    for_each_line(
        path,
        TRAJECTORIES_HEADER,
        allow_truncated_tail,
        |line, text| {
            let f = Fields::split(path, line, text, &TRAJECTORY_FIELDS)?;
            let tick: u64 = f.parse(0, "a tick (whole number)")?;
            if !keep.contains(&tick) {
                return Ok(());
            }
            if c.ticks.last() != Some(&tick) {
                c.ticks.push(tick);
                c.times.push(f.parse(1, "a time in seconds")?);
                c.offsets.push(c.id.len() as u32);
                last_id = None;
            }
            let id: u32 = f.parse(2, "an agent id (whole number)")?;
            if let Some(prev) = last_id {
                if id <= prev {
                    return Err(f.error(
                        2,
                        format!("agent id {id} after {prev}: ids must ascend within a tick"),
                    ));
                }
            }
            last_id = Some(id);
            let sp = species.intern(f.str(3));
            if sp > usize::from(u8::MAX) {
                return Err(f.error(3, "more than 256 species"));
            }
            let be = behaviors.intern(f.str(11));
            if be > usize::from(u16::MAX) {
                return Err(f.error(11, "more than 65536 behavior names"));
            }
            c.id.push(id);
            c.species.push(sp as u8);
            for (i, name) in [(4, "x"), (5, "y"), (6, "z")] {
                c.pos.push(f.num(i, name)?);
            }
            for (i, name) in [(7, "fx"), (8, "fy"), (9, "fz")] {
                c.fwd.push(f.num(i, name)?);
            }
            c.speed.push(f.num(10, "speed")?);
            c.behavior.push(be as u16);
            let depth: u32 = f.parse(12, "a stack depth (whole number)")?;
            c.stack_depth.push(depth.min(255) as u8);
            c.hunger.push(f.num(13, "hunger")?);
            c.libido.push(f.num(14, "libido")?);
            c.fear.push(f.num(15, "fear")?);
            c.swim_phase.push(f.num(16, "swim_phase")?);
            c.tail_bend.push(f.num(17, "tail_bend")?);
            Ok(())
        },
    )?;
    c.offsets.push(c.id.len() as u32);
    Ok(c)
}

/// Food positions per recorded tick (`x,y,z` flattened), from `food.csv`.
#[derive(Debug, Clone, Default)]
pub(crate) struct FoodFrames {
    /// Tick → flattened positions.
    pub by_tick: BTreeMap<u64, Vec<f32>>,
    /// Line number of a truncated last line that was skipped, if any.
    pub truncated_line: Option<usize>,
}

/// Reads `food.csv`; a missing file means no food was recorded.
pub(crate) fn read_food(path: &Path, allow_truncated_tail: bool) -> Result<FoodFrames, ViewError> {
    let mut out = FoodFrames::default();
    if !path.exists() {
        return Ok(out);
    }
    let mut last_tick: Option<u64> = None;
    out.truncated_line = for_each_line(path, FOOD_HEADER, allow_truncated_tail, |line, text| {
        let f = Fields::split(path, line, text, &["tick", "id", "x", "y", "z"])?;
        let tick: u64 = f.parse(0, "a tick (whole number)")?;
        if let Some(prev) = last_tick {
            if tick < prev {
                return Err(f.error(
                    0,
                    format!(
                        "tick {tick} after tick {prev}: rows must be grouped by ascending tick"
                    ),
                ));
            }
        }
        last_tick = Some(tick);
        let _id: u64 = f.parse(1, "a food id (whole number)")?;
        let v = out.by_tick.entry(tick).or_default();
        for (i, name) in [(2, "x"), (3, "y"), (4, "z")] {
            v.push(f.num(i, name)?);
        }
        Ok(())
    })?;
    Ok(out)
}
