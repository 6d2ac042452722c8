//! Procedural height fields and the small deterministic generator behind them, for tests,
//! benchmarks and leader draws (seed 004: "a leader is chosen … at random").
//!
//! Not a tick stage. Everything here is a pure function of its seed, so a scenario that names a
//! seed gets the same ground and the same leader on every machine.

use super::Terrain;
use glam::Vec2;

/// SplitMix64: a tiny, fast, well-mixed 64-bit generator (Steele, Lea & Flood 2014).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64 { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix(self.state)
    }

    /// A uniform value in `[0, 1)`.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniform index in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() as u128 * n as u128) >> 64) as usize
    }
}

fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Hash of a lattice point to `[0, 1)`.
fn lattice_value(seed: u64, x: i64, z: i64) -> f32 {
    let h = mix(seed ^ mix((x as u64).wrapping_mul(0x9E37_79B9) ^ (z as u64).rotate_left(32)));
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// Smoothly interpolated value noise at `(x, z)` (lattice spacing 1), in `[0, 1)`.
fn value_noise(seed: u64, x: f32, z: f32) -> f32 {
    let (x0, z0) = (x.floor(), z.floor());
    let (tx, tz) = (x - x0, z - z0);
    let (sx, sz) = (tx * tx * (3.0 - 2.0 * tx), tz * tz * (3.0 - 2.0 * tz));
    let (i, j) = (x0 as i64, z0 as i64);
    let a = lattice_value(seed, i, j);
    let b = lattice_value(seed, i + 1, j);
    let c = lattice_value(seed, i, j + 1);
    let d = lattice_value(seed, i + 1, j + 1);
    let top = a + (b - a) * sx;
    let bottom = c + (d - c) * sx;
    top + (bottom - top) * sz
}

/// Fractal (fBm) heights in `[0, amplitude)` for a `cols × rows` grid: `octaves` layers of value
/// noise, the first with features about `feature_cells` cells across, each next one half as big
/// and half as high.
pub fn fractal_heights(
    cols: usize,
    rows: usize,
    seed: u64,
    feature_cells: f32,
    octaves: u32,
    amplitude: f32,
) -> Vec<f32> {
    let mut norm = 0.0;
    let mut amp = 1.0;
    for _ in 0..octaves {
        norm += amp;
        amp *= 0.5;
    }
    let mut out = Vec::with_capacity(cols * rows);
    for r in 0..rows {
        for c in 0..cols {
            let (mut sum, mut amp, mut freq) = (0.0, 1.0, 1.0 / feature_cells);
            for o in 0..octaves {
                sum += amp
                    * value_noise(
                        seed.wrapping_add(o as u64),
                        c as f32 * freq,
                        r as f32 * freq,
                    );
                amp *= 0.5;
                freq *= 2.0;
            }
            out.push(amplitude * sum / norm);
        }
    }
    out
}

impl Terrain {
    /// Rolling hills: fractal heights up to `relief` world units on a `cols × rows` grid with its
    /// north-west corner at the world origin.
    pub fn procedural(cols: usize, rows: usize, cell_size: f32, relief: f32, seed: u64) -> Terrain {
        let h = fractal_heights(cols, rows, seed, 48.0, 5, relief);
        Terrain::from_heights(cols, rows, cell_size, Vec2::ZERO, h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix_is_deterministic_and_spread() {
        let mut a = SplitMix64::new(7);
        let mut b = SplitMix64::new(7);
        let xs: Vec<u64> = (0..4).map(|_| a.next_u64()).collect();
        let ys: Vec<u64> = (0..4).map(|_| b.next_u64()).collect();
        assert_eq!(xs, ys);
        // Reference value of SplitMix64 seeded with 0.
        assert_eq!(SplitMix64::new(0).next_u64(), 0xE220_A839_7B1D_CDAF);
        let mut g = SplitMix64::new(1);
        let mut counts = [0; 4];
        for _ in 0..4000 {
            counts[g.below(4)] += 1;
        }
        assert!(
            counts.iter().all(|&n| (850..1150).contains(&n)),
            "{counts:?}"
        );
        assert!((0..1000).all(|_| (0.0..1.0).contains(&g.next_f32())));
    }

    #[test]
    fn fractal_heights_are_bounded_and_repeatable() {
        let a = fractal_heights(32, 16, 3, 8.0, 4, 50.0);
        assert_eq!(a, fractal_heights(32, 16, 3, 8.0, 4, 50.0));
        assert_ne!(a, fractal_heights(32, 16, 4, 8.0, 4, 50.0));
        assert!(a.iter().all(|h| (0.0..50.0).contains(h)));
    }
}
