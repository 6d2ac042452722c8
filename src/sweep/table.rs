//! A sweep's results: each finished run's row (`runs/NNNNN/result.json`) and the table that
//! merges them in index order. Columns are named and typed; a column's type is the widest its
//! rows hold (whole numbers, then decimals, then text), and floats are written in Rust's
//! shortest round-trip form, so the table is the same bytes whatever order, sharding or
//! thread count made the rows.

use super::exec::SweepError;
use std::path::Path;

/// One value of a row.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// A whole number.
    Int(i64),
    /// A decimal number.
    Float(f64),
    /// Yes or no.
    Bool(bool),
    /// Text.
    Text(String),
}

impl Cell {
    /// The value as CSV text (floats round-trip; booleans `true`/`false`).
    pub fn to_text(&self) -> String {
        match self {
            Cell::Int(i) => i.to_string(),
            Cell::Float(x) if x.is_finite() => format!("{x:?}"),
            Cell::Float(x) if x.is_nan() => "NaN".to_string(),
            Cell::Float(x) => if *x > 0.0 { "inf" } else { "-inf" }.to_string(),
            Cell::Bool(b) => b.to_string(),
            Cell::Text(t) => t.clone(),
        }
    }

    fn to_json(&self) -> serde_json::Value {
        match self {
            Cell::Int(i) => serde_json::json!(["int", i]),
            Cell::Float(x) => serde_json::json!(["float", self.to_text(), x.is_finite()]),
            Cell::Bool(b) => serde_json::json!(["bool", b]),
            Cell::Text(t) => serde_json::json!(["text", t]),
        }
    }

    fn from_json(v: &serde_json::Value) -> Option<Cell> {
        let a = v.as_array()?;
        Some(match a.first()?.as_str()? {
            "int" => Cell::Int(a.get(1)?.as_i64()?),
            "float" => Cell::Float(a.get(1)?.as_str()?.parse().ok()?),
            "bool" => Cell::Bool(a.get(1)?.as_bool()?),
            "text" => Cell::Text(a.get(1)?.as_str()?.to_string()),
            _ => return None,
        })
    }
}

/// The type of a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum ColumnType {
    /// Booleans.
    Bool,
    /// Whole numbers.
    Int,
    /// Decimal numbers (whole numbers are widened).
    Float,
    /// Text (anything is written as text).
    Text,
}

fn type_of(c: &Cell) -> ColumnType {
    match c {
        Cell::Bool(_) => ColumnType::Bool,
        Cell::Int(_) => ColumnType::Int,
        Cell::Float(_) => ColumnType::Float,
        Cell::Text(_) => ColumnType::Text,
    }
}

/// One run's row, in column order.
pub type Row = Vec<(String, Cell)>;

/// Writes a row as JSON text (what `runs/NNNNN/result.json` holds).
pub fn row_json(row: &Row) -> String {
    let cols: Vec<serde_json::Value> = row
        .iter()
        .map(|(n, c)| serde_json::json!([n, c.to_json()]))
        .collect();
    serde_json::to_string_pretty(&serde_json::json!({ "format": 1, "columns": cols }))
        .expect("JSON of plain values")
}

/// Reads a row written by [`row_json`].
pub fn read_row(path: &Path) -> Result<Row, SweepError> {
    let bad = || SweepError(format!("{}: not a sweep run's result", path.display()));
    let text = std::fs::read_to_string(path)
        .map_err(|e| SweepError(format!("cannot read {}: {e}", path.display())))?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|_| bad())?;
    let cols = v["columns"].as_array().ok_or_else(bad)?;
    cols.iter()
        .map(|c| {
            let name = c.get(0).and_then(|n| n.as_str()).ok_or_else(bad)?;
            let cell = c.get(1).and_then(Cell::from_json).ok_or_else(bad)?;
            Ok((name.to_string(), cell))
        })
        .collect()
}

/// Named, typed columns over the runs of a sweep, in index order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    /// Column names, in order of first appearance.
    pub names: Vec<String>,
    /// Each column's type.
    pub types: Vec<ColumnType>,
    /// The rows: one value per column (`None` where a run has no such column).
    pub rows: Vec<Vec<Option<Cell>>>,
    /// Indices of runs not finished (collected with [`collect_partial`]).
    pub missing: Vec<usize>,
}

impl Table {
    fn push(&mut self, row: Row) {
        let mut out = vec![None; self.names.len()];
        for (name, cell) in row {
            let i = match self.names.iter().position(|n| *n == name) {
                Some(i) => i,
                None => {
                    self.names.push(name);
                    self.types.push(type_of(&cell));
                    out.push(None);
                    self.names.len() - 1
                }
            };
            let t = type_of(&cell);
            self.types[i] = match (self.types[i], t) {
                (a, b) if a == b => a,
                (ColumnType::Int, ColumnType::Float) | (ColumnType::Float, ColumnType::Int) => {
                    ColumnType::Float
                }
                _ => ColumnType::Text,
            };
            out[i] = Some(cell);
        }
        self.rows.push(out);
    }

    /// The value of `column` in row `row`, widened to the column's type.
    pub fn get(&self, row: usize, column: usize) -> Option<Cell> {
        let c = self.rows.get(row)?.get(column)?.clone()?;
        Some(match (self.types[column], c) {
            (ColumnType::Float, Cell::Int(i)) => Cell::Float(i as f64),
            (ColumnType::Text, c) => Cell::Text(c.to_text()),
            (_, c) => c,
        })
    }

    /// Writes the table as CSV: a header of column names, then one line per run (empty where a
    /// run has no value).
    pub fn write_csv(&self, p: &Path) -> std::io::Result<()> {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(&self.names).map_err(std::io::Error::other)?;
        for r in 0..self.rows.len() {
            let line: Vec<String> = (0..self.names.len())
                .map(|c| self.get(r, c).map(|v| v.to_text()).unwrap_or_default())
                .collect();
            w.write_record(&line).map_err(std::io::Error::other)?;
        }
        let bytes = w
            .into_inner()
            .map_err(|e| std::io::Error::other(e.to_string()))?;
        crate::record::write_atomic(p, &bytes)
    }
}

/// Merges the finished runs of the sweep output folder `out` into one table, in index order;
/// fails naming the runs not finished.
pub fn collect(out: &Path) -> Result<Table, SweepError> {
    let t = collect_partial(out)?;
    if t.missing.is_empty() {
        Ok(t)
    } else {
        Err(SweepError(format!(
            "{} of {} run(s) not finished: {} (run them, or collect with --partial)",
            t.missing.len(),
            t.missing.len() + t.rows.len(),
            super::exec::ranges(&t.missing)
        )))
    }
}

/// [`collect`], leaving out the runs not finished (listed in [`Table::missing`]).
pub fn collect_partial(out: &Path) -> Result<Table, SweepError> {
    let m = super::exec::read_manifest(out)?;
    let runs = m["runs"].as_u64().ok_or_else(|| {
        SweepError(format!(
            "{}: the manifest does not say how many runs",
            out.display()
        ))
    })? as usize;
    let mut t = Table::default();
    for i in 0..runs {
        let f = super::exec::run_dir(out, i).join("result.json");
        if f.is_file() {
            t.push(read_row(&f)?);
        } else {
            t.missing.push(i);
        }
    }
    Ok(t)
}
