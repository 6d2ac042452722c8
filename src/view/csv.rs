//! `trajectories.csv` and `food.csv` of a run folder, read into columns with the `csv` crate and
//! the recorder's own schema ([`crate::record::schema`]).
//!
//! Trajectories are read in two passes: a cheap scan that counts rows per tick (so the payload
//! can choose a frame stride before anything large is held), then a full parse of the kept ticks
//! only.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use super::ViewError;
use crate::diag::Diagnostic;
use crate::record::schema::{FoodColumn, TrajColumn, FOOD_COLUMNS, TRAJECTORY_COLUMNS};

/// Calls `each(line_number, fields)` for every data record of the CSV file at `path` after
/// checking that its header is exactly `columns`. When `allow_truncated_tail` is set, a last line
/// that lacks its newline (a recorder stopped mid-write) is skipped and its number returned
/// instead of being parsed.
pub(crate) fn for_each_line(
    path: &Path,
    columns: &[&str],
    allow_truncated_tail: bool,
    mut each: impl FnMut(usize, &csv::ByteRecord) -> Result<(), ViewError>,
) -> Result<Option<usize>, ViewError> {
    let mut file = File::open(path).map_err(|e| ViewError::io(path, e))?;
    let len = file.metadata().map_err(|e| ViewError::io(path, e))?.len();
    let mut unterminated = false;
    if len > 0 {
        let mut last = [0u8];
        file.seek(SeekFrom::End(-1))
            .and_then(|_| file.read_exact(&mut last))
            .and_then(|_| file.seek(SeekFrom::Start(0)))
            .map_err(|e| ViewError::io(path, e))?;
        unterminated = last[0] != b'\n';
    }
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .buffer_capacity(1 << 20)
        .from_reader(file);
    let mut record = csv::ByteRecord::new();
    let mut first = true;
    loop {
        let more = reader
            .read_byte_record(&mut record)
            .map_err(|e| csv_error(path, e))?;
        if !more {
            if first {
                return Err(Diagnostic::new(
                    path,
                    1,
                    1,
                    format!("file is empty; expected the header `{}`", columns.join(",")),
                    None,
                )
                .into());
            }
            return Ok(None);
        }
        let line = record.position().map_or(0, |p| p.line() as usize);
        if first {
            first = false;
            if record.iter().ne(columns.iter().map(|c| c.as_bytes())) {
                return Err(located(
                    path,
                    line,
                    1,
                    format!(
                        "unexpected header; expected exactly `{}`",
                        columns.join(",")
                    ),
                    &line_text(&record),
                ));
            }
            continue;
        }
        if allow_truncated_tail && unterminated && reader.position().byte() == len {
            return Ok(Some(line));
        }
        each(line, &record)?;
    }
}

/// A CSV syntax or encoding error, located.
fn csv_error(path: &Path, e: csv::Error) -> ViewError {
    let line = e.position().map_or(0, |p| p.line() as usize);
    match e.into_kind() {
        csv::ErrorKind::Io(e) => ViewError::io(path, e),
        csv::ErrorKind::Utf8 { err, .. } => {
            Diagnostic::new(path, line, 1, format!("not UTF-8 text ({err})"), None).into()
        }
        other => Diagnostic::new(path, line, 1, format!("{other:?}"), None).into(),
    }
}

/// A record as the line it came from (fields joined by commas), for error messages.
fn line_text(r: &csv::ByteRecord) -> String {
    let fields: Vec<_> = r.iter().map(String::from_utf8_lossy).collect();
    fields.join(",")
}

/// Field `i` of `r` as text (`""` when missing); a field that is not UTF-8 is an error.
fn text_of<'r>(
    path: &Path,
    line: usize,
    r: &'r csv::ByteRecord,
    i: usize,
) -> Result<&'r str, ViewError> {
    std::str::from_utf8(r.get(i).unwrap_or(b"")).map_err(|_| {
        located(
            path,
            line,
            1,
            format!("field {} is not UTF-8 text", i + 1),
            &line_text(r),
        )
    })
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

/// The fields of one CSV line; columns for error messages are worked out only when one is due.
pub(crate) struct Fields<'a> {
    path: &'a Path,
    line: usize,
    record: &'a csv::ByteRecord,
    /// The record's fields back to back, checked as UTF-8 once.
    all: &'a str,
}

