//! A sweep's points from its axes: the grid's combinations of values and ranges, uniform random
//! and Latin hypercube samples within bounds (drawn from the sweep's seed, so a plan is the same
//! everywhere), and the rows of a sample file. Values are RON text; numbers made here are
//! written in Rust's shortest round-trip form (whole numbers without a fraction, so that they
//! also fit integer keys).

use super::def::{AxisDef, SamplerDef, SweepDef};
use crate::load::ron_patch::{value_text, Step};
use crate::load::{locate, locate_key, Diagnostic, Diagnostics};
use std::path::Path;

/// The most points a sweep may have (a typo in a range must not plan a billion runs).
pub const MAX_POINTS: usize = 1_000_000;

/// A number as RON text: whole numbers bare (`40`), others in shortest round-trip form.
pub fn number(x: f64, integer: bool) -> String {
    let x = if integer { x.round() } else { x };
    if x == x.trunc() && x.abs() < 1e15 {
        format!("{}", x as i64)
    } else {
        format!("{x:?}")
    }
}

/// SplitMix64: the samplers' stream, seeded by the sweep's seed.
struct Draws(u64);

impl Draws {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in 0..n.
    fn below(&mut self, n: usize) -> usize {
        (self.unit() * n as f64) as usize
    }
}

/// Every point of the sweep, one RON value per axis.
pub fn points(file: &Path, text: &str, def: &SweepDef) -> Result<Vec<Vec<String>>, Diagnostics> {
    let axis_at = |i: usize, key: &str| {
        // The i-th axis's `key` (or the `axes` list when it cannot be found).
        let mut from = locate_key(text, "axes", 0).map_or(0, |x| x.2);
        for _ in 0..i {
            from = locate_key(text, "key", from).map_or(from, |x| x.2 + 1);
        }
        let (l, c, _) = locate_key(text, key, from)
            .or_else(|| locate_key(text, "axes", 0))
            .unwrap_or((0, 0, 0));
        (l, c)
    };
    let bad = |i: usize, key: &str, msg: String| {
        let (l, c) = axis_at(i, key);
        Diagnostics::from(Diagnostic::new(file, l, c, msg, Some(text)))
    };
    if def.axes.is_empty() {
        let (l, c, _) = locate_key(text, "axes", 0).unwrap_or((0, 0, 0));
        return Err(Diagnostic::new(
            file,
            l,
            c,
            "`axes` is empty: a sweep varies at least one key",
            Some(text),
        )
        .into());
    }
    let sampled = |n: u32| -> Result<Vec<(f64, f64, bool)>, Diagnostics> {
        if n == 0 {
            let (l, c, _) = locate_key(text, "sampler", 0).unwrap_or((0, 0, 0));
            return Err(
                Diagnostic::new(file, l, c, "the sampler needs n ≥ 1 points", Some(text)).into(),
            );
        }
        def.axes
            .iter()
            .enumerate()
            .map(|(i, a)| match a.bounds {
                Some((lo, hi)) if lo.is_finite() && hi.is_finite() && lo <= hi => {
                    Ok((lo, hi, a.integer))
                }
                Some(_) => Err(bad(
                    i,
                    "bounds",
                    "`bounds` must be (low, high) with low ≤ high".into(),
                )),
                None => Err(bad(
                    i,
                    "key",
                    format!(
                        "axis `{}` has no `bounds`: a sampled sweep draws each axis within \
                         `bounds: (low, high)`",
                        a.key
                    ),
                )),
            })
            .collect()
    };
    let mut draws = Draws(def.seed);
    let pts = match &def.sampler {
        SamplerDef::Grid => {
            let mut per_axis = Vec::new();
            for (i, a) in def.axes.iter().enumerate() {
                per_axis.push(axis_values(text, i, a).map_err(|m| bad(i, m.0, m.1))?);
            }
            let total = per_axis
                .iter()
                .try_fold(1usize, |n, v| n.checked_mul(v.len()))
                .unwrap_or(usize::MAX);
            if total > MAX_POINTS {
                return Err(bad(
                    0,
                    "key",
                    format!("the grid has {total} points; at most {MAX_POINTS}"),
                ));
            }
            let mut out = vec![Vec::new()];
            for vals in &per_axis {
                let mut next = Vec::with_capacity(out.len() * vals.len());
                for p in &out {
                    for v in vals {
                        let mut q: Vec<String> = p.clone();
                        q.push(v.clone());
                        next.push(q);
                    }
                }
                out = next;
            }
            out
        }
        SamplerDef::Random(n) => {
            let b = sampled(*n)?;
            (0..*n)
                .map(|_| {
                    b.iter()
                        .map(|&(lo, hi, int)| number(lo + draws.unit() * (hi - lo), int))
                        .collect()
                })
                .collect()
        }
        SamplerDef::LatinHypercube(n) => {
            let b = sampled(*n)?;
            let n = *n as usize;
            let mut cols = Vec::new();
            for &(lo, hi, int) in &b {
                // One stratum of each axis per point, in an order drawn for the axis.
                let mut perm: Vec<usize> = (0..n).collect();
                for i in (1..n).rev() {
                    perm.swap(i, draws.below(i + 1));
                }
                let col: Vec<String> = perm
                    .iter()
                    .map(|&s| number(lo + (s as f64 + draws.unit()) / n as f64 * (hi - lo), int))
                    .collect();
                cols.push(col);
            }
            (0..n)
                .map(|p| cols.iter().map(|c| c[p].clone()).collect())
                .collect()
        }
        SamplerDef::File(f) => {
            let path = file.parent().unwrap_or(Path::new(".")).join(f);
            sample_file(&path, &def.axes).map_err(|mut d| {
                // A missing file is said where the sweep names it.
                if d.0.iter().all(|x| x.line == 0) {
                    let (l, c, _) = locate(text, &format!("\"{f}\""), 0).unwrap_or((0, 0, 0));
                    d.0 =
                        d.0.into_iter()
                            .map(|x| {
                                Diagnostic::new(
                                    file,
                                    l,
                                    c,
                                    format!("{}: {}", x.file.display(), x.message),
                                    Some(text),
                                )
                            })
                            .collect();
                }
                d
            })?
        }
    };
    Ok(pts)
}

