//! Pairs of agents on a sampled tick: coincident agents (any species) and same-species
//! neighbors that overlap, found through a uniform grid hash (sorted cell keys, one binary
//! gallop forward from row to row, only through the cells after a point's own), so a sample
//! costs O(N·k) rather than O(N²); the points are counted in parallel.

use super::{COINCIDENT_DISTANCE, NEIGHBOR_LENGTHS, OVERLAP_WIDTH};
use crate::world::Agent;
use glam::Vec3;
use rayon::prelude::*;

/// Cell coordinates are kept within ±2²⁰ so that three fit in a key.
const HALF_RANGE: i64 = 1 << 20;
/// Bits per coordinate in a key.
const BITS: u32 = 21;

/// What one sample found.
#[derive(Debug, Clone, Default)]
pub(super) struct PairCounts {
    /// Pairs closer than [`COINCIDENT_DISTANCE`].
    pub coincident: u64,
    /// One agent of a coincident pair.
    pub coincident_agent: Option<u32>,
    /// Per species: neighbor pairs.
    pub neighbors: Vec<u64>,
    /// Per species: overlapping neighbor pairs.
    pub overlapping: Vec<u64>,
    /// Per species: one agent of an overlapping pair.
    pub overlap_agent: Vec<Option<u32>>,
}

impl PairCounts {
    /// Empty counts for `species` species.
    pub fn new(species: usize) -> Self {
        PairCounts {
            coincident: 0,
            coincident_agent: None,
            neighbors: vec![0; species],
            overlapping: vec![0; species],
            overlap_agent: vec![None; species],
        }
    }

    fn clear(&mut self) {
        self.coincident = 0;
        self.coincident_agent = None;
        self.neighbors.fill(0);
        self.overlapping.fill(0);
        self.overlap_agent.fill(None);
    }
}

/// An agent as the pair pass reads it, kept in cell order so that the agents of a row of
/// cells lie next to each other in memory.
#[derive(Debug, Clone, Copy)]
struct Point {
    key: u64,
    pos: Vec3,
    length: f32,
    width: f32,
    species: u16,
    id: u32,
}

/// The grid, its buffers kept from one sample to the next.
#[derive(Debug, Clone, Default)]
pub(super) struct PairGrid {
    /// The agents, sorted by (cell key, id).
    points: Vec<Point>,
    /// Per species: the longest body and the agent count this sample.
    longest: Vec<f32>,
    counts: Vec<u32>,
}

fn coord(x: f32, inv_cell: f32) -> i64 {
    ((x * inv_cell).floor() as i64).clamp(-HALF_RANGE, HALF_RANGE - 1)
}

fn key(x: i64, y: i64, z: i64) -> u64 {
    let c = |v: i64| (v + HALF_RANGE).clamp(0, (1 << BITS) - 1) as u64;
    c(x) << (2 * BITS) | c(y) << BITS | c(z)
}

/// The first index at or after `from` whose key is ≥ `target` (keys sorted): doubling steps,
/// then a binary search in the last step, so a near target costs a comparison or two.
fn gallop(points: &[Point], from: usize, target: u64) -> usize {
    let mut lo = from;
    let mut step = 1;
    while lo + step < points.len() && points[lo + step].key < target {
        lo += step;
        step *= 2;
    }
    if lo >= points.len() || points[lo].key >= target {
        return lo;
    }
    let hi = (lo + step).min(points.len());
    lo + 1 + points[lo + 1..hi].partition_point(|p| p.key < target)
}

impl PairGrid {
    /// Counts the pairs among `agents` into `out` (resized to the species seen if needed).
    pub fn sample(&mut self, agents: &[Agent], out: &mut PairCounts) {
        // One pass over the agents' records: what the pairs need of them, and per species the
        // longest body and the count.
        self.points.clear();
        self.longest.clear();
        self.counts.clear();
        for a in agents.iter().filter(|a| a.pos.is_finite()) {
            let s = a.species.0 as usize;
            if self.longest.len() <= s {
                self.longest.resize(s + 1, 0.0);
                self.counts.resize(s + 1, 0);
            }
            let length = a.size.z.abs();
            self.longest[s] = self.longest[s].max(length);
            self.counts[s] += 1;
            self.points.push(Point {
                key: 0,
                pos: a.pos,
                length,
                width: a.size.x.abs(),
                species: a.species.0,
                id: a.id.0,
            });
        }
        let n_species = self.longest.len().max(out.neighbors.len());
        self.longest.resize(n_species, 0.0);
        if out.neighbors.len() < n_species {
            *out = PairCounts::new(n_species);
        }
        out.clear();
        // Cells sized for the most numerous species' neighbor radius: other species look a few
        // more cells out.
        let Some(common) =
            (0..self.counts.len()).max_by_key(|&s| (self.counts[s], std::cmp::Reverse(s)))
        else {
            return;
        };
        let cell = (NEIGHBOR_LENGTHS * self.longest[common]).max(0.05);
        let inv = 1.0 / cell;
        for p in &mut self.points {
            p.key = key(
                coord(p.pos.x, inv),
                coord(p.pos.y, inv),
                coord(p.pos.z, inv),
            );
        }
        self.points.sort_unstable_by_key(|p| (p.key, p.id));
        // Each point's pairs with the points after it, in parallel; the sums do not depend on
        // the split, and the agent kept for a spot is the lowest id, whatever the order.
        let points = &self.points;
        let longest = &self.longest;
        let counts = (0..points.len())
            .into_par_iter()
            .with_min_len(64)
            .fold(
                || PairCounts::new(n_species),
                |mut acc, i| {
                    pairs_after(points, i, inv, longest, &mut acc);
                    acc
                },
            )
            .reduce(
                || PairCounts::new(n_species),
                |mut a, b| {
                    a.merge(&b);
                    a
                },
            );
        *out = counts;
    }
}

