//! Typed columns built in Rust and handed to Python as raw buffers in Arrow's memory layout
//! (values, 32-bit offsets, validity bits, in native byte order), so that `shoal/_tables.py`
//! wraps them into `pyarrow` arrays without one Python object per value.

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyList, PyTuple};

/// The Arrow type of a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `bool` (bit-packed).
    Bool,
    /// `int64`.
    I64,
    /// `uint8`.
    U8,
    /// `uint32`.
    U32,
    /// `uint64`.
    U64,
    /// `float32`.
    F32,
    /// `float64`.
    F64,
    /// `string` (32-bit offsets).
    Str,
    /// `dictionary<int32, string>`: a category per row.
    Dict,
    /// `list<string>`.
    ListStr,
}

impl Kind {
    /// The name `_tables.py` maps to a pyarrow type.
    fn name(self) -> &'static str {
        match self {
            Kind::Bool => "bool",
            Kind::I64 => "i64",
            Kind::U8 => "u8",
            Kind::U32 => "u32",
            Kind::U64 => "u64",
            Kind::F32 => "f32",
            Kind::F64 => "f64",
            Kind::Str => "str",
            Kind::Dict => "dict",
            Kind::ListStr => "list_str",
        }
    }
}

/// One column under construction.
#[derive(Debug, Clone)]
pub struct Column {
    /// Its name in the table.
    pub name: String,
    kind: Kind,
    /// Values (numbers), string bytes (`Str`), `int32` indices (`Dict`), or the strings' bytes
    /// of a list's items (`ListStr`).
    data: Vec<u8>,
    /// `int32` offsets: into `data` (`Str`), into the items (`ListStr`).
    offsets: Vec<u8>,
    /// `int32` offsets of a list's items into `data` (`ListStr`).
    item_offsets: Vec<u8>,
    items: usize,
    /// Validity bits, one per row, kept only once a row is null.
    valid: Option<Vec<u8>>,
    nulls: usize,
    len: usize,
    /// The categories of a `Dict` column.
    pub dictionary: Vec<String>,
}

fn push_bit(bits: &mut Vec<u8>, row: usize, on: bool) {
    if row / 8 >= bits.len() {
        bits.push(0);
    }
    if on {
        bits[row / 8] |= 1 << (row % 8);
    }
}

fn offset(n: usize) -> [u8; 4] {
    // Arrow's `string` holds 2 GiB per column; a run large enough to pass it needs a
    // `record_interval`.
    i32::try_from(n)
        .expect("a column's text exceeds 2 GiB: record less often (record_interval)")
        .to_ne_bytes()
}

impl Column {
    /// An empty column of `kind`.
    pub fn new(name: &str, kind: Kind) -> Column {
        Column::named(name.to_string(), kind)
    }

    /// [`Column::new`], with a name of its own.
    pub fn named(name: String, kind: Kind) -> Column {
        let mut c = Column {
            name,
            kind,
            data: Vec::new(),
            offsets: Vec::new(),
            item_offsets: Vec::new(),
            items: 0,
            valid: None,
            nulls: 0,
            len: 0,
            dictionary: Vec::new(),
        };
        if matches!(kind, Kind::Str | Kind::ListStr) {
            c.offsets.extend(offset(0));
        }
        if kind == Kind::ListStr {
            c.item_offsets.extend(offset(0));
        }
        c
    }

    /// Room for `rows` more rows of `width` bytes each.
    pub fn reserve(&mut self, rows: usize, width: usize) {
        self.data.reserve(rows * width);
    }

    fn row(&mut self, valid: bool) {
        if !valid && self.valid.is_none() {
            let mut bits = Vec::with_capacity(self.len / 8 + 1);
            for r in 0..self.len {
                push_bit(&mut bits, r, true);
            }
            self.valid = Some(bits);
        }
        if let Some(bits) = self.valid.as_mut() {
            push_bit(bits, self.len, valid);
        }
        if !valid {
            self.nulls += 1;
        }
        self.len += 1;
    }

    /// Appends a number's bytes (the column's kind says its width).
    pub fn bytes(&mut self, b: &[u8]) {
        self.data.extend_from_slice(b);
        self.row(true);
    }

