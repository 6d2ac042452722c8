//! Elevation loaders: ESRI ASCII grids (`.asc`) and 16-bit binary PGM height maps, seed 004
//! ("construct the digital elevation database").
//!
//! Not a tick stage: run once when a scenario loads. Every problem in a file becomes a located
//! [`Diagnostic`]; a loader reports all the data errors it finds (up to [`MAX_DIAGNOSTICS`]), not
//! just the first.

use super::{CellAttrs, Terrain};
use crate::diag::{Diagnostic, Diagnostics};
use crate::numbers::MAX_CELLS;
use glam::Vec2;
use std::collections::VecDeque;
use std::path::Path;

pub use crate::load::diag::MAX_DIAGNOSTICS;

const HEADER_KEYS: &str =
    "ncols, nrows, xllcorner, xllcenter, yllcorner, yllcenter, cellsize, NODATA_value";

/// Reads and parses an ESRI ASCII grid file.
pub fn load_asc(path: &Path) -> Result<Terrain, Diagnostics> {
    let text = crate::diag::read_text(path, "terrain file")?;
    parse_asc(&text, path)
}

/// One whitespace-separated token of a line, with its 1-based column.
struct Token<'a> {
    text: &'a str,
    col: usize,
}

fn tokens(line: &str) -> impl Iterator<Item = Token<'_>> {
    let mut col = 0usize;
    let mut start: Option<(usize, usize)> = None;
    let mut out = Vec::new();
    for (byte, ch) in line.char_indices() {
        col += 1;
        if ch.is_whitespace() {
            if let Some((b0, c0)) = start.take() {
                out.push(Token {
                    text: &line[b0..byte],
                    col: c0,
                });
            }
        } else if start.is_none() {
            start = Some((byte, col));
        }
    }
    if let Some((b0, c0)) = start {
        out.push(Token {
            text: &line[b0..],
            col: c0,
        });
    }
    out.into_iter()
}

#[derive(Default)]
struct Header {
    ncols: Option<usize>,
    nrows: Option<usize>,
    /// West edge and whether it was given as a centre.
    x: Option<(f64, bool)>,
    /// South edge and whether it was given as a centre.
    y: Option<(f64, bool)>,
    cellsize: Option<f64>,
    nodata: Option<f64>,
    /// Line and column of the last `ncols` or `nrows` value, where a grid too large is reported.
    size_at: (usize, usize),
}

