//! Pairs of agents on a sampled tick: coincident agents (any species) and same-species
//! neighbors that overlap, found through a uniform grid hash (sorted cell keys, one binary
//! search per row of cells), so a sample costs O(N·k) rather than O(N²).

use super::{COINCIDENT_DISTANCE, NEIGHBOR_LENGTHS, OVERLAP_WIDTH};
use crate::world::Agent;

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

/// The grid, its buffers kept from one sample to the next.
#[derive(Debug, Clone, Default)]
pub(super) struct PairGrid {
    /// (cell key, agent index), sorted.
    keys: Vec<(u64, u32)>,
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

impl PairGrid {
    /// Counts the pairs among `agents` into `out` (resized to the species seen if needed).
    pub fn sample(&mut self, agents: &[Agent], out: &mut PairCounts) {
        let n_species = agents
            .iter()
            .map(|a| a.species.0 as usize + 1)
            .max()
            .unwrap_or(0)
            .max(out.neighbors.len());
        if out.neighbors.len() < n_species {
            *out = PairCounts::new(n_species);
        }
        out.clear();
        self.longest.clear();
        self.longest.resize(n_species, 0.0);
        self.counts.clear();
        self.counts.resize(n_species, 0);
        for a in agents {
            let s = a.species.0 as usize;
            self.longest[s] = self.longest[s].max(a.size.z.abs());
            self.counts[s] += 1;
        }
        // Cells sized for the most numerous species' neighbor radius: other species look a few
        // more cells out.
        let Some(common) = (0..n_species).max_by_key(|&s| (self.counts[s], std::cmp::Reverse(s)))
        else {
            return;
        };
        let cell = (NEIGHBOR_LENGTHS * self.longest[common]).max(0.05);
        let inv = 1.0 / cell;
        self.keys.clear();
        for (i, a) in agents.iter().enumerate() {
            if a.pos.is_finite() {
                let p = a.pos;
                self.keys.push((
                    key(coord(p.x, inv), coord(p.y, inv), coord(p.z, inv)),
                    i as u32,
                ));
            }
        }
        self.keys.sort_unstable();
        let coincident2 = COINCIDENT_DISTANCE * COINCIDENT_DISTANCE;
        for &(_, i) in &self.keys {
            let a = &agents[i as usize];
            let s = a.species.0 as usize;
            let reach = (NEIGHBOR_LENGTHS * self.longest[s]).max(COINCIDENT_DISTANCE);
            let rings = (reach * inv).ceil().max(1.0) as i64;
            let (x, y, z) = (
                coord(a.pos.x, inv),
                coord(a.pos.y, inv),
                coord(a.pos.z, inv),
            );
            for dx in -rings..=rings {
                for dy in -rings..=rings {
                    let lo = key(x + dx, y + dy, z - rings);
                    let hi = key(x + dx, y + dy, z + rings);
                    let start = self.keys.partition_point(|e| e.0 < lo);
                    for &(k, j) in &self.keys[start..] {
                        if k > hi {
                            break;
                        }
                        // Each pair once, from its lower index.
                        if j <= i {
                            continue;
                        }
                        let b = &agents[j as usize];
                        let d2 = (b.pos - a.pos).length_squared();
                        if d2 < coincident2 {
                            out.coincident += 1;
                            out.coincident_agent.get_or_insert(a.id.0);
                        }
                        if b.species == a.species {
                            let near = NEIGHBOR_LENGTHS * 0.5 * (a.size.z + b.size.z).abs();
                            if d2 < near * near {
                                out.neighbors[s] += 1;
                                let overlap = OVERLAP_WIDTH * 0.5 * (a.size.x + b.size.x).abs();
                                if d2 < overlap * overlap {
                                    out.overlapping[s] += 1;
                                    out.overlap_agent[s].get_or_insert(a.id.0);
                                }
                            }
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