    /// Appends a `bool` (one bit).
    pub fn bool(&mut self, v: bool) {
        push_bit(&mut self.data, self.len, v);
        self.row(true);
    }
    /// Appends an `i64`.
    pub fn i64(&mut self, v: i64) {
        self.bytes(&v.to_ne_bytes());
    }
    /// Appends a `u8`.
    pub fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }
    /// Appends a `u32`.
    pub fn u32(&mut self, v: u32) {
        self.bytes(&v.to_ne_bytes());
    }
    /// Appends a `u64`.
    pub fn u64(&mut self, v: u64) {
        self.bytes(&v.to_ne_bytes());
    }
    /// Appends an `f32`.
    pub fn f32(&mut self, v: f32) {
        self.bytes(&v.to_ne_bytes());
    }
    /// Appends an `f64`.
    pub fn f64(&mut self, v: f64) {
        self.bytes(&v.to_ne_bytes());
    }
    /// Appends a category (an index into [`Column::dictionary`]).
    pub fn category(&mut self, i: i32) {
        self.bytes(&i.to_ne_bytes());
    }

    /// Appends a string.
    pub fn str(&mut self, s: &str) {
        self.data.extend_from_slice(s.as_bytes());
        self.offsets.extend(offset(self.data.len()));
        self.row(true);
    }

    /// Appends a list of strings.
    pub fn list<'a>(&mut self, items: impl IntoIterator<Item = &'a str>) {
        for s in items {
            self.data.extend_from_slice(s.as_bytes());
            self.item_offsets.extend(offset(self.data.len()));
            self.items += 1;
        }
        self.offsets.extend(offset(self.items));
        self.row(true);
    }

    /// Appends a null (zeroed value bytes of `width`, or an empty string or list).
    pub fn null(&mut self) {
        match self.kind {
            Kind::Str => self.offsets.extend(offset(self.data.len())),
            Kind::ListStr => self.offsets.extend(offset(self.items)),
            Kind::Bool => push_bit(&mut self.data, self.len, false),
            k => {
                let width = match k {
                    Kind::U8 => 1,
                    Kind::U32 | Kind::F32 | Kind::Dict => 4,
                    _ => 8,
                };
                self.data.extend(std::iter::repeat_n(0, width));
            }
        }
        self.row(false);
    }

    /// The column as the tuple `_tables.py` reads: `(name, kind, length, null_count, buffers,
    /// extra)`, where `buffers` is Arrow's buffer list (validity first, `None` when no row is
    /// null) and `extra` the dictionary of a `dict` column or `(items, [None, offsets, data])` of
    /// a `list_str` column's items.
    pub fn into_py<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let bytes = |b: &[u8]| PyBytes::new(py, b).into_any();
        let valid = match &self.valid {
            Some(v) => bytes(v),
            None => py.None().into_bound(py),
        };
        let mut buffers = vec![valid];
        let extra = match self.kind {
            Kind::Str => {
                buffers.push(bytes(&self.offsets));
                buffers.push(bytes(&self.data));
                py.None().into_bound(py)
            }
            Kind::ListStr => {
                buffers.push(bytes(&self.offsets));
                let child = PyList::new(
                    py,
                    [
                        py.None().into_bound(py),
                        bytes(&self.item_offsets),
                        bytes(&self.data),
                    ],
                )?;
                PyTuple::new(
                    py,
                    [self.items.into_pyobject(py)?.into_any(), child.into_any()],
                )?
                .into_any()
            }
            Kind::Dict => {
                buffers.push(bytes(&self.data));
                PyList::new(py, &self.dictionary)?.into_any()
            }
            _ => {
                buffers.push(bytes(&self.data));
                py.None().into_bound(py)
            }
        };
        PyTuple::new(
            py,
            [
                self.name.as_str().into_pyobject(py)?.into_any(),
                self.kind.name().into_pyobject(py)?.into_any(),
                self.len.into_pyobject(py)?.into_any(),
                self.nulls.into_pyobject(py)?.into_any(),
                PyList::new(py, buffers)?.into_any(),
                extra,
            ],
        )
    }
}

/// Columns as a list of [`Column::into_py`] tuples.
pub fn into_py<'py>(py: Python<'py>, columns: Vec<Column>) -> PyResult<Bound<'py, PyList>> {
    let tuples = columns
        .into_iter()
        .map(|c| c.into_py(py))
        .collect::<PyResult<Vec<_>>>()?;
    PyList::new(py, tuples)
}