/// Parses the text of an ESRI ASCII grid; `file` names it in diagnostics.
///
/// The header gives `ncols`, `nrows`, `xllcorner` or `xllcenter`, `yllcorner` or `yllcenter`,
/// `cellsize` and optionally `NODATA_value` (keys in any case, one per line); then come `nrows`
/// lines of `ncols` numbers, the first line the northmost row. Cells equal to `NODATA_value`
/// are marked [`CellAttrs::NODATA`] (the planner blocks them) and take the height of the nearest
/// cell with data, so the surface stays finite. NaN and infinite values are rejected.
pub fn parse_asc(text: &str, file: impl AsRef<Path>) -> Result<Terrain, Diagnostics> {
    let file = file.as_ref();
    let at =
        |line: usize, col: usize, msg: String| Diagnostic::new(file, line, col, msg, Some(text));
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l)).peekable();

    // Header: lines whose first token starts with a letter.
    let mut h = Header::default();
    while let Some(&(ln, line)) = lines.peek() {
        let mut toks = tokens(line);
        let Some(key) = toks.next() else {
            lines.next();
            continue;
        };
        let lower = key.text.to_ascii_lowercase();
        let known = matches!(
            lower.as_str(),
            "ncols"
                | "nrows"
                | "xllcorner"
                | "xllcenter"
                | "yllcorner"
                | "yllcenter"
                | "cellsize"
                | "nodata_value"
        );
        // The data starts at the first line that opens with a number (`nan` and `inf` count),
        // or, once the required keys are all there, with anything but a header key.
        let complete = h.ncols.is_some()
            && h.nrows.is_some()
            && h.x.is_some()
            && h.y.is_some()
            && h.cellsize.is_some();
        if !key.text.starts_with(|c: char| c.is_ascii_alphabetic())
            || key.text.parse::<f64>().is_ok()
            || (complete && !known)
        {
            break;
        }
        lines.next();
        if !known {
            return Err(at(
                ln,
                key.col,
                format!(
                    "unknown header key `{}`; expected one of {HEADER_KEYS}",
                    key.text
                ),
            )
            .into());
        }
        let Some(value) = toks.next() else {
            let end = line.trim_end().chars().count() + 1;
            return Err(at(ln, end, format!("expected a value after `{}`", key.text)).into());
        };
        if let Some(extra) = toks.next() {
            return Err(at(
                ln,
                extra.col,
                format!(
                    "unexpected `{}` after the value of `{}`",
                    extra.text, key.text
                ),
            )
            .into());
        }
        let number = value.text.parse::<f64>().ok().filter(|v| v.is_finite());
        let bad = |what: &str| {
            Diagnostics::from(at(
                ln,
                value.col,
                format!("expected {what} for `{}`, found `{}`", key.text, value.text),
            ))
        };
        let duplicate = || {
            Diagnostics::from(at(
                ln,
                key.col,
                format!("header key `{}` repeats an earlier one", key.text),
            ))
        };
        match lower.as_str() {
            "ncols" | "nrows" => {
                let n = value
                    .text
                    .parse::<u64>()
                    .ok()
                    .filter(|&n| n > 0 && n <= MAX_CELLS)
                    .ok_or_else(|| {
                        bad(&format!(
                            "a whole number from 1 to {MAX_CELLS} (the most cells a grid may have)"
                        ))
                    })? as usize;
                h.size_at = (ln, value.col);
                let slot = if lower == "ncols" {
                    &mut h.ncols
                } else {
                    &mut h.nrows
                };
                if slot.replace(n).is_some() {
                    return Err(duplicate());
                }
            }
            "xllcorner" | "xllcenter" | "yllcorner" | "yllcenter" => {
                let v = number.ok_or_else(|| bad("a number"))?;
                let slot = if lower.starts_with('x') {
                    &mut h.x
                } else {
                    &mut h.y
                };
                if slot.replace((v, lower.ends_with("center"))).is_some() {
                    return Err(duplicate());
                }
            }
            "cellsize" => {
                let v = number
                    .filter(|&v| v > 0.0)
                    .ok_or_else(|| bad("a positive number"))?;
                if h.cellsize.replace(v).is_some() {
                    return Err(duplicate());
                }
            }
            _ => {
                let v = number.ok_or_else(|| bad("a number"))?;
                if h.nodata.replace(v).is_some() {
                    return Err(duplicate());
                }
            }
        }
    }

    let (data_line, _) = lines
        .peek()
        .copied()
        .unwrap_or((text.lines().count() + 1, ""));
    let missing = |key: &str| {
        Diagnostics::from(at(
            data_line,
            1,
            format!("missing header key `{key}` before the data (the header needs ncols, nrows, xllcorner or xllcenter, yllcorner or yllcenter, cellsize)"),
        ))
    };
    let ncols = h.ncols.ok_or_else(|| missing("ncols"))?;
    let nrows = h.nrows.ok_or_else(|| missing("nrows"))?;
    let (x, x_centre) = h.x.ok_or_else(|| missing("xllcorner"))?;
    let (y, y_centre) = h.y.ok_or_else(|| missing("yllcorner"))?;
    let cs = h.cellsize.ok_or_else(|| missing("cellsize"))?;
    let cells = (ncols as u64).saturating_mul(nrows as u64);
    if cells > MAX_CELLS {
        return Err(at(
            h.size_at.0,
            h.size_at.1,
            format!(
                "the grid has {ncols} × {nrows} = {cells} cells; a terrain may have at most {MAX_CELLS} (2^28)"
            ),
        )
        .into());
    }

    // Data rows.
    let mut heights = Vec::with_capacity(ncols * nrows);
    let mut nodata = Vec::with_capacity(ncols * nrows);
    let mut errors = Vec::new();
    let mut row = 0usize;
    let mut last_line = 0usize;
    for (ln, line) in lines {
        last_line = ln;
        if line.trim().is_empty() {
            continue;
        }
        if row == nrows {
            errors.push(at(
                ln,
                1,
                format!("extra row: the header declares {nrows} rows (nrows)"),
            ));
            break;
        }
        let mut count = 0usize;
        for tok in tokens(line) {
            count += 1;
            if count == ncols + 1 {
                let total = tokens(line).count();
                errors.push(at(
                    ln,
                    tok.col,
                    format!(
                        "row {} has {total} values, expected {ncols} (ncols)",
                        row + 1
                    ),
                ));
            }
            if count > ncols {
                continue;
            }
            match tok.text.parse::<f32>() {
                Ok(v) if !v.is_finite() => {
                    errors.push(at(
                        ln,
                        tok.col,
                        format!(
                            "`{}` is not a finite height (mark missing cells with NODATA_value)",
                            tok.text
                        ),
                    ));
                    heights.push(0.0);
                    nodata.push(true);
                }
                Ok(v) => {
                    let missing = h
                        .nodata
                        .is_some_and(|nd| f64::from(v) == nd || v == nd as f32);
                    heights.push(if missing { 0.0 } else { v });
                    nodata.push(missing);
                }
                Err(_) => {
                    errors.push(at(
                        ln,
                        tok.col,
                        format!("expected a number, found `{}`", tok.text),
                    ));
                    heights.push(0.0);
                    nodata.push(true);
                }
            }
        }
        if count < ncols {
            errors.push(at(
                ln,
                line.trim_end().chars().count() + 1,
                format!(
                    "row {} has {count} values, expected {ncols} (ncols)",
                    row + 1
                ),
            ));
            for _ in count..ncols {
                heights.push(0.0);
                nodata.push(true);
            }
        }
        row += 1;
        if errors.len() >= MAX_DIAGNOSTICS {
            break;
        }
    }
    if row < nrows && errors.len() < MAX_DIAGNOSTICS {
        let end = text.lines().count().max(last_line) + 1;
        errors.push(at(
            end,
            1,
            format!("the file ends after {row} rows, expected {nrows} (nrows)"),
        ));
    }
    if !errors.is_empty() {
        errors.truncate(MAX_DIAGNOSTICS);
        return Err(Diagnostics(errors));
    }

    let span = cs * ncols.max(nrows) as f64;
    let far = f64::from(crate::numbers::MAX_COORD);
    if span > far || x.abs() > far || y.abs() > far {
        return Err(at(
            h.size_at.0,
            h.size_at.1,
            format!(
                "the grid spans {span} world units from ({x}, {y}); coordinates must stay within ±{far:e}"
            ),
        )
        .into());
    }
    let west = if x_centre { x - cs / 2.0 } else { x };
    let south = if y_centre { y - cs / 2.0 } else { y };
    let origin = Vec2::new(west as f32, -(south + nrows as f64 * cs) as f32);
    let mut t = Terrain::from_heights(ncols, nrows, cs as f32, origin, heights);
    fill_nodata(&mut t, &nodata);
    Ok(t)
}

