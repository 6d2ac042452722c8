//! Floats as the recording writes them: exactly the bytes of Rust's `Display` (the shortest
//! digits that read back to the same bits, never an exponent: `0.0000001`, `-0`, `1`), laid out
//! from `ryu`'s shortest digits at about a third of the cost. A trajectory row holds twelve
//! floats; formatting them was most of the recording's time.
//!
//! The two pick the same digits but for one case: a float exactly halfway between the two
//! nearest shortest candidates (3065919.25 between 3065919.2 and 3065919.3), where `ryu` takes
//! the even one and `Display` the one further from zero. Such a float's exact decimal form has
//! one digit more than the shortest (its last a 5): every float with digits after the point
//! whose exact form has at most two digits more than the shortest is written by `Display`
//! itself. An integer is never such a tie. A test compares every `f32` bit pattern
//! (`cargo test --release -- --ignored every_f32`, about five minutes on two cores) and a
//! sample of them in every run.

use std::fmt::Write as _;

/// Appends `v` to `out` exactly as `write!(out, "{v}")` does.
pub fn push_f32(out: &mut String, v: f32) {
    if !v.is_finite() {
        let _ = write!(out, "{v}");
        return;
    }
    let mut buf = ryu::Buffer::new();
    if !layout(out, buf.format_finite(v), exact_fraction_bits(v)) {
        let _ = write!(out, "{v}");
    }
}

/// The binary digits after the point of `v`'s exact value (`v = m · 2^−k`, `m` odd; 0 for an
/// integer).
fn exact_fraction_bits(v: f32) -> u32 {
    let bits = v.to_bits();
    let field = (bits >> 23) & 0xff;
    let mantissa = bits & 0x7f_ffff;
    let (m, e) = if field == 0 {
        (mantissa, -149)
    } else {
        (mantissa | 0x80_0000, field as i32 - 150)
    };
    if m == 0 {
        return 0;
    }
    (-(e + m.trailing_zeros() as i32)).max(0) as u32
}

/// Lays out `ryu`'s form of a finite float (`-1.5e-7`, `123.0`, `0.001`) as `Display` does;
/// `false` (nothing written) where `Display` may pick other digits (see the module's header),
/// given the binary digits after the point of the float's exact value.
fn layout(out: &mut String, s: &str, fraction_bits: u32) -> bool {
    let (negative, s) = match s.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, s),
    };
    let (mantissa, exponent) = match s.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap_or(0)),
        None => (s, 0),
    };
    let (whole, fraction) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    // The significant digits, and where the decimal point falls among them.
    let mut digits = [0u8; 48];
    let mut n = 0;
    for &d in whole.as_bytes().iter().chain(fraction.as_bytes()) {
        digits[n] = d;
        n += 1;
    }
    let mut point = whole.len() as i32 + exponent;
    let leading = digits[..n].iter().take_while(|&&d| d == b'0').count();
    point -= leading as i32;
    let digits = &digits[leading..n];
    let trailing = digits.iter().rev().take_while(|&&d| d == b'0').count();
    let digits = &digits[..digits.len() - trailing];
    // The exact value's significant digits: its `k` binary digits after the point are `k`
    // decimal ones (2^−k ends in 5), and `point` (one more where the shortest digits rounded
    // up to a power of ten) before them.
    let k = fraction_bits as i64;
    if k > 0 && k + point as i64 <= digits.len() as i64 + 2 {
        return false;
    }
    if negative {
        out.push('-');
    }
    if digits.is_empty() {
        out.push('0');
    } else if point <= 0 {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', (-point) as usize));
        out.push_str(text(digits));
    } else if point as usize >= digits.len() {
        out.push_str(text(digits));
        out.extend(std::iter::repeat_n('0', point as usize - digits.len()));
    } else {
        let (a, b) = digits.split_at(point as usize);
        out.push_str(text(a));
        out.push('.');
        out.push_str(text(b));
    }
    true
}

/// ASCII digits as text.
fn text(d: &[u8]) -> &str {
    std::str::from_utf8(d).unwrap_or("")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(bits: u32, ours: &mut String, std: &mut String) {
        let v = f32::from_bits(bits);
        ours.clear();
        std.clear();
        push_f32(ours, v);
        let _ = write!(std, "{v}");
        assert_eq!(ours, std, "bits {bits:#010x}");
    }

    #[test]
    fn floats_are_written_as_display_writes_them() {
        let (mut a, mut b) = (String::new(), String::new());
        let special = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.5,
            1e-7,
            1.5e-7,
            123.456,
            1e20,
            16777216.0,
            123456790.0,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            f32::EPSILON,
            f32::from_bits(1),
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for v in special {
            check(v.to_bits(), &mut a, &mut b);
        }
        // A sample of every bit pattern (a fixed stream: the same values every run).
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            check(x as u32, &mut a, &mut b);
            check((x >> 32) as u32, &mut a, &mut b);
        }
        // And every float a recording holds most: positions and headings, two decimal
        // exponents either side of one.
        for bits in (0x3c00_0000u32..0x4400_0000).step_by(97) {
            check(bits, &mut a, &mut b);
            check(bits | 0x8000_0000, &mut a, &mut b);
        }
    }

    /// Every `f32` (about five minutes in a release build on two cores).
    #[test]
    #[ignore]
    fn every_f32_is_written_as_display_writes_it() {
        use rayon::prelude::*;
        (0..=u32::MAX >> 16).into_par_iter().for_each(|hi| {
            let (mut a, mut b) = (String::new(), String::new());
            for lo in 0..=0xffffu32 {
                check(hi << 16 | lo, &mut a, &mut b);
            }
        });
    }
}
