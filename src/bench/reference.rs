//! The `reference` workload: the smallest fast program that does the `boids` workload's work, so
//! that every boids figure can be read against a floor. The same world (a flat square at
//! [`BOIDS_DENSITY`], vision radius 10, constant speed 10, `dt` 0.05), the same rules as
//! `boid.ron` (separation within 3, alignment, cohesion, containment), written as one would by
//! hand: positions and velocities as structure of arrays, a counting-sort grid rebuilt every
//! tick (rows a radius high, cells a quarter radius wide, as the engine's grid), a neighbour
//! loop over the three rows' contiguous sorted runs in explicit 4-lane vectors (glam's `Vec4`,
//! SSE on baseline x86-64, no CPU-specific code), agents split over the
//! rayon pool in fixed chunks. No decision, no drives, no recording: what it leaves out is what
//! the engine's generality costs. Not a tick stage; reads nothing of the engine.

use super::{Sample, BOIDS_DENSITY, DT, SEED};
use glam::Vec4;
use rayon::prelude::*;
use std::time::Instant;

/// Vision radius (as `boid.ron`).
const RADIUS: f32 = 10.0;
/// Separation radius and gain, alignment and cohesion gains (as `boid.ron`).
const SEP_RADIUS: f32 = 3.0;
const SEP_K: f32 = 3.0;
const ALIGN_K: f32 = 0.05;
const COHESION_K: f32 = 0.02;
/// Constant speed (`min_speed = max_speed = 10`).
const SPEED: f32 = 10.0;
/// Distance from a wall where containment starts turning a boid back.
const MARGIN: f32 = 1.0;
/// Agents per parallel work item: small enough for either thread to take the rest.
const CHUNK: usize = 256;
/// Cells per radius along x: a row's run then ends within a narrow cell of the radius.
const SPLIT: usize = 4;
/// Lanes per neighbour step.
const LANES: usize = 4;
/// Where the padding of a run's last, partial step lies: farther than any radius.
const FAR: f32 = 1e30;

/// A flock in structure-of-arrays form with its grid.
pub struct Flock {
    side: f32,
    /// Cells along z (rows) and along x: rows are a radius high, cells [`SPLIT`] times narrower.
    cells: usize,
    cols: usize,
    px: Vec<f32>,
    pz: Vec<f32>,
    vx: Vec<f32>,
    vz: Vec<f32>,
    /// Grid: the first sorted index of each cell (`cells · cols + 1` entries), x fastest.
    start: Vec<u32>,
    /// Sorted copies (by cell) of positions and velocities.
    sx: Vec<f32>,
    sz: Vec<f32>,
    svx: Vec<f32>,
    svz: Vec<f32>,
    cell_of: Vec<u32>,
    /// Kin within the radius of each agent at the last step.
    seen: Vec<u32>,
    /// Each agent's new state, written in parallel, then copied back.
    out: Vec<(f32, f32, f32, f32, u32)>,
}