/// The lower of two optional ids.
fn lowest(a: Option<u32>, b: Option<u32>) -> Option<u32> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        _ => a.or(b),
    }
}

impl PairCounts {
    fn merge(&mut self, other: &PairCounts) {
        self.coincident += other.coincident;
        self.coincident_agent = lowest(self.coincident_agent, other.coincident_agent);
        for s in 0..self.neighbors.len() {
            self.neighbors[s] += other.neighbors[s];
            self.overlapping[s] += other.overlapping[s];
            self.overlap_agent[s] = lowest(self.overlap_agent[s], other.overlap_agent[s]);
        }
    }
}

/// Counts the pairs of point `i` with the points after it (each pair once).
fn pairs_after(points: &[Point], i: usize, inv: f32, longest: &[f32], out: &mut PairCounts) {
    let a = &points[i];
    let s = a.species as usize;
    let coincident2 = COINCIDENT_DISTANCE * COINCIDENT_DISTANCE;
    let reach = (NEIGHBOR_LENGTHS * longest[s]).max(COINCIDENT_DISTANCE);
    let rings = (reach * inv).ceil().max(1.0) as i64;
    let (x, y, z) = (
        coord(a.pos.x, inv),
        coord(a.pos.y, inv),
        coord(a.pos.z, inv),
    );
    // Only the cells at or after the point's own in key order can hold points after it: the
    // rows from its own on in its column of cells, then every row of the columns after.
    let mut at = i + 1;
    for dx in 0..=rings {
        let first_row = if dx == 0 { 0 } else { -rings };
        for dy in first_row..=rings {
            let lo = key(x + dx, y + dy, z - rings);
            let hi = key(x + dx, y + dy, z + rings);
            at = gallop(points, at, lo);
            for b in &points[at..] {
                if b.key > hi {
                    break;
                }
                let d2 = (b.pos - a.pos).length_squared();
                let low = Some(a.id.min(b.id));
                if d2 < coincident2 {
                    out.coincident += 1;
                    out.coincident_agent = lowest(out.coincident_agent, low);
                }
                if b.species == a.species {
                    let near = NEIGHBOR_LENGTHS * 0.5 * (a.length + b.length);
                    if d2 < near * near {
                        out.neighbors[s] += 1;
                        let overlap = OVERLAP_WIDTH * 0.5 * (a.width + b.width);
                        if d2 < overlap * overlap {
                            out.overlapping[s] += 1;
                            out.overlap_agent[s] = lowest(out.overlap_agent[s], low);
                        }
                    }
                }
            }
        }
    }
}

/// Brute-force counts, to check the grid against.
#[cfg(test)]
pub(super) fn brute_force(agents: &[Agent], species: usize) -> (u64, Vec<u64>, Vec<u64>) {
    let mut coincident = 0;
    let mut neighbors = vec![0; species];
    let mut overlapping = vec![0; species];
    for (i, a) in agents.iter().enumerate() {
        for b in &agents[i + 1..] {
            let d = (b.pos - a.pos).length();
            if d < COINCIDENT_DISTANCE {
                coincident += 1;
            }
            if a.species == b.species {
                let s = a.species.0 as usize;
                if d < NEIGHBOR_LENGTHS * 0.5 * (a.size.z + b.size.z) {
                    neighbors[s] += 1;
                    if d < OVERLAP_WIDTH * 0.5 * (a.size.x + b.size.x) {
                        overlapping[s] += 1;
                    }
                }
            }
        }
    }
    (coincident, neighbors, overlapping)
}