/// The grid values of axis `i`, as RON text; the error names the key to point at.
fn axis_values(text: &str, i: usize, a: &AxisDef) -> Result<Vec<String>, (&'static str, String)> {
    match (&a.values, &a.range) {
        (Some(v), None) => {
            if v.is_empty() {
                return Err(("values", format!("axis `{}`: `values` is empty", a.key)));
            }
            (0..v.len())
                .map(|j| {
                    let steps = [
                        Step::Field("axes".into()),
                        Step::Index(i),
                        Step::Field("values".into()),
                        Step::Index(j),
                    ];
                    value_text(text, &steps).map(|t| t.to_string()).ok_or((
                        "values",
                        format!("axis `{}`: value {j} could not be read", a.key),
                    ))
                })
                .collect()
        }
        (None, Some(r)) => {
            let ok = r.from.is_finite() && r.to.is_finite();
            let n = match (r.step, r.count) {
                (Some(s), None) if ok && s.is_finite() && s > 0.0 && r.to >= r.from => {
                    // A step that lands on `to` within rounding includes it.
                    ((r.to - r.from) / s * (1.0 + 1e-12)).floor() as usize + 1
                }
                (None, Some(c)) if ok && c >= 1 => c as usize,
                _ => {
                    return Err((
                        "range",
                        format!(
                            "axis `{}`: a range is (from: a, to: b, step: s) with s > 0 and \
                             b ≥ a, or (from: a, to: b, count: n) with n ≥ 1",
                            a.key
                        ),
                    ))
                }
            };
            if n > MAX_POINTS {
                return Err((
                    "range",
                    format!("axis `{}`: {n} values; at most {MAX_POINTS}", a.key),
                ));
            }
            Ok((0..n)
                .map(|k| {
                    let x = match r.step {
                        Some(s) => r.from + k as f64 * s,
                        None if n == 1 => r.from,
                        None => r.from + (r.to - r.from) * k as f64 / (n - 1) as f64,
                    };
                    number(x, a.integer)
                })
                .collect())
        }
        _ => Err((
            "key",
            format!(
                "axis `{}`: a grid axis has either `values: [...]` or `range: (...)`",
                a.key
            ),
        )),
    }
}

/// The rows of a sample file: one number per axis each, whitespace-separated (`#` comments and
/// blank lines skipped).
fn sample_file(path: &Path, axes: &[AxisDef]) -> Result<Vec<Vec<String>>, Diagnostics> {
    let text = crate::load::read_text(path, "sample file")?;
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = l.split_whitespace().collect();
        if cols.len() != axes.len() {
            return Err(Diagnostic::new(
                path,
                n + 1,
                1,
                format!(
                    "{} column(s), expected {} (one per axis, in the order of `axes`)",
                    cols.len(),
                    axes.len()
                ),
                Some(&text),
            )
            .into());
        }
        let mut row = Vec::new();
        for (c, (v, a)) in cols.iter().zip(axes).enumerate() {
            let x: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| {
                    let col = line.find(v).map_or(1, |i| i + 1);
                    Diagnostics::from(Diagnostic::new(
                        path,
                        n + 1,
                        col,
                        format!("column {} (`{}`): `{v}` is not a number", c + 1, a.key),
                        Some(&text),
                    ))
                })?;
            row.push(number(x, a.integer));
        }
        rows.push(row);
    }
    if rows.len() > MAX_POINTS {
        return Err(
            Diagnostic::file(path, format!("{} rows; at most {MAX_POINTS}", rows.len())).into(),
        );
    }
    Ok(rows)
}