/// A small deterministic generator (SplitMix64) for the spawn.
fn next(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

impl Flock {
    /// `n` boids spread over the square of the `boids` workload, random headings.
    pub fn new(n: usize) -> Flock {
        let side = (n as f32 / BOIDS_DENSITY).sqrt().max(10.0);
        let cells = ((side / RADIUS).floor() as usize).max(1);
        let cols = ((side * SPLIT as f32 / RADIUS).floor() as usize).max(1);
        let mut s = SEED;
        let (mut px, mut pz, mut vx, mut vz) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for _ in 0..n {
            px.push(next(&mut s) * side);
            pz.push(next(&mut s) * side);
            let a = next(&mut s) * std::f32::consts::TAU;
            vx.push(SPEED * crate::math::cos(a));
            vz.push(SPEED * crate::math::sin(a));
        }
        Flock {
            side,
            cells,
            cols,
            px,
            pz,
            vx,
            vz,
            start: vec![0; cells * cols + 1],
            sx: vec![0.0; n],
            sz: vec![0.0; n],
            svx: vec![0.0; n],
            svz: vec![0.0; n],
            cell_of: vec![0; n],
            seen: vec![0; n],
            out: vec![(0.0, 0.0, 0.0, 0.0, 0); n],
        }
    }

    /// Agents.
    pub fn len(&self) -> usize {
        self.px.len()
    }

    /// Whether the flock is empty.
    pub fn is_empty(&self) -> bool {
        self.px.is_empty()
    }

    /// Mean kin within the radius at the last step.
    pub fn mean_seen(&self) -> f32 {
        self.seen.iter().map(|&k| k as u64).sum::<u64>() as f32 / self.len().max(1) as f32
    }

    fn cell(&self, x: f32, z: f32) -> (usize, usize) {
        let c = ((x * self.cols as f32 / self.side) as usize).min(self.cols - 1);
        let r = ((z * self.cells as f32 / self.side) as usize).min(self.cells - 1);
        (c, r)
    }

    /// Counting sort of the agents by cell into the sorted copies.
    fn index(&mut self) {
        let n = self.len();
        self.start.iter_mut().for_each(|s| *s = 0);
        for i in 0..n {
            let (c, r) = self.cell(self.px[i], self.pz[i]);
            let k = (r * self.cols + c) as u32;
            self.cell_of[i] = k;
            self.start[k as usize + 1] += 1;
        }
        for k in 1..self.start.len() {
            self.start[k] += self.start[k - 1];
        }
        let mut fill = self.start.clone();
        for i in 0..n {
            let k = self.cell_of[i] as usize;
            let at = fill[k] as usize;
            fill[k] += 1;
            self.sx[at] = self.px[i];
            self.sz[at] = self.pz[i];
            self.svx[at] = self.vx[i];
            self.svz[at] = self.vz[i];
        }
    }

    /// One tick: index, then every agent's neighbour sums and move, in parallel chunks.
    pub fn step(&mut self) {
        self.index();
        let mut out = std::mem::take(&mut self.out);
        let me = &*self;
        out.par_iter_mut()
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(i, o)| *o = me.update(i));
        for (i, &(x, z, vx, vz, k)) in out.iter().enumerate() {
            self.px[i] = x;
            self.pz[i] = z;
            self.vx[i] = vx;
            self.vz[i] = vz;
            self.seen[i] = k;
        }
        self.out = out;
    }

    /// Agent `i`'s new position, velocity and kin count.
    fn update(&self, i: usize) -> (f32, f32, f32, f32, u32) {
        let (x, z) = (self.px[i], self.pz[i]);
        let (c, r) = self.cell(x, z);
        let mut acc = ACC_ZERO;
        for rr in r.saturating_sub(1)..=(r + 1).min(self.cells - 1) {
            let row = rr * self.cols;
            let lo = self.start[row + c.saturating_sub(SPLIT)] as usize;
            let hi = self.start[row + (c + SPLIT).min(self.cols - 1) + 1] as usize;
            sums(
                &mut acc,
                x,
                z,
                &self.sx[lo..hi],
                &self.sz[lo..hi],
                &self.svx[lo..hi],
                &self.svz[lo..hi],
            );
        }
        let total = |v: Vec4| v.element_sum();
        // The agent itself is in the sums (distance 0): take it out.
        let count = total(acc.n) - 1.0;
        let (mut ax, mut az) = (SEP_K * total(acc.sx), SEP_K * total(acc.sz));
        if count > 0.0 {
            let (cx, cz) = (
                (total(acc.px) - x) / count - x,
                (total(acc.pz) - z) / count - z,
            );
            let (avx, avz) = (
                (total(acc.vx) - self.vx[i]) / count,
                (total(acc.vz) - self.vz[i]) / count,
            );
            ax += ALIGN_K * (avx - self.vx[i]) + COHESION_K * cx;
            az += ALIGN_K * (avz - self.vz[i]) + COHESION_K * cz;
        }
        // Containment: straight back in near a wall.
        let wall = |p: f32| {
            if p < MARGIN {
                SPEED
            } else if p > self.side - MARGIN {
                -SPEED
            } else {
                0.0
            }
        };
        ax += wall(x);
        az += wall(z);
        let (mut vx, mut vz) = (self.vx[i] + ax * DT, self.vz[i] + az * DT);
        let speed = (vx * vx + vz * vz).sqrt().max(1e-6);
        vx *= SPEED / speed;
        vz *= SPEED / speed;
        let nx = (x + vx * DT).clamp(0.0, self.side);
        let nz = (z + vz * DT).clamp(0.0, self.side);
        (nx, nz, vx, vz, count as u32)
    }
}

/// The running sums of one agent, four lanes each: count, Σx, Σz, Σvx, Σvz, separation x, z.
#[derive(Clone, Copy)]
struct Acc {
    n: Vec4,
    px: Vec4,
    pz: Vec4,
    vx: Vec4,
    vz: Vec4,
    sx: Vec4,
    sz: Vec4,
}

const ACC_ZERO: Acc = Acc {
    n: Vec4::ZERO,
    px: Vec4::ZERO,
    pz: Vec4::ZERO,
    vx: Vec4::ZERO,
    vz: Vec4::ZERO,
    sx: Vec4::ZERO,
    sz: Vec4::ZERO,
};

