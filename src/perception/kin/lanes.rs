//! The kin kernel's lanes: every agent's position, heading and velocity in the agent grid's
//! order, one array per component, refilled once a tick for the fold ([`super::KinFold`]) to
//! read four candidates at a time.

use super::LANES;
use glam::{Vec3, Vec3A};
use rayon::prelude::*;

/// The neighbors' records in the agent grid's order, one array per component, padded with
/// [`LANES`] far-away entries so that a step may read past a row's last candidate.
#[derive(Debug, Clone, Default)]
pub struct KinLanes {
    /// Positions.
    pub pos: [Vec<f32>; 3],
    /// Forward unit vectors.
    pub heading: [Vec<f32>; 3],
    /// Velocities.
    pub vel: [Vec<f32>; 3],
    pub(super) len: usize,
    /// Whether the heading columns are filled (see [`KinLanes::fill`]).
    pub(super) headings: bool,
    /// Whether every record lies and moves in the plane y = 0 (positions, velocities and,
    /// where the heading lanes are filled, headings with a y of ±0): a perceiver in that
    /// plane then folds two components, not three (see [`super::KinFold`]'s fold).
    pub(super) flat: bool,
}

/// Position of the padding entries: every squared distance to it is infinite.
const FAR: f32 = 1e30;

impl KinLanes {
    /// Refills the lanes for `positions` (in grid order): `motion(k, &mut extra[k])` gives the
    /// heading and velocity of slot `k` (and may fill `extra[k]` on the way). Filled in
    /// parallel. Without `headings` the heading columns are left empty (12 bytes an agent):
    /// only a fold that sums headings reads them (see [`super::needs_headings`]).
    pub fn fill<T: Send>(
        &mut self,
        positions: &[Vec3A],
        extra: &mut [T],
        headings: bool,
        motion: impl Fn(usize, &mut T) -> (Vec3, Vec3) + Sync,
    ) {
        let n = positions.len().min(extra.len());
        self.len = n;
        self.headings = headings;
        for (c, v) in self.columns_mut().into_iter().enumerate() {
            if headings || !(3..6).contains(&c) {
                v.clear();
                v.resize(n + LANES, if c < 3 { FAR } else { 0.0 });
            } else {
                // Not kept either: a world that needed them once does not hold them for good.
                *v = Vec::new();
            }
        }
        // Slots per task: a 1,000-agent world splits it in four (its helper thread is awake).
        const CHUNK: usize = 256;
        let [px, py, pz] = &mut self.pos;
        let [hx, hy, hz] = &mut self.heading;
        let [vx, vy, vz] = &mut self.vel;
        fn chunks(c: &mut [f32], n: usize) -> rayon::slice::ChunksMut<'_, f32> {
            c[..n].par_chunks_mut(CHUNK)
        }
        let chunks = |c| chunks(c, n);
        let positions_and_velocities = chunks(px)
            .zip(chunks(py))
            .zip(chunks(pz))
            .zip(chunks(vx).zip(chunks(vy)).zip(chunks(vz)))
            .zip(extra[..n].par_chunks_mut(CHUNK))
            .enumerate()
            .with_min_len(crate::par::min_len(1));
        let write = |m: usize, l: usize, t: &mut T, p: [&mut f32; 3], v: [&mut f32; 3]| {
            let k = m * CHUNK + l;
            let at = positions[k];
            let (h, vel) = motion(k, t);
            (*p[0], *p[1], *p[2]) = (at.x, at.y, at.z);
            (*v[0], *v[1], *v[2]) = (vel.x, vel.y, vel.z);
            h
        };
        if headings {
            positions_and_velocities
                .zip(chunks(hx).zip(chunks(hy)).zip(chunks(hz)))
                .for_each(
                    |((m, ((((px, py), pz), ((vx, vy), vz)), extra)), ((hx, hy), hz))| {
                        for (l, t) in extra.iter_mut().enumerate() {
                            let p = [&mut px[l], &mut py[l], &mut pz[l]];
                            let h = write(m, l, t, p, [&mut vx[l], &mut vy[l], &mut vz[l]]);
                            (hx[l], hy[l], hz[l]) = (h.x, h.y, h.z);
                        }
                    },
                );
        } else {
            positions_and_velocities.for_each(|(m, ((((px, py), pz), ((vx, vy), vz)), extra))| {
                for (l, t) in extra.iter_mut().enumerate() {
                    let p = [&mut px[l], &mut py[l], &mut pz[l]];
                    write(m, l, t, p, [&mut vx[l], &mut vy[l], &mut vz[l]]);
                }
            });
        }
        let level = |c: &[f32]| c[..n].iter().all(|&y| y == 0.0);
        self.flat =
            level(&self.pos[1]) && (!headings || level(&self.heading[1])) && level(&self.vel[1]);
    }

    /// Whether the heading columns are filled.
    pub fn has_headings(&self) -> bool {
        self.headings
    }

    fn columns_mut(&mut self) -> [&mut Vec<f32>; 9] {
        let [px, py, pz] = &mut self.pos;
        let [hx, hy, hz] = &mut self.heading;
        let [vx, vy, vz] = &mut self.vel;
        [px, py, pz, hx, hy, hz, vx, vy, vz]
    }

    /// Number of records (padding excluded).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}
