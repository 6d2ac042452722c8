//! Elementary functions with the same bits on every machine.
//!
//! `f32::sin` and its kin call the platform's math library, and glibc picks one of several
//! versions at run time by the processor's features (an FMA one, an SSE2 one) and changes them
//! between releases: the same run could give different bits on another x86-64 machine, and a
//! chaotic flock diverges from the first differing bit. The engine computes every elementary
//! function here instead, with the `libm` crate (a pure Rust port of musl's): plain IEEE
//! arithmetic, which baseline x86-64 code performs identically on every processor. `sqrt` and
//! the operators are exact IEEE operations already; `frame::atan2` and `frame::tan_quarter`
//! are the engine's own. Rhai's math functions are replaced by these too (`script::math`).
//! `clippy.toml` refuses the platform's versions in the code. glam's rotations and angles
//! (`angle_between`, `from_rotation_y`, …) call the platform's library: none is used. (glam's
//! `libm` feature would route them here, but also its `sqrt`, which `libm` computes with an
//! instruction the compiler cannot see through: the kin kernel's four-lane square roots become
//! four scalar ones.)

/// `x.sin()`.
#[inline]
pub fn sin(x: f32) -> f32 {
    libm::sinf(x)
}

/// `x.cos()`.
#[inline]
pub fn cos(x: f32) -> f32 {
    libm::cosf(x)
}

/// `x.sin_cos()`.
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    libm::sincosf(x)
}

/// `x.tan()`.
#[inline]
pub fn tan(x: f32) -> f32 {
    libm::tanf(x)
}

/// `x.asin()`.
#[inline]
pub fn asin(x: f32) -> f32 {
    libm::asinf(x)
}

/// `x.acos()`.
#[inline]
pub fn acos(x: f32) -> f32 {
    libm::acosf(x)
}

/// `x.atan()`.
#[inline]
pub fn atan(x: f32) -> f32 {
    libm::atanf(x)
}

/// `x.sinh()`.
#[inline]
pub fn sinh(x: f32) -> f32 {
    libm::sinhf(x)
}

/// `x.cosh()`.
#[inline]
pub fn cosh(x: f32) -> f32 {
    libm::coshf(x)
}

/// `x.tanh()`.
#[inline]
pub fn tanh(x: f32) -> f32 {
    libm::tanhf(x)
}

/// `x.asinh()`.
#[inline]
pub fn asinh(x: f32) -> f32 {
    libm::asinhf(x)
}

/// `x.acosh()`.
#[inline]
pub fn acosh(x: f32) -> f32 {
    libm::acoshf(x)
}

/// `x.atanh()`.
#[inline]
pub fn atanh(x: f32) -> f32 {
    libm::atanhf(x)
}

/// `x.log10()`.
#[inline]
pub fn log10(x: f32) -> f32 {
    libm::log10f(x)
}

/// `x.exp()`.
#[inline]
pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}

/// `x.ln()`.
#[inline]
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}

/// `x.powf(y)`.
#[inline]
pub fn powf(x: f32, y: f32) -> f32 {
    libm::powf(x, y)
}

/// `x.hypot(y)`.
#[inline]
pub fn hypot(x: f32, y: f32) -> f32 {
    libm::hypotf(x, y)
}

/// `x.cbrt()`.
#[inline]
pub fn cbrt(x: f32) -> f32 {
    libm::cbrtf(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_6, PI};

    #[test]
    fn hand_computed_values() {
        assert_eq!(sin(0.0), 0.0);
        assert!((sin(FRAC_PI_6) - 0.5).abs() < 1e-7);
        assert!((cos(PI / 3.0) - 0.5).abs() < 1e-7);
        assert!(sin_cos(FRAC_PI_2).1.abs() < 1e-7);
        assert!((tan(PI / 4.0) - 1.0).abs() < 1e-7);
        assert!((asin(0.5) - FRAC_PI_6).abs() < 1e-7);
        assert!((acos(0.5) - PI / 3.0).abs() < 1e-7);
        assert!((atan(1.0) - PI / 4.0).abs() < 1e-7);
        assert_eq!(exp(0.0), 1.0);
        assert!((exp(1.0) - std::f32::consts::E).abs() < 1e-6);
        assert_eq!(ln(1.0), 0.0);
        assert!((ln(std::f32::consts::E) - 1.0).abs() < 1e-7);
        assert_eq!(powf(2.0, 10.0), 1024.0);
        assert_eq!(hypot(3.0, 4.0), 5.0);
        assert_eq!(cbrt(27.0), 3.0);
    }

    /// Each function's bits at a few arguments, as `libm` 0.2.16 gives them. A run's bits
    /// depend on these: if an upgrade changes one, recorded runs no longer rerun bit for bit,
    /// and that must be a decision, not an accident.
    #[test]
    fn the_bits_are_those_runs_were_recorded_with() {
        // 2,000 arguments over ±40: enough that another implementation, even one as close to
        // correctly rounded, differs somewhere.
        let mut bits = Vec::new();
        for k in 0..2000 {
            let x = (k as f32 - 1000.0) * 0.04 + 0.013;
            let (s, c) = sin_cos(x);
            bits.extend([sin(x), cos(x), s, c, tan(x), atan(x), exp(x * 0.5)]);
            bits.extend([
                asin(x / 40.0),
                acos(x / 40.0),
                ln(x.abs()),
                powf(x.abs(), 1.7),
            ]);
            bits.extend([
                hypot(x, 1.5),
                cbrt(x),
                sinh(x * 0.1),
                cosh(x * 0.1),
                tanh(x),
            ]);
            bits.extend([
                asinh(x),
                acosh(x.abs() + 1.0),
                atanh(x / 40.0),
                log10(x.abs()),
            ]);
        }
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in bits {
            for byte in b.to_bits().to_le_bytes() {
                h = (h ^ byte as u64).wrapping_mul(0x0100_0000_01b3);
            }
        }
        assert_eq!(
            h, 15_694_196_137_965_586_590,
            "the elementary functions' bits changed"
        );
    }
}