/// Gives each no-data cell the height of the nearest cell with data (breadth-first over the
/// 4-neighbourhood) and marks it [`CellAttrs::NODATA`].
fn fill_nodata(t: &mut Terrain, nodata: &[bool]) {
    if !nodata.iter().any(|&b| b) {
        return;
    }
    let (cols, rows) = (t.cols, t.rows);
    let mut done: Vec<bool> = nodata.iter().map(|&b| !b).collect();
    let mut queue: VecDeque<usize> = (0..nodata.len()).filter(|&i| done[i]).collect();
    while let Some(i) = queue.pop_front() {
        let (c, r) = (i % cols, i / cols);
        let mut push = |j: usize| {
            if !done[j] {
                done[j] = true;
                t.heights[j] = t.heights[i];
                queue.push_back(j);
            }
        };
        if c > 0 {
            push(i - 1);
        }
        if c + 1 < cols {
            push(i + 1);
        }
        if r > 0 {
            push(i - cols);
        }
        if r + 1 < rows {
            push(i + cols);
        }
    }
    for (a, &nd) in t.attrs.iter_mut().zip(nodata) {
        if nd {
            a.flags |= CellAttrs::NODATA;
        }
    }
}

/// Reads and parses a binary PGM height map; see [`parse_pgm`].
pub fn load_pgm(path: &Path, cell_size: f32, vertical_scale: f32) -> Result<Terrain, Diagnostics> {
    let bytes = crate::diag::read_bytes(path, "height map")?;
    parse_pgm(&bytes, path, cell_size, vertical_scale)
}