/// Adds the neighbours among one sorted run to `acc`, four at a time, branch-free (masks select
/// what counts); the agent itself adds to the first five sums only (separation skips distance
/// 0). The run's last, partial step reads copies padded with far-away entries.
#[inline]
fn sums(acc: &mut Acc, x: f32, z: f32, sx: &[f32], sz: &[f32], svx: &[f32], svz: &[f32]) {
    let (cx, cz) = (Vec4::splat(x), Vec4::splat(z));
    let r2 = Vec4::splat(RADIUS * RADIUS);
    let s2 = Vec4::splat(SEP_RADIUS * SEP_RADIUS);
    let mut a = *acc;
    let mut step = |ox: Vec4, oz: Vec4, ovx: Vec4, ovz: Vec4| {
        let (dx, dz) = (cx - ox, cz - oz);
        let d2 = dx * dx + dz * dz;
        let within = d2.cmplt(r2);
        let close = d2.cmplt(s2) & d2.cmpgt(Vec4::ZERO);
        let pick = |v: Vec4| Vec4::select(within, v, Vec4::ZERO);
        a.n += pick(Vec4::ONE);
        a.px += pick(ox);
        a.pz += pick(oz);
        a.vx += pick(ovx);
        a.vz += pick(ovz);
        let inv = Vec4::select(close, d2.recip(), Vec4::ZERO);
        a.sx += inv * dx;
        a.sz += inv * dz;
    };
    let n = sx.len();
    let whole = n - n % LANES;
    let v4 = |c: &[f32], k: usize| Vec4::from_slice(&c[k..k + LANES]);
    let mut k = 0;
    while k < whole {
        step(v4(sx, k), v4(sz, k), v4(svx, k), v4(svz, k));
        k += LANES;
    }
    if k < n {
        let pad = |c: &[f32], far: f32| {
            let mut t = [far; LANES];
            t[..n - k].copy_from_slice(&c[k..]);
            Vec4::from_array(t)
        };
        step(pad(sx, FAR), pad(sz, FAR), pad(svx, 0.0), pad(svz, 0.0));
    }
    *acc = a;
}

/// Times `ticks` ticks of a fresh `n`-boid flock on the current rayon pool, after the same
/// warm-up as the engine's workloads.
pub fn measure(n: usize, ticks: u64) -> Sample {
    let base = super::memory().map(|m| m.0);
    let mut flock = Flock::new(n);
    for _ in 0..super::WARMUP_TICKS {
        flock.step();
    }
    let tracked = super::reset_peak_memory();
    let t0 = Instant::now();
    for _ in 0..ticks {
        flock.step();
    }
    let seconds = t0.elapsed().as_secs_f64();
    let bytes_per_agent = match (tracked, base, super::memory()) {
        (true, Some(b), Some((_, peak))) if n > 0 => Some(peak.saturating_sub(b) as f64 / n as f64),
        _ => None,
    };
    Sample {
        workload: "reference".into(),
        agents: n,
        ticks,
        seconds,
        updates: n as u64 * ticks,
        neighbors: flock.mean_seen(),
        bytes_per_agent,
        stages: None,
        note: None,
        steady: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute-force kin count of agent `i` (the agent itself excluded).
    fn brute(f: &Flock, i: usize) -> u32 {
        (0..f.len())
            .filter(|&j| {
                let (dx, dz) = (f.px[i] - f.px[j], f.pz[i] - f.pz[j]);
                j != i && dx * dx + dz * dz < RADIUS * RADIUS
            })
            .count() as u32
    }

    #[test]
    fn the_grid_finds_every_neighbour_within_the_radius() {
        let mut f = Flock::new(2_000);
        f.index();
        for i in (0..f.len()).step_by(37) {
            assert_eq!(f.update(i).4, brute(&f, i), "agent {i}");
        }
        // About 31 kin each at this density (π·10²·0.1), fewer at the walls.
        f.step();
        assert!((20.0..35.0).contains(&f.mean_seen()), "{}", f.mean_seen());
    }

    #[test]
    fn boids_keep_their_speed_and_stay_inside() {
        let mut f = Flock::new(500);
        for _ in 0..50 {
            f.step();
        }
        for i in 0..f.len() {
            let v = (f.vx[i] * f.vx[i] + f.vz[i] * f.vz[i]).sqrt();
            assert!((v - SPEED).abs() < 1e-3, "{v}");
            assert!((0.0..=f.side).contains(&f.px[i]) && (0.0..=f.side).contains(&f.pz[i]));
        }
    }

    #[test]
    fn the_same_flock_steps_the_same_on_any_pool() {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut f = Flock::new(3_000);
                for _ in 0..20 {
                    f.step();
                }
                (f.px.clone(), f.vz.clone())
            })
        };
        assert_eq!(run(1), run(2));
    }
}
