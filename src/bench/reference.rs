//! The `reference` workload: the smallest fast program that does the `boids` workload's work, so
//! that every boids figure can be read against a floor. The same world (a flat square at
//! [`BOIDS_DENSITY`], vision radius 10, constant speed 10, `dt` 0.05), the same rules as
//! `boid.ron` (separation within 3, alignment, cohesion, containment), written as one would by
//! hand: positions and velocities as structure of arrays, a counting-sort grid of radius-sized
//! cells rebuilt every tick, a neighbour loop over contiguous sorted runs in lanes of four that
//! the compiler turns into SSE (baseline x86-64, no CPU-specific code), agents split over the
//! rayon pool in fixed chunks. No decision, no drives, no recording: what it leaves out is what
//! the engine's generality costs. Not a tick stage; reads nothing of the engine.

use super::{Sample, BOIDS_DENSITY, DT, SEED};
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
/// Lanes per neighbour step.
const LANES: usize = 4;

/// A flock in structure-of-arrays form with its grid.
pub struct Flock {
    side: f32,
    cells: usize,
    px: Vec<f32>,
    pz: Vec<f32>,
    vx: Vec<f32>,
    vz: Vec<f32>,
    /// Grid: the first sorted index of each cell (`cells² + 1` entries).
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
            px,
            pz,
            vx,
            vz,
            start: vec![0; cells * cells + 1],
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
        let f = self.cells as f32 / self.side;
        let c = ((x * f) as usize).min(self.cells - 1);
        let r = ((z * f) as usize).min(self.cells - 1);
        (c, r)
    }

    /// Counting sort of the agents by cell into the sorted copies.
    fn index(&mut self) {
        let n = self.len();
        self.start.iter_mut().for_each(|s| *s = 0);
        for i in 0..n {
            let (c, r) = self.cell(self.px[i], self.pz[i]);
            let k = (r * self.cells + c) as u32;
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
        let mut acc = [[0.0f32; LANES]; 7];
        for rr in r.saturating_sub(1)..=(r + 1).min(self.cells - 1) {
            let row = rr * self.cells;
            let lo = self.start[row + c.saturating_sub(1)] as usize;
            let hi = self.start[row + (c + 1).min(self.cells - 1) + 1] as usize;
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
        let total = |k: usize| acc[k].iter().sum::<f32>();
        // The agent itself is in the sums (distance 0): take it out.
        let count = total(0) - 1.0;
        let (mut ax, mut az) = (SEP_K * total(5), SEP_K * total(6));
        if count > 0.0 {
            let (cx, cz) = ((total(1) - x) / count - x, (total(2) - z) / count - z);
            let (avx, avz) = (
                (total(3) - self.vx[i]) / count,
                (total(4) - self.vz[i]) / count,
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

/// Adds the neighbours among one sorted run to `acc` (count, Σx, Σz, Σvx, Σvz, separation x, z),
/// four at a time; the agent itself adds to the first five only (separation skips distance 0).
#[inline]
fn sums(
    acc: &mut [[f32; LANES]; 7],
    x: f32,
    z: f32,
    sx: &[f32],
    sz: &[f32],
    svx: &[f32],
    svz: &[f32],
) {
    let r2 = RADIUS * RADIUS;
    let s2 = SEP_RADIUS * SEP_RADIUS;
    let n = sx.len();
    let whole = n - n % LANES;
    let mut j = 0;
    while j < whole {
        for l in 0..LANES {
            lane(
                acc,
                l,
                x,
                z,
                sx[j + l],
                sz[j + l],
                svx[j + l],
                svz[j + l],
                r2,
                s2,
            );
        }
        j += LANES;
    }
    for k in whole..n {
        lane(acc, 0, x, z, sx[k], sz[k], svx[k], svz[k], r2, s2);
    }
}

/// One neighbour into lane `l`, branch-free: masks select what counts.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn lane(
    acc: &mut [[f32; LANES]; 7],
    l: usize,
    x: f32,
    z: f32,
    ox: f32,
    oz: f32,
    ovx: f32,
    ovz: f32,
    r2: f32,
    s2: f32,
) {
    let (dx, dz) = (x - ox, z - oz);
    let d2 = dx * dx + dz * dz;
    let within = if d2 < r2 { 1.0 } else { 0.0 };
    let close = if d2 < s2 && d2 > 0.0 { 1.0 / d2 } else { 0.0 };
    acc[0][l] += within;
    acc[1][l] += within * ox;
    acc[2][l] += within * oz;
    acc[3][l] += within * ovx;
    acc[4][l] += within * ovz;
    acc[5][l] += close * dx;
    acc[6][l] += close * dz;
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