/// Parses a binary PGM (`P5`) height map: 8-bit samples when maxval < 256, else 16-bit
/// big-endian (maxval up to 65535). Height = sample × `vertical_scale`; the first image row is
/// the northmost; the grid's north-west corner is at the world origin.
pub fn parse_pgm(
    bytes: &[u8],
    file: impl AsRef<Path>,
    cell_size: f32,
    vertical_scale: f32,
) -> Result<Terrain, Diagnostics> {
    let file = file.as_ref();
    // The header is text; find where it ends to show its lines in diagnostics.
    let header_text = String::from_utf8_lossy(&bytes[..bytes.len().min(512)]).into_owned();
    let (mut pos, mut line, mut col) = (0usize, 1usize, 1usize);
    let mut fields: Vec<(String, usize, usize)> = Vec::new();
    while fields.len() < 4 {
        // Skip whitespace and comments.
        while pos < bytes.len() {
            match bytes[pos] {
                b'#' => {
                    while pos < bytes.len() && bytes[pos] != b'\n' {
                        pos += 1;
                    }
                }
                b'\n' => {
                    pos += 1;
                    line += 1;
                    col = 1;
                }
                c if c.is_ascii_whitespace() => {
                    pos += 1;
                    col += 1;
                }
                _ => break,
            }
        }
        if pos >= bytes.len() {
            // Located where the file ends, so the user sees how far the header got.
            return Err(Diagnostic::new(
                file,
                line,
                col,
                "the PGM header ends before width, height and maxval",
                Some(&header_text),
            )
            .into());
        }
        let (start_line, start_col, start) = (line, col, pos);
        while pos < bytes.len()
            && !bytes[pos].is_ascii_whitespace()
            && (fields.is_empty() || bytes[pos] != b'#')
        {
            pos += 1;
            col += 1;
        }
        fields.push((
            String::from_utf8_lossy(&bytes[start..pos]).into_owned(),
            start_line,
            start_col,
        ));
    }
    let at = |i: usize, msg: String| {
        Diagnostics::from(Diagnostic::new(
            file,
            fields[i].1,
            fields[i].2,
            msg,
            Some(&header_text),
        ))
    };
    if fields[0].0 != "P5" {
        return Err(at(
            0,
            format!("expected `P5` (binary greymap), found `{}`", fields[0].0),
        ));
    }
    let number = |i: usize, what: &str, max: usize| {
        fields[i]
            .0
            .parse::<usize>()
            .ok()
            .filter(|&n| n > 0 && n <= max)
            .ok_or_else(|| at(i, format!("expected {what}, found `{}`", fields[i].0)))
    };
    let cols = number(1, "a positive whole number for the width", 1 << 20)?;
    let rows = number(2, "a positive whole number for the height", 1 << 20)?;
    let maxval = number(3, "a maxval from 1 to 65535", 65535)?;
    if (cols as u64) * (rows as u64) > MAX_CELLS {
        return Err(at(
            2,
            format!(
                "the image has {cols} × {rows} cells; a terrain may have at most {MAX_CELLS} (2^28)"
            ),
        ));
    }
    // Exactly one whitespace byte separates the header from the samples.
    let data = &bytes[(pos + 1).min(bytes.len())..];
    let width = if maxval < 256 { 1 } else { 2 };
    let need = cols * rows * width;
    if data.len() < need {
        // Samples have no lines: point at the width, which with the height sets how many.
        return Err(at(
            1,
            format!(
                "expected {need} bytes of samples for {cols}×{rows} at maxval {maxval}, found {}",
                data.len()
            ),
        ));
    }
    let heights = (0..cols * rows)
        .map(|i| {
            let s = if width == 1 {
                u32::from(data[i])
            } else {
                u32::from(u16::from_be_bytes([data[2 * i], data[2 * i + 1]]))
            };
            s.min(maxval as u32) as f32 * vertical_scale
        })
        .collect();
    Ok(Terrain::from_heights(
        cols,
        rows,
        cell_size,
        Vec2::ZERO,
        heights,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::Cell;

    const GOOD: &str = "ncols 3\nNROWS 2\nxllcorner 100\nyllcenter 51\ncellsize 2\nNODATA_value -9999\n1 2 3\n4 -9999 6\n";

    fn err(text: &str) -> Diagnostic {
        parse_asc(text, "hills.asc").unwrap_err().0.remove(0)
    }

    #[test]
    fn parses_header_rows_and_nodata() {
        let t = parse_asc(GOOD, "hills.asc").unwrap();
        assert_eq!((t.cols, t.rows, t.cell_size), (3, 2, 2.0));
        // South edge 50, two rows of 2 m: the north edge is at northing 54, so z = -54.
        assert_eq!(t.origin, Vec2::new(100.0, -54.0));
        assert_eq!(t.height_of(Cell::new(0, 0)), 1.0);
        assert_eq!(t.height_of(Cell::new(2, 1)), 6.0);
        assert!(t.attrs[4].nodata());
        let filled = t.height_of(Cell::new(1, 1));
        assert!(filled == 4.0 || filled == 2.0 || filled == 6.0);
        assert!(t.heights.iter().all(|h| h.is_finite()));
    }

    #[test]
    fn wrong_header_key_is_located_at_the_key() {
        let d = err("ncols 3\nnrows 2\nxllcorner 0\nylcorner 0\ncellsize 1\n1 2 3\n4 5 6\n");
        assert_eq!(
            (d.file.to_str().unwrap(), d.line, d.col),
            ("hills.asc", 4, 1)
        );
        assert_eq!(
            d.message,
            "unknown header key `ylcorner`; expected one of ncols, nrows, xllcorner, xllcenter, yllcorner, yllcenter, cellsize, NODATA_value"
        );
        assert_eq!(d.source_line.as_deref(), Some("ylcorner 0"));
    }

    #[test]
    fn missing_header_key_is_reported_where_the_data_starts() {
        let d = err("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\n1 2 3\n4 5 6\n");
        assert_eq!((d.line, d.col), (5, 1));
        assert!(d
            .message
            .starts_with("missing header key `cellsize` before the data"));
    }

    #[test]
    fn bad_header_value_is_located_at_the_value() {
        let d = err("ncols three\nnrows 2\n");
        assert_eq!((d.line, d.col), (1, 7));
        assert_eq!(
            d.message,
            "expected a whole number from 1 to 268435456 (the most cells a grid may have) for `ncols`, found `three`"
        );
    }

    #[test]
    fn nan_cell_is_rejected_at_its_token() {
        let d = err("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4  NaN 6\n");
        assert_eq!((d.line, d.col), (7, 4));
        assert_eq!(
            d.message,
            "`NaN` is not a finite height (mark missing cells with NODATA_value)"
        );
        let d = err("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\ninf 2 3\n4 5 6\n");
        assert_eq!((d.line, d.col), (6, 1));
    }

    #[test]
    fn bad_number_is_located_at_its_token() {
        let d = err("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5.5.1 6\n");
        assert_eq!(
            (d.file.to_str().unwrap(), d.line, d.col),
            ("hills.asc", 7, 3)
        );
        assert_eq!(d.message, "expected a number, found `5.5.1`");
        assert_eq!(
            d.to_string(),
            "hills.asc:7:3: expected a number, found `5.5.1`\n7 | 4 5.5.1 6\n  |   ^"
        );
    }

    #[test]
    fn row_with_wrong_count_is_located() {
        let d = err("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n4 5 6\n");
        assert_eq!((d.line, d.col), (6, 4));
        assert_eq!(d.message, "row 1 has 2 values, expected 3 (ncols)");
        let d = err("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6 7 8\n");
        assert_eq!((d.line, d.col), (7, 7));
        assert_eq!(d.message, "row 2 has 5 values, expected 3 (ncols)");
    }

    #[test]
    fn size_mismatch_in_rows_is_reported() {
        let d = err("ncols 2\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 4\n");
        assert_eq!((d.line, d.col), (8, 1));
        assert_eq!(d.message, "the file ends after 2 rows, expected 3 (nrows)");
        assert_eq!(d.source_line, None);
        let d = err("ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 4\n");
        assert_eq!((d.line, d.col), (7, 1));
        assert_eq!(d.message, "extra row: the header declares 1 rows (nrows)");
    }

    #[test]
    fn several_data_errors_are_reported_together() {
        let all = parse_asc(
            "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nx 2\n3 y\n",
            "a.asc",
        )
        .unwrap_err();
        let at: Vec<(usize, usize)> = all.0.iter().map(|d| (d.line, d.col)).collect();
        assert_eq!(at, vec![(6, 1), (7, 3)]);
    }

    #[test]
    fn loads_from_disk_and_reports_missing_files() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("g.asc");
        std::fs::write(&p, GOOD).unwrap();
        assert_eq!(load_asc(&p).unwrap().cols, 3);
        let d = load_asc(&dir.path().join("none.asc")).unwrap_err();
        assert_eq!(d.0[0].line, 0);
        assert!(d.0[0].message.starts_with("cannot read terrain file"));
    }

    #[test]
    fn pgm16_is_big_endian_and_scaled() {
        let mut bytes = b"P5\n# a comment\n2 2\n65535\n".to_vec();
        for s in [0u16, 1, 256, 65535] {
            bytes.extend_from_slice(&s.to_be_bytes());
        }
        let t = parse_pgm(&bytes, "h.pgm", 5.0, 0.5).unwrap();
        assert_eq!((t.cols, t.rows, t.cell_size), (2, 2, 5.0));
        assert_eq!(t.heights, vec![0.0, 0.5, 128.0, 32767.5]);
        let mut small = b"P5 2 1 255\n".to_vec();
        small.extend_from_slice(&[10, 20]);
        assert_eq!(
            parse_pgm(&small, "s.pgm", 1.0, 1.0).unwrap().heights,
            vec![10.0, 20.0]
        );
    }

    #[test]
    fn pgm_errors_are_located_in_the_header() {
        let d = parse_pgm(b"P2\n2 2\n255\n", "h.pgm", 1.0, 1.0)
            .unwrap_err()
            .0
            .remove(0);
        assert_eq!((d.line, d.col), (1, 1));
        assert_eq!(d.message, "expected `P5` (binary greymap), found `P2`");
        let d = parse_pgm(b"P5\n2 2\n70000\n", "h.pgm", 1.0, 1.0)
            .unwrap_err()
            .0
            .remove(0);
        assert_eq!((d.line, d.col), (3, 1));
        let d = parse_pgm(b"P5\n2 2\n255\n\x01", "h.pgm", 1.0, 1.0)
            .unwrap_err()
            .0
            .remove(0);
        assert_eq!(
            d.message,
            "expected 4 bytes of samples for 2×2 at maxval 255, found 1"
        );
        assert_eq!((d.line, d.col), (2, 1));
        // A header cut short is located where the file ends.
        let d = parse_pgm(b"P5\n2 ", "h.pgm", 1.0, 1.0)
            .unwrap_err()
            .0
            .remove(0);
        assert_eq!((d.line, d.col), (2, 3));
        assert_eq!(d.source_line.as_deref(), Some("2 "));
    }
}
