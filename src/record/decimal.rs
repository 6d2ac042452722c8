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

use std::io::Write as _;

/// Appends `v` to `out` exactly as `write!(out, "{v}")` does.
pub fn push_f32(out: &mut Vec<u8>, v: f32) {
    if !v.is_finite() {
        let _ = write!(out, "{v}");
        return;
    }
    let mut buf = ryu::Buffer::new();
    if !layout(out, buf.format_finite(v).as_bytes(), exact_fraction_bits(v)) {
        let _ = write!(out, "{v}");
    }
}

/// Appends `v` in decimal digits (as `Display` writes an unsigned integer).
pub fn push_u64(out: &mut Vec<u8>, mut v: u64) {
    let mut b = [0u8; 20];
    let mut i = b.len();
    loop {
        i -= 1;
        b[i] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    out.extend_from_slice(&b[i..]);
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

/// `ryu`'s exponent after the `e` (`-7`, `20`).
fn exponent_of(s: &[u8]) -> i32 {
    let (negative, digits) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, s),
    };
    let e = digits
        .iter()
        .fold(0i32, |e, &d| e * 10 + i32::from(d.wrapping_sub(b'0')));
    if negative {
        -e
    } else {
        e
    }
}

/// Lays out `ryu`'s form of a finite float (`-1.5e-7`, `123.0`, `0.001`) as `Display` does;
/// `false` (nothing written) where `Display` may pick other digits (see the module's header),
/// given the binary digits after the point of the float's exact value. Works on bytes: `ryu`
/// writes ASCII only.
fn layout(out: &mut Vec<u8>, s: &[u8], fraction_bits: u32) -> bool {
    let (negative, s) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, s),
    };
    let (mantissa, exponent) = match s.iter().position(|&b| b == b'e') {
        Some(i) => (&s[..i], exponent_of(&s[i + 1..])),
        None => (s, 0),
    };
    let (whole, fraction) = match mantissa.iter().position(|&b| b == b'.') {
        Some(i) => (&mantissa[..i], &mantissa[i + 1..]),
        None => (mantissa, &[][..]),
    };
    // The significant digits, and where the decimal point falls among them.
    let mut digits = [0u8; 48];
    let n = whole.len() + fraction.len();
    if n > digits.len() {
        return false;
    }
    digits[..whole.len()].copy_from_slice(whole);
    digits[whole.len()..n].copy_from_slice(fraction);
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
        out.push(b'-');
    }
    if digits.is_empty() {
        out.push(b'0');
    } else if point <= 0 {
        out.extend_from_slice(b"0.");
        out.resize(out.len() + (-point) as usize, b'0');
        out.extend_from_slice(digits);
    } else if point as usize >= digits.len() {
        out.extend_from_slice(digits);
        out.resize(out.len() + (point as usize - digits.len()), b'0');
    } else {
        let (a, b) = digits.split_at(point as usize);
        out.extend_from_slice(a);
        out.push(b'.');
        out.extend_from_slice(b);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(bits: u32, ours: &mut Vec<u8>, std: &mut Vec<u8>) {
        let v = f32::from_bits(bits);
        ours.clear();
        std.clear();
        push_f32(ours, v);
        let _ = write!(std, "{v}");
        assert_eq!(ours, std, "bits {bits:#010x}");
    }

    #[test]
    fn integers_are_written_as_display_writes_them() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut values = vec![0, 1, 9, 10, 99, 100, u64::MAX, u64::MAX / 10, 1 << 32];
        for _ in 0..10_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            values.push(x >> (x % 64));
        }
        let mut ours = Vec::new();
        for v in values {
            ours.clear();
            push_u64(&mut ours, v);
            assert_eq!(ours, v.to_string().as_bytes());
        }
    }

    #[test]
    fn floats_are_written_as_display_writes_them() {
        let (mut a, mut b) = (Vec::new(), Vec::new());
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
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for lo in 0..=0xffffu32 {
                check(hi << 16 | lo, &mut a, &mut b);
            }
        });
    }
}