impl<'a> Fields<'a> {
    /// The fields of `record` (read at `line`), checking it has exactly `names.len()` fields.
    pub(crate) fn split(
        path: &'a Path,
        line: usize,
        record: &'a csv::ByteRecord,
        names: &[&str],
    ) -> Result<Fields<'a>, ViewError> {
        // One UTF-8 check for the whole record; fields are slices of it.
        let all = std::str::from_utf8(record.as_slice())
            .map_err(|_| located(path, line, 1, "not UTF-8 text", &line_text(record)))?;
        if record.len() != names.len() {
            return Err(located(
                path,
                line,
                1,
                format!(
                    "expected {} comma-separated fields ({}), found {}",
                    names.len(),
                    names.join(","),
                    record.len()
                ),
                &line_text(record),
            ));
        }
        Ok(Fields {
            path,
            line,
            record,
            all,
        })
    }

    /// The 1-based column where field `i` starts on its line.
    fn col(&self, i: usize) -> usize {
        1 + (0..i).map(|k| self.str(k).len() + 1).sum::<usize>()
    }

    /// Field `i` as text.
    pub(crate) fn str(&self, i: usize) -> &'a str {
        self.record.range(i).map_or("", |r| &self.all[r])
    }

    /// Field `i` parsed as `T`; `what` names the field and its expected type in the error.
    pub(crate) fn parse<T: std::str::FromStr>(&self, i: usize, what: &str) -> Result<T, ViewError> {
        let s = self.str(i);
        s.trim().parse::<T>().map_err(|_| {
            located(
                self.path,
                self.line,
                self.col(i),
                format!("expected {what}, found `{s}`"),
                &line_text(self.record),
            )
        })
    }

    /// Field `i` as a finite number.
    pub(crate) fn num(&self, i: usize, name: &str) -> Result<f32, ViewError> {
        // The message is formatted only on error: this runs for every number of a replay.
        let Ok(v) = self.str(i).trim().parse::<f32>() else {
            return Err(self.error(
                i,
                format!("expected a number for `{name}`, found `{}`", self.str(i)),
            ));
        };
        if !v.is_finite() {
            let s = self.str(i);
            return Err(located(
                self.path,
                self.line,
                self.col(i),
                format!("expected a finite number for `{name}`, found `{s}`"),
                &line_text(self.record),
            ));
        }
        Ok(v)
    }

    /// A diagnostic at field `i` of this line.
    pub(crate) fn error(&self, i: usize, message: impl Into<String>) -> ViewError {
        located(
            self.path,
            self.line,
            self.col(i),
            message,
            &line_text(self.record),
        )
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
        &TRAJECTORY_COLUMNS,
        allow_truncated_tail,
        |line, record| {
            let field = text_of(path, line, record, TrajColumn::Tick as usize)?;
            let tick: u64 = field.trim().parse().map_err(|_| {
                located(
                    path,
                    line,
                    1,
                    format!("expected a tick (whole number), found `{field}`"),
                    &line_text(record),
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
                        &line_text(record),
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
        &TRAJECTORY_COLUMNS,
        allow_truncated_tail,
        |line, record| {
            let f = Fields::split(path, line, record, &TRAJECTORY_COLUMNS)?;
            let tick: u64 = f.parse(TrajColumn::Tick as usize, "a tick (whole number)")?;
            if !keep.contains(&tick) {
                return Ok(());
            }
            if c.ticks.last() != Some(&tick) {
                c.ticks.push(tick);
                c.times
                    .push(f.parse(TrajColumn::Time as usize, "a time in seconds")?);
                c.offsets.push(c.id.len() as u32);
                last_id = None;
            }
            let id: u32 = f.parse(TrajColumn::Id as usize, "an agent id (whole number)")?;
            if let Some(prev) = last_id {
                if id <= prev {
                    return Err(f.error(
                        TrajColumn::Id as usize,
                        format!("agent id {id} after {prev}: ids must ascend within a tick"),
                    ));
                }
            }
            last_id = Some(id);
            let sp = species.intern(f.str(TrajColumn::Species as usize));
            if sp > usize::from(u8::MAX) {
                return Err(f.error(TrajColumn::Species as usize, "more than 256 species"));
            }
            let be = behaviors.intern(f.str(TrajColumn::Behavior as usize));
            if be > usize::from(u16::MAX) {
                return Err(f.error(
                    TrajColumn::Behavior as usize,
                    "more than 65536 behavior names",
                ));
            }
            c.id.push(id);
            c.species.push(sp as u8);
            for col in [TrajColumn::X, TrajColumn::Y, TrajColumn::Z] {
                c.pos
                    .push(f.num(col as usize, TRAJECTORY_COLUMNS[col as usize])?);
            }
            for col in [TrajColumn::Fx, TrajColumn::Fy, TrajColumn::Fz] {
                c.fwd
                    .push(f.num(col as usize, TRAJECTORY_COLUMNS[col as usize])?);
            }
            c.speed.push(f.num(TrajColumn::Speed as usize, "speed")?);
            c.behavior.push(be as u16);
            let depth: u32 = f.parse(
                TrajColumn::StackDepth as usize,
                "a stack depth (whole number)",
            )?;
            c.stack_depth.push(depth.min(255) as u8);
            c.hunger.push(f.num(TrajColumn::Hunger as usize, "hunger")?);
            c.libido.push(f.num(TrajColumn::Libido as usize, "libido")?);
            c.fear.push(f.num(TrajColumn::Fear as usize, "fear")?);
            c.swim_phase
                .push(f.num(TrajColumn::SwimPhase as usize, "swim_phase")?);
            c.tail_bend
                .push(f.num(TrajColumn::TailBend as usize, "tail_bend")?);
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
    out.truncated_line =
        for_each_line(path, &FOOD_COLUMNS, allow_truncated_tail, |line, record| {
            let f = Fields::split(path, line, record, &FOOD_COLUMNS)?;
            let tick: u64 = f.parse(FoodColumn::Tick as usize, "a tick (whole number)")?;
            if let Some(prev) = last_tick {
                if tick < prev {
                    return Err(f.error(
                        FoodColumn::Tick as usize,
                        format!(
                            "tick {tick} after tick {prev}: rows must be grouped by ascending tick"
                        ),
                    ));
                }
            }
            last_tick = Some(tick);
            let _id: u64 = f.parse(FoodColumn::Id as usize, "a food id (whole number)")?;
            let v = out.by_tick.entry(tick).or_default();
            for col in [FoodColumn::X, FoodColumn::Y, FoodColumn::Z] {
                v.push(f.num(col as usize, FOOD_COLUMNS[col as usize])?);
            }
            Ok(())
        })?;
    Ok(out)
}
