//! Stage 2 of the tick: the kin kernel, the perception of a plain flocker (seed 001's schooling
//! fish, seed 003's boids) folded [`LANES`] candidates at a time.
//!
//! A perceiver that keeps no agent percepts, sees only kin (every species is kin to it), and has
//! no custom sense volume and no mates needs, of its neighbors, only sums: the
//! kin summary (count, seen, nearest distance, position, heading and velocity sums) and the
//! group sums of separation and of neighborhood means. Those are accumulated here from
//! structure-of-arrays copies of the neighbors' records, every candidate of a grid row tested
//! and folded without a branch (a mask selects what is added), in fixed lanes that are added up
//! in a fixed order at the end. (Under a vision cone, which leaves most candidates out, a batch
//! of rows is tested first and only its steps with a lane perceived are folded: the same sums.
//! In a flat world, every record in the plane y = 0 as the boids', the y components, all ±0,
//! are left out: the same sums too.)
//! Each perceiver's result is therefore a pure function of the world: bit-identical whatever
//! the thread count. It is the same set of neighbors as the
//! general path perceives (a neighbor an obstacle hides is left out by the walks' own test, run
//! for the lanes in sight of a perceiver beside an obstacle); the sums differ from its
//! one-by-one sums only by rounding.

use super::eye::MAX_OCCLUDERS;
use super::group::{GroupAcc, GroupQueries, GroupQuery, GroupSum, MAX_GROUP_QUERIES};
use super::occlusion;
use crate::world::Shape;
use glam::{BVec4A, Vec3, Vec3A, Vec4};

mod lanes;
pub use lanes::KinLanes;

/// Candidates folded at a time (one 4-wide vector operation each).
pub const LANES: usize = 4;

/// Group queries the kernel folds itself; a species with more perceives by the general path.
pub const MAX_KERNEL_QUERIES: usize = 4;

/// Rows of the grid gathered before they are folded (the sums stay in registers meanwhile).
const ROWS: usize = 32;

/// Steps a batch of rows holds at most when the lanes are tested before they are folded
/// ([`KinFold::fold`] with a vision cone); a longer row is cut into batches.
const STEPS: usize = 64;

/// Whether a perceiver's fold sums headings, so reads the heading lanes: beside an obstacle
/// (`occluders`), with a vision cone or smell, or when its species reads the mean heading.
/// `KinFold::flush` picks its instance by the same four.
#[inline]
pub fn needs_headings(occluders: bool, cone: bool, smell: bool, headings: bool) -> bool {
    occluders || cone || smell || headings
}

/// What one perceiver brings to the kernel.
#[derive(Debug, Clone, Copy)]
pub struct Probe {
    /// Its position.
    pub here: Vec3,
    /// Its own slot in the grid's order (never its own neighbor).
    pub me: usize,
    /// Squared vision radius.
    pub vision2: f32,
    /// Squared smell radius.
    pub smell2: f32,
    /// Forward unit vector and the cosine bound of the vision cone; `None`: the whole sphere.
    pub cone: Option<(Vec3, f32)>,
    /// Whether the neighbors' forward vectors are summed (else the sum is left zero).
    pub headings: bool,
}

/// The kin sums of one perceiver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KinSums {
    /// Kin perceived (seen or smelt).
    pub count: u32,
    /// Kin seen.
    pub seen: u32,
    /// Smallest squared distance (infinite when none).
    pub nearest2: f32,
    /// Sum of positions.
    pub pos: Vec3A,
    /// Sum of forward vectors.
    pub heading: Vec3A,
    /// Sum of velocities.
    pub vel: Vec3A,
}

/// Whether the kernel can fold every query of `queries` (separation and means only).
pub fn supports(queries: &GroupQueries) -> bool {
    queries.len() <= MAX_KERNEL_QUERIES
        && queries
            .iter()
            .all(|q| matches!(q, GroupQuery::Separation { .. } | GroupQuery::Mean { .. }))
}

/// Running lanes of one group query: `a` offsets (or offsets / d²), `b` velocities, `n` count.
#[derive(Debug, Clone, Copy)]
struct QueryLanes {
    a: [Vec4; 3],
    b: [Vec4; 3],
    n: u32,
}

const QUERY_ZERO: QueryLanes = QueryLanes {
    a: [Vec4::ZERO; 3],
    b: [Vec4::ZERO; 3],
    n: 0,
};

/// The running lanes of the kin sums.
#[derive(Debug, Clone, Copy)]
struct KinLanesSum {
    count: u32,
    seen: u32,
    near2: Vec4,
    pos: [Vec4; 3],
    head: [Vec4; 3],
    vel: [Vec4; 3],
}

/// The running sums of one perceiver: the grid rows of its query go in with
/// [`KinFold::row`], the sums come out of [`KinFold::finish`].
pub struct KinFold<'a> {
    lanes: &'a KinLanes,
    probe: Probe,
    sum: KinLanesSum,
    /// The query lanes, pending rows and a cone batch's hits, reused from perceiver to
    /// perceiver: only what a perceiver writes is read back, so nothing is cleared.
    buf: &'a mut KinBuf,
    /// Squared radii of the queries, and which are separations (the others are means).
    radius2: [f32; MAX_KERNEL_QUERIES],
    separation: [bool; MAX_KERNEL_QUERIES],
    nq: usize,
    pending: usize,
    /// Steps of the pending rows, counted (and capped at [`STEPS`]) only under a vision cone,
    /// whose batches are tested whole before the perceived steps are folded.
    steps: usize,
    /// Obstacles that may hide a neighbor from sight, and the neighbors' bounding-box
    /// diagonals in the grid's order (read only for a lane whose centre is hidden).
    occluders: &'a [Shape],
    diagonals: &'a [f32],
}

/// A worker's buffers for [`KinFold`], kept from one perceiver to the next: clearing some
/// 1.2 KB for every perceiver cost more than a tenth of a small one's fold. Of `q` only the
/// first `nq` (set up by [`KinFold::new`]), of `rows` the first `pending`, of `hits` the
/// entries written in the same batch are read.
#[derive(Debug, Clone)]
pub struct KinBuf {
    /// The group sums of a walk (not the kernel) while it folds neighbors in.
    pub(super) acc: [GroupAcc; MAX_GROUP_QUERIES],
    q: [QueryLanes; MAX_KERNEL_QUERIES],
    rows: [(u32, u32); ROWS],
    hits: [u64; STEPS],
}

impl Default for KinBuf {
    fn default() -> Self {
        KinBuf {
            acc: [GroupAcc::default(); MAX_GROUP_QUERIES],
            q: [QUERY_ZERO; MAX_KERNEL_QUERIES],
            rows: [(0, 0); ROWS],
            hits: [0; STEPS],
        }
    }
}

/// Lane numbers within a step.
const LANE: Vec4 = Vec4::new(0.0, 1.0, 2.0, 3.0);

/// For each 4-bit lane mask, its lanes as 1 (set) or 0.
const BITS: [Vec4; 16] = {
    let mut t = [Vec4::ZERO; 16];
    let mut b = 0;
    while b < 16 {
        let (x, y, z, w) = (b & 1, (b >> 1) & 1, (b >> 2) & 1, b >> 3);
        t[b] = Vec4::new(x as f32, y as f32, z as f32, w as f32);
        b += 1;
    }
    t
};

impl<'a> KinFold<'a> {
    /// Nothing folded yet, for `probe` and `queries` (which [`supports`] must accept: others
    /// are ignored).
    #[inline(always)]
    pub fn new<'q>(
        lanes: &'a KinLanes,
        probe: Probe,
        queries: impl IntoIterator<Item = &'q GroupQuery>,
        buf: &'a mut KinBuf,
    ) -> Self {
        let mut f = KinFold {
            lanes,
            probe,
            sum: KinLanesSum {
                count: 0,
                seen: 0,
                near2: Vec4::INFINITY,
                pos: [Vec4::ZERO; 3],
                head: [Vec4::ZERO; 3],
                vel: [Vec4::ZERO; 3],
            },
            buf,
            radius2: [0.0; MAX_KERNEL_QUERIES],
            separation: [false; MAX_KERNEL_QUERIES],
            nq: 0,
            pending: 0,
            steps: 0,
            occluders: &[],
            diagonals: &[],
        };
        for query in queries.into_iter().take(MAX_KERNEL_QUERIES) {
            let k = f.nq;
            match *query {
                GroupQuery::Separation { radius } => {
                    f.radius2[k] = radius * radius;
                    f.separation[k] = true;
                }
                GroupQuery::Mean { radius } => f.radius2[k] = radius * radius,
                _ => continue,
            }
            f.buf.q[k] = QUERY_ZERO;
            f.nq += 1;
        }
        f
    }

    /// Neighbors hidden by `occluders` (with their real shapes, as the general path's
    /// [`occlusion::hidden`]; `diagonals`: every neighbor's bounding-box diagonal in the
    /// grid's order) are not seen: only smelt where smell reaches them, else not perceived.
    /// The same neighbors as the general path then, tested by the same function.
    #[inline(always)]
    pub fn occlude(&mut self, occluders: &'a [Shape], diagonals: &'a [f32]) {
        self.occluders = occluders;
        self.diagonals = diagonals;
    }

    /// Adds the candidates in grid slots `start..end` (folded a batch of rows at a time).
    /// `end` must not pass the number of records.
    #[inline]
    pub fn row(&mut self, start: usize, end: usize) {
        // The perceiver's own slot splits its row: no lane needs a test for it.
        let me = self.probe.me;
        if (start..end).contains(&me) {
            self.push(start, me);
            self.push(me + 1, end);
        } else {
            self.push(start, end);
        }
    }

    #[inline]
    fn push(&mut self, start: usize, end: usize) {
        if start >= end {
            return;
        }
        if self.probe.cone.is_some() {
            self.push_capped(start, end);
            return;
        }
        self.buf.rows[self.pending] = (start as u32, end as u32);
        self.pending += 1;
        if self.pending == ROWS {
            self.flush();
        }
    }

    /// `push` for a batch of at most [`STEPS`] steps: a row is cut a whole number of steps
    /// from its start, so each candidate keeps its lane and the sums their bits.
    #[inline]
    fn push_capped(&mut self, mut start: usize, end: usize) {
        while start < end {
            if self.steps == STEPS {
                self.flush();
            }
            let cut = end.min(start + (STEPS - self.steps) * LANES);
            self.buf.rows[self.pending] = (start as u32, cut as u32);
            self.pending += 1;
            self.steps += (cut - start).div_ceil(LANES);
            if self.pending == ROWS {
                self.flush();
            }
            start = cut;
        }
    }

    /// Folds the rows gathered so far.
    fn flush(&mut self) {
        let smell = self.probe.smell2 > 0.0;
        debug_assert!(
            self.lanes.has_headings()
                || !needs_headings(
                    !self.occluders.is_empty(),
                    self.probe.cone.is_some(),
                    smell,
                    self.probe.headings
                ),
            "a fold that sums headings over lanes without them"
        );
        // A single separation query (the boids' and the 3D flockers' case) has its own
        // instances: its sums then stay in registers too. So does a perceiver that sums no
        // headings.
        let lone_separation = self.nq == 1 && self.separation[0];
        // Beside an obstacle (rare): instances that test occlusion, general in the rest.
        if !self.occluders.is_empty() {
            match (self.probe.cone.is_some(), smell) {
                (false, false) => self.fold::<false, false, false, true, true, false>(),
                (false, true) => self.fold::<false, true, false, true, true, false>(),
                (true, false) => self.fold::<true, false, false, true, true, false>(),
                (true, true) => self.fold::<true, true, false, true, true, false>(),
            }
            (self.pending, self.steps) = (0, 0);
            return;
        }
        // A flat world (every record in the plane y = 0, the perceiver too: the boids'): the
        // y components are all ±0 and leave every sum +0, so they are not folded at all.
        if self.lanes.flat && self.probe.here.y == 0.0 && !smell && self.probe.cone.is_none() {
            match (lone_separation, self.probe.headings) {
                (true, false) => self.fold::<false, false, true, false, false, true>(),
                (false, false) => self.fold::<false, false, false, false, false, true>(),
                (_, true) => self.fold::<false, false, false, true, false, true>(),
            }
            (self.pending, self.steps) = (0, 0);
            return;
        }
        match (
            self.probe.cone.is_some(),
            smell,
            lone_separation,
            self.probe.headings,
        ) {
            (false, false, true, false) => self.fold::<false, false, true, false, false, false>(),
            (false, false, true, true) => self.fold::<false, false, true, true, false, false>(),
            (false, false, false, false) => self.fold::<false, false, false, false, false, false>(),
            (false, false, false, true) => self.fold::<false, false, false, true, false, false>(),
            (false, true, _, _) => self.fold::<false, true, false, true, false, false>(),
            (true, false, true, false) => self.fold::<true, false, true, false, false, false>(),
            (true, false, true, true) => self.fold::<true, false, true, true, false, false>(),
            (true, false, false, _) => self.fold::<true, false, false, true, false, false>(),
            (true, true, _, _) => self.fold::<true, true, false, true, false, false>(),
        }
        (self.pending, self.steps) = (0, 0);
    }

    #[inline(always)]
    fn fold<
        const CONE: bool,
        const SMELL: bool,
        const SEPARATION: bool,
        const HEADINGS: bool,
        const OCCLUSION: bool,
        const FLAT: bool,
    >(
        &mut self,
    ) {
        let lanes: &'a KinLanes = self.lanes;
        let p = self.probe;
        let (cx, cy, cz) = (
            Vec4::splat(p.here.x),
            Vec4::splat(p.here.y),
            Vec4::splat(p.here.z),
        );
        let (fwd, cos_min) = p.cone.unwrap_or((Vec3::ZERO, -2.0));
        let (fx, fy, fz, cos_min) = (
            Vec4::splat(fwd.x),
            Vec4::splat(fwd.y),
            Vec4::splat(fwd.z),
            Vec4::splat(cos_min),
        );
        let vision2 = Vec4::splat(p.vision2);
        let smell2 = Vec4::splat(p.smell2);
        let tiny = Vec4::splat(1e-12);
        let sep2 = Vec4::splat(self.radius2[0]);
        let mut sum = self.sum;
        let mut sep = self.buf.q[0];
        let nq = self.nq;
        let (radius2, separation) = (self.radius2, self.separation);
        let q = &mut self.buf.q;
        let (occluders, diagonals) = (self.occluders, self.diagonals);
        // Each occluder's bounding sphere, centred on the eye and a little larger: a lane
        // whose line of sight passes outside every one is not hidden, with no test. The
        // margin covers this test's rounding (`scale`: the coordinates' size) and the exact
        // test's: its quadratic, `b² − a·(|o|² − r²)`, may call a line that passes up to about
        // `ε·|o|²/r` outside a small sphere at `o` blocked, hence the `1e-5·|o|²` in r².
        let mut spheres = [[Vec4::ZERO; 4]; MAX_OCCLUDERS];
        let n_occ = if OCCLUSION {
            occluders.len().min(MAX_OCCLUDERS)
        } else {
            0
        };
        // More occluders than spheres (never from the walks): every lane in sight is tested.
        let test_all = OCCLUSION && occluders.len() > MAX_OCCLUDERS;
        for (o, shape) in spheres.iter_mut().zip(&occluders[..n_occ]) {
            let c = shape.center() - p.here;
            let r = shape.bounding_radius().abs();
            let scale = p.here.abs().max_element() + shape.center().abs().max_element();
            let r = r * 1.001 + 1e-5 * scale + 1e-4;
            // A shape that is not finite: a sphere around the eye that every line reaches.
            *o = if r.is_finite() && c.is_finite() {
                [c.x, c.y, c.z, r * r + 1e-5 * c.length_squared()]
            } else {
                [0.0, 0.0, 0.0, f32::INFINITY]
            }
            .map(Vec4::splat);
        }
        // The columns as slices, cut to one length (their pointers then stay in registers
        // and one bounds check covers them all).
        let m = lanes.pos[0].len();
        let col = |c: &'a Vec<f32>| &c[..m];
        let (px, py, pz) = (col(&lanes.pos[0]), col(&lanes.pos[1]), col(&lanes.pos[2]));
        let (vx, vy, vz) = (col(&lanes.vel[0]), col(&lanes.vel[1]), col(&lanes.vel[2]));
        let (hx, hy, hz) = if HEADINGS {
            (
                col(&lanes.heading[0]),
                col(&lanes.heading[1]),
                col(&lanes.heading[2]),
            )
        } else {
            // Never read: `HEADINGS` is false.
            (px, py, pz)
        };
        // One step's test: of the candidates in slots `k..k + LANES` (those of lanes `ok`),
        // the lanes perceived (`hit`) and of those the lanes seen (`vis`). Macros, not
        // closures: the sums must stay in this function's registers.
        macro_rules! test {
            ($k:expr, $ok:expr) => {{
                let (k, ok): (usize, Option<glam::BVec4A>) = ($k, $ok);
                // `each_step` checked the row's end: `k + LANES <= m` follows.
                let v4 = |c: &[f32]| Vec4::from_slice(&c[k..k + LANES]);
                let (dx, dz) = (v4(px) - cx, v4(pz) - cz);
                let (dy, d2) = flat_or(FLAT, dx, dz, || v4(py) - cy);
                let mut vis = d2.cmple(vision2);
                if CONE {
                    let len = d2.sqrt();
                    let dot = fx * dx + fy * dy + fz * dz;
                    vis &= len.cmpeq(Vec4::ZERO) | (dot / len).cmpge(cos_min);
                }
                if let Some(ok) = ok {
                    vis &= ok;
                }
                if OCCLUSION && vis.any() {
                    // Lanes whose segment from the eye comes within a bounding sphere.
                    let mut near = BVec4A::splat(test_all);
                    for &[ox, oy, oz, r2] in &spheres[..n_occ] {
                        let t = ((ox * dx + oy * dy + oz * dz) / d2).clamp(Vec4::ZERO, Vec4::ONE);
                        let (ex, ey, ez) = (ox - t * dx, oy - t * dy, oz - t * dz);
                        near |= (ex * ex + ey * ey + ez * ez).cmple(r2);
                    }
                    let test = vis & near;
                    if test.any() {
                        vis = unhidden(vis, test, p.here, k, [dx, dy, dz], occluders, diagonals);
                    }
                }
                let hit = if SMELL {
                    let smelt = d2.cmple(smell2);
                    vis | ok.map_or(smelt, |ok| smelt & ok)
                } else {
                    vis
                };
                (hit, vis)
            }};
        }
        // Folds the lanes `hit` of slots `k..k + LANES` (`vis`: those seen). A lane left out
        // adds nothing: a step without a lane perceived may be skipped, the sums' bits the
        // same (a running sum is never −0, so adding +0 leaves it as it is).
        macro_rules! add {
            ($k:expr, $hit:expr, $vis:expr) => {{
                let (k, hit, vis): (usize, BVec4A, BVec4A) = ($k, $hit, $vis);
                // Under `each_step` the row's end was checked; a cone's steps come back from
                // `hits` and are checked here.
                if CONE {
                    assert!(k + LANES <= m);
                }
                let v4 = |c: &[f32]| Vec4::from_slice(&c[k..k + LANES]);
                let (x, z) = (v4(px), v4(pz));
                let (dx, dz) = (x - cx, z - cz);
                let (dy, d2) = flat_or(FLAT, dx, dz, || v4(py) - cy);
                let pick = |v: Vec4| Vec4::select(hit, v, Vec4::ZERO);
                sum.count += lanes_set(hit);
                if SMELL {
                    sum.seen += lanes_set(vis);
                }
                sum.near2 = sum.near2.min(Vec4::select(hit, d2, Vec4::INFINITY));
                sum.pos[0] += pick(x);
                if !FLAT {
                    sum.pos[1] += pick(v4(py));
                }
                sum.pos[2] += pick(z);
                if HEADINGS {
                    sum.head[0] += pick(v4(hx));
                    if !FLAT {
                        sum.head[1] += pick(v4(hy));
                    }
                    sum.head[2] += pick(v4(hz));
                }
                let (ux, uz) = (v4(vx), v4(vz));
                // Never read when `FLAT`.
                let uy = if FLAT { Vec4::ZERO } else { v4(vy) };
                sum.vel[0] += pick(ux);
                if !FLAT {
                    sum.vel[1] += pick(uy);
                }
                sum.vel[2] += pick(uz);
                if SEPARATION {
                    separate::<FLAT>(&mut sep, hit, d2, sep2, tiny, dx, dy, dz);
                } else {
                    for (k, s) in q.iter_mut().enumerate().take(nq) {
                        let r2 = Vec4::splat(radius2[k]);
                        if separation[k] {
                            separate::<FLAT>(s, hit, d2, r2, tiny, dx, dy, dz);
                        } else {
                            let take = hit & d2.cmple(r2);
                            let pick = |v: Vec4| Vec4::select(take, v, Vec4::ZERO);
                            s.a[0] += pick(dx);
                            s.a[2] += pick(dz);
                            s.b[0] += pick(ux);
                            s.b[2] += pick(uz);
                            if !FLAT {
                                s.a[1] += pick(dy);
                                s.b[1] += pick(uy);
                            }
                            s.n += lanes_set(take);
                        }
                    }
                }
            }};
        }
        // Every step of the batch in order: whole steps unmasked; the last, partial one of a
        // row reads up to LANES − 1 entries past it (within the padding at worst), masked off.
        macro_rules! each_step {
            (|$k:ident, $ok:ident| $body:expr) => {
                for &(start, end) in &self.buf.rows[..self.pending] {
                    let (start, end) = (start as usize, end as usize);
                    // Once per row: every step below reads `k..k + LANES` with `k < end`.
                    assert!(end + LANES <= m);
                    let mut $k = start;
                    while $k + LANES <= end {
                        let $ok = None;
                        $body;
                        $k += LANES;
                    }
                    if $k < end {
                        let $ok = Some(LANE.cmplt(Vec4::splat((end - $k) as f32)));
                        $body;
                    }
                }
            };
        }
        if CONE {
            // A cone's batch is tested whole first (a few registers), and only its steps with
            // a lane perceived are then folded (all of them): most have none, a cone and a
            // sphere leaving most of the grid cells' cube out. `push_capped` holds a batch to
            // `STEPS` steps.
            debug_assert!(self.steps <= STEPS);
            let hits = &mut self.buf.hits;
            let mut n = 0;
            each_step!(|k, ok| {
                let (hit, vis) = test!(k, ok);
                hits[n] = k as u64 | (hit.bitmask() as u64) << 32 | (vis.bitmask() as u64) << 36;
                n += usize::from(hit.any());
            });
            for &h in &hits[..n] {
                let lanes_of = |bits: u64| BITS[(bits & 15) as usize].cmpne(Vec4::ZERO);
                add!(h as u32 as usize, lanes_of(h >> 32), lanes_of(h >> 36));
            }
        } else {
            each_step!(|k, ok| {
                let (hit, vis) = test!(k, ok);
                add!(k, hit, vis);
            });
        }
        if !SMELL {
            sum.seen = sum.count;
        }
        self.sum = sum;
        if SEPARATION {
            self.buf.q[0] = sep;
        }
    }

    /// The kin sums; the group sums go to `sums` (one per query, in order).
    pub fn finish(&mut self, sums: &mut [GroupSum]) -> KinSums {
        let mut out = sums.iter_mut();
        self.finish_with(|s| {
            if let Some(o) = out.next() {
                *o = s;
            }
        })
    }

    /// The kin sums; `put` takes the group sums, one per query, in order.
    #[inline(always)]
    pub fn finish_with(&mut self, mut put: impl FnMut(GroupSum)) -> KinSums {
        if self.pending > 0 {
            self.flush();
        }
        for s in &self.buf.q[..self.nq] {
            put(GroupSum {
                a: vec_of(&s.a).into(),
                b: vec_of(&s.b).into(),
                c: Vec3::ZERO,
                n: s.n,
                m: 0,
                w: 0.0,
            });
        }
        let sum = &self.sum;
        KinSums {
            count: sum.count,
            seen: sum.seen,
            nearest2: sum.near2.min_element(),
            pos: vec_of(&sum.pos),
            // The instances for cones and smell sum headings whatever the probe asks.
            heading: if self.probe.headings {
                vec_of(&sum.head)
            } else {
                Vec3A::ZERO
            },
            vel: vec_of(&sum.vel),
        }
    }
}

/// Separation lanes: `offset / d²` for `1e-6 < d ≤ radius`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn separate<const FLAT: bool>(
    s: &mut QueryLanes,
    hit: glam::BVec4A,
    d2: Vec4,
    r2: Vec4,
    tiny: Vec4,
    dx: Vec4,
    dy: Vec4,
    dz: Vec4,
) {
    let take = hit & d2.cmple(r2) & d2.cmpgt(tiny);
    // Separation radii are short: most steps have no lane within one.
    if !take.any() {
        return;
    }
    let inv = Vec4::ONE / d2;
    let pick = |v: Vec4| Vec4::select(take, v, Vec4::ZERO);
    s.a[0] += pick(dx * inv);
    if !FLAT {
        s.a[1] += pick(dy * inv);
    }
    s.a[2] += pick(dz * inv);
    s.n += lanes_set(take);
}

/// A step's y offsets and squared distances: `(dy, dx² + dy² + dz²)`, `dy = y()`; in a flat
/// world (`flat`: every y ±0) `(0, dx² + dz²)`, the same bits (`dy²` is +0, and adding +0 to
/// `dx²`, never −0, changes nothing), `y` not read.
#[inline(always)]
fn flat_or(flat: bool, dx: Vec4, dz: Vec4, y: impl FnOnce() -> Vec4) -> (Vec4, Vec4) {
    if flat {
        (Vec4::ZERO, dx * dx + dz * dz)
    } else {
        let dy = y();
        (dy, dx * dx + dy * dy + dz * dz)
    }
}

/// How many lanes of `m` are set. Counts are kept in an integer register, not in a vector
/// one: the kernel's sums need more vector registers than there are, and a vector count would
/// take one more (the same totals: the lanes of a count hold integers).
#[inline(always)]
fn lanes_set(m: BVec4A) -> u32 {
    const SET: [u8; 16] = [0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4];
    SET[m.bitmask() as usize & 15] as u32
}

/// `vis` without the lanes of `test` whose neighbor (grid slot `k` + lane, at offsets `d` from
/// the eye at `here`) `occluders` hide. Out of line: only lines of sight that pass near an
/// obstacle come here.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn unhidden(
    vis: BVec4A,
    test: BVec4A,
    here: Vec3,
    k: usize,
    d: [Vec4; 3],
    occluders: &[Shape],
    diagonals: &[f32],
) -> BVec4A {
    let [dx, dy, dz] = d.map(|v| v.to_array());
    let mut keep = [false; LANES];
    for (l, keep) in keep.iter_mut().enumerate() {
        *keep = vis.test(l);
        if test.test(l) {
            // The general path's offset, `pos − here`, component by component: the same bits.
            let offset = Vec3::new(dx[l], dy[l], dz[l]);
            let radius = || diagonals.get(k + l).map_or(0.0, |&d| d * 0.5);
            *keep = !occlusion::hidden(here, offset, radius, occluders);
        }
    }
    BVec4A::from_array(keep)
}

/// The lanes of each component added up.
#[inline(always)]
fn vec_of(l: &[Vec4; 3]) -> Vec3A {
    Vec3A::new(l[0].element_sum(), l[1].element_sum(), l[2].element_sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fold(
        l: &KinLanes,
        probe: Probe,
        rows: &[(usize, usize)],
        queries: &[GroupQuery],
        sums: &mut [GroupSum],
    ) -> KinSums {
        let mut buf = KinBuf::default();
        let mut f = KinFold::new(l, probe, queries, &mut buf);
        for &(s, e) in rows {
            f.row(s, e);
        }
        f.finish(sums)
    }

    /// Every bit of the kin sums and of the group sums `s`, to compare folds exactly.
    #[allow(clippy::type_complexity)]
    fn sum_bits(
        k: &KinSums,
        s: &[GroupSum],
    ) -> (u32, u32, u32, [[u32; 3]; 3], Vec<(u32, [u32; 3], [u32; 3])>) {
        let v = |v: Vec3| v.to_array().map(f32::to_bits);
        let sums = s.iter().map(|s| (s.n, v(s.a), v(s.b))).collect();
        (
            k.count,
            k.seen,
            k.nearest2.to_bits(),
            [v(k.pos.into()), v(k.heading.into()), v(k.vel.into())],
            sums,
        )
    }

    /// A perceiver at `here` in slot `me`, vision radius² `vision2`: no smell, no cone, no
    /// headings summed.
    fn plain(here: Vec3, me: usize, vision2: f32) -> Probe {
        Probe {
            here,
            me,
            vision2,
            smell2: 0.0,
            cone: None,
            headings: false,
        }
    }

    fn lanes(points: &[(Vec3, Vec3)]) -> KinLanes {
        let mut l = KinLanes::default();
        let positions: Vec<Vec3A> = points.iter().map(|&(p, _)| p.into()).collect();
        let mut extra = vec![(); positions.len()];
        l.fill(&positions, &mut extra, true, |k, _| {
            (points[k].1.normalize_or_zero(), points[k].1)
        });
        l
    }

    #[test]
    fn folds_hand_computed_sums_and_skips_itself() {
        // Perceiver at the origin (slot 0), vision 3, no smell, whole sphere.
        let pts = [
            (Vec3::ZERO, Vec3::X),
            (Vec3::new(2.0, 0.0, 0.0), Vec3::Z * 2.0),
            (Vec3::new(0.0, 0.0, 1.0), Vec3::X * 4.0),
            (Vec3::new(0.0, 4.0, 0.0), Vec3::Y), // out of range
        ];
        let l = lanes(&pts);
        let probe = Probe {
            here: Vec3::ZERO,
            me: 0,
            vision2: 9.0,
            smell2: 0.0,
            cone: None,
            headings: true,
        };
        let queries = [
            GroupQuery::Separation { radius: 1.5 },
            GroupQuery::Mean { radius: 3.0 },
        ];
        let mut sums = [GroupSum::default(); 2];
        let k = fold(&l, probe, &[(0, 4)], &queries, &mut sums);
        assert_eq!((k.count, k.seen), (2, 2));
        assert_eq!(k.nearest2, 1.0);
        assert_eq!(k.pos, Vec3A::new(2.0, 0.0, 1.0));
        assert_eq!(k.heading, Vec3A::new(1.0, 0.0, 1.0));
        assert_eq!(k.vel, Vec3A::new(4.0, 0.0, 2.0));
        // Separation within 1.5: only (0,0,1), weighted 1/1.
        assert_eq!((sums[0].a, sums[0].n), (Vec3::Z, 1));
        // Means within 3: both.
        assert_eq!(
            (sums[1].a, sums[1].b, sums[1].n),
            (Vec3::new(2.0, 0.0, 1.0), Vec3::new(4.0, 0.0, 2.0), 2)
        );
    }

    #[test]
    fn lanes_without_headings_fold_the_same_bits_where_no_heading_is_summed() {
        // A flat world (the boids') and a 3D one; perceivers with full-circle vision, no
        // smell, no heading read: the fold never reads the heading lanes, so leaving them
        // empty changes no bit.
        let mut rng = crate::world::Rng::new(9, 0);
        for flat in [true, false] {
            let pts: Vec<(Vec3, Vec3)> = (0..200)
                .map(|_| {
                    let y = if flat { 0.0 } else { rng.range(0.0, 10.0) };
                    let p = Vec3::new(rng.range(0.0, 10.0), y, rng.range(0.0, 10.0));
                    let vy = if flat { 0.0 } else { rng.range(-1.0, 1.0) };
                    (p, Vec3::new(rng.range(-1.0, 1.0), vy, 1.0))
                })
                .collect();
            let positions: Vec<Vec3A> = pts.iter().map(|&(p, _)| p.into()).collect();
            // Headings pitched out of the plane, velocities in it (a body at rest, nose up):
            // only the heading lanes would make the world not flat.
            let motion = |k: usize, _: &mut ()| {
                let v = pts[k].1;
                ((v + Vec3::Y * 0.5).normalize_or_zero(), v)
            };
            let (mut with, mut without) = (KinLanes::default(), KinLanes::default());
            with.fill(&positions, &mut [(); 200], true, motion);
            without.fill(&positions, &mut [(); 200], false, motion);
            assert!(with.has_headings() && !without.has_headings());
            assert!(
                without.heading.iter().all(|c| c.is_empty()),
                "no heading lanes kept"
            );
            assert!(!with.flat);
            assert_eq!(without.flat, flat);
            for (t, queries) in [
                &[GroupQuery::Separation { radius: 2.0 }][..],
                &[
                    GroupQuery::Separation { radius: 1.0 },
                    GroupQuery::Mean { radius: 3.0 },
                ][..],
            ]
            .into_iter()
            .enumerate()
            {
                let me = 17 + 40 * t;
                let probe = Probe {
                    here: pts[me].0,
                    me,
                    vision2: 16.0,
                    smell2: 0.0,
                    cone: None,
                    headings: false,
                };
                assert!(!needs_headings(false, false, false, probe.headings));
                let rows = [(0, 90), (90, 200)];
                let (mut a, mut b) = ([GroupSum::default(); 2], [GroupSum::default(); 2]);
                let ka = fold(&with, probe, &rows, queries, &mut a);
                let kb = fold(&without, probe, &rows, queries, &mut b);
                assert!(ka.count > 0);
                assert_eq!(
                    sum_bits(&ka, &a),
                    sum_bits(&kb, &b),
                    "flat {flat}, {queries:?}"
                );
            }
        }
    }

    #[test]
    fn a_buffer_kept_from_perceiver_to_perceiver_gives_every_bit_of_a_fresh_one() {
        // Perceivers in turn on one buffer, with query lists of four, one and two queries and
        // with and without a cone: what one leaves behind (more query lanes, longer batches)
        // must not reach the next one's sums.
        let mut rng = crate::world::Rng::new(5, 0);
        let pts: Vec<(Vec3, Vec3)> = (0..300)
            .map(|_| {
                let p = Vec3::new(
                    rng.range(0.0, 12.0),
                    rng.range(0.0, 12.0),
                    rng.range(0.0, 12.0),
                );
                let v = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 1.0);
                (p, v)
            })
            .collect();
        let l = lanes(&pts);
        let lists: [&[GroupQuery]; 3] = [
            &[
                GroupQuery::Mean { radius: 5.0 },
                GroupQuery::Separation { radius: 2.0 },
                GroupQuery::Mean { radius: 3.0 },
                GroupQuery::Separation { radius: 4.0 },
            ],
            &[GroupQuery::Separation { radius: 2.5 }],
            &[
                GroupQuery::Mean { radius: 4.0 },
                GroupQuery::Mean { radius: 1.0 },
            ],
        ];
        let mut kept = KinBuf::default();
        let mut cones = 0;
        for t in 0..60 {
            let me = t * 5;
            let cone = (t % 2 == 1).then(|| (pts[me].1.normalize(), -0.3));
            cones += usize::from(cone.is_some());
            let probe = Probe {
                here: pts[me].0,
                me,
                vision2: 36.0,
                smell2: 0.0,
                cone,
                headings: t % 3 == 0,
            };
            let queries = lists[t % 3];
            // Rows of every length, some longer than a cone's batch.
            let rows = [(0, 7), (9, 180), (180, 300)];
            let mut fresh_sums = [GroupSum::default(); MAX_KERNEL_QUERIES];
            let fresh = fold(&l, probe, &rows, queries, &mut fresh_sums);
            let mut kept_sums = [GroupSum::default(); MAX_KERNEL_QUERIES];
            let mut f = KinFold::new(&l, probe, queries, &mut kept);
            for &(s, e) in &rows {
                f.row(s, e);
            }
            let k = f.finish(&mut kept_sums);
            assert!(fresh.count > 0, "perceiver {t} perceives no one");
            assert_eq!(
                sum_bits(&k, &kept_sums),
                sum_bits(&fresh, &fresh_sums),
                "perceiver {t}"
            );
        }
        assert_eq!(cones, 30);
    }

    #[test]
    fn obstacles_hide_exactly_what_the_walks_own_test_hides() {
        // Pebbles (radius 0 or nearly) a hair off the lines of sight to neighbors of no size
        // (hidden exactly when the line to the centre is blocked): where rounding makes the
        // exact test call such a line blocked, the kernel's bounding-sphere pre-test must not
        // have passed the lane over. Counted against the walks' `occlusion::hidden`.
        let mut rng = crate::world::Rng::new(11, 0);
        let mut differ = Vec::new();
        for trial in 0..400 {
            let here = Vec3::new(
                rng.range(-60.0, 60.0),
                rng.range(-20.0, 20.0),
                rng.range(-60.0, 60.0),
            );
            let mut pts = vec![(here, Vec3::Z)];
            for _ in 0..40 {
                let d = Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                pts.push((here + d * 9.0, Vec3::X));
            }
            let occluders: Vec<Shape> = (0..MAX_OCCLUDERS)
                .map(|k| {
                    let to = pts[1 + k].0 - here;
                    let side = to.any_orthonormal_vector();
                    let off = crate::math::powf(10.0, -rng.range(2.0, 5.0));
                    let radius = if k % 2 == 0 { 0.0 } else { 0.001 };
                    Shape::Sphere {
                        center: here + to * rng.range(0.2, 0.8) + side * off,
                        radius,
                    }
                })
                .collect();
            let diagonals = vec![0.0; pts.len()];
            let l = lanes(&pts);
            let mut buf = KinBuf::default();
            let mut f = KinFold::new(&l, plain(here, 0, 100.0), &[], &mut buf);
            f.occlude(&occluders, &diagonals);
            f.row(0, pts.len());
            let k = f.finish(&mut []);
            let seen = pts[1..]
                .iter()
                .filter(|(p, _)| {
                    let offset = *p - here;
                    offset.length_squared() <= 100.0
                        && !occlusion::hidden(here, offset, || 0.0, &occluders)
                })
                .count() as u32;
            if k.count != seen {
                differ.push((trial, k.count, seen));
            }
        }
        assert!(differ.is_empty(), "(trial, kernel, walks): {differ:?}");
    }

    #[test]
    fn a_cone_hides_what_is_behind_and_smell_still_counts() {
        // Facing +Z with a 90° half-angle cone: (0,0,-1) is behind, (1,0,0) at the edge.
        let pts = [
            (Vec3::ZERO, Vec3::Z),
            (Vec3::new(0.0, 0.0, -1.0), Vec3::Z),
            (Vec3::new(0.0, 0.0, 2.0), Vec3::Z),
            (Vec3::new(0.0, 0.0, -2.5), Vec3::Z),
        ];
        let l = lanes(&pts);
        let probe = Probe {
            here: Vec3::ZERO,
            me: 0,
            vision2: 9.0,
            smell2: 1.5 * 1.5,
            cone: Some((Vec3::Z, 0.0)),
            headings: true,
        };
        let k = fold(&l, probe, &[(0, 4)], &[], &mut []);
        // Seen: (0,0,2). Smelt only: (0,0,-1). Missed: (0,0,-2.5), behind and beyond smell.
        assert_eq!((k.count, k.seen), (2, 1));
        assert_eq!(k.pos, Vec3A::new(0.0, 0.0, 1.0));
    }

    #[test]
    fn rows_longer_than_a_step_and_ragged_ends_are_folded_whole() {
        // 21 neighbors along x at 0.1 spacing, the perceiver in the middle of its row.
        let pts: Vec<(Vec3, Vec3)> = (0..21)
            .map(|k| (Vec3::new(k as f32 * 0.1, 0.0, 0.0), Vec3::Z))
            .collect();
        let l = lanes(&pts);
        let probe = Probe {
            here: pts[10].0,
            me: 10,
            vision2: 100.0,
            smell2: 0.0,
            cone: None,
            headings: true,
        };
        // Two rows: 0..13 and 13..21.
        let k = fold(&l, probe, &[(0, 13), (13, 21)], &[], &mut []);
        assert_eq!(k.count, 20);
        assert_eq!(k.heading, Vec3A::new(0.0, 0.0, 20.0));
        assert!((k.nearest2 - 0.01).abs() < 1e-6);
        // Rows may also stop before the end of the data: the lanes past them are masked.
        let k = fold(&l, probe, &[(0, 3)], &[], &mut []);
        assert_eq!(k.count, 3);
    }

    #[test]
    fn a_cone_admits_exactly_the_lanes_of_the_walks_test_at_its_edge() {
        // The kernel's 4-wide cone test against the walks' `len == 0 || dot / len ≥ cos`.
        // Neighbors at the cone's edge (within a few units in the last place of its angle), at
        // the eye, a hair from it, and far: each must be admitted exactly when the walks' test
        // admits it.
        let mut rng = crate::world::Rng::new(17, 0);
        let mut differ = Vec::new();
        let mut admitted = [0, 0];
        for trial in 0..6000 {
            let here = Vec3::new(
                rng.range(-50.0, 50.0),
                rng.range(-50.0, 50.0),
                rng.range(-50.0, 50.0),
            );
            let fwd = Vec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            )
            .normalize_or(Vec3::Z);
            let half = [0.3, 1.0, 1.5707964, 2.0, 2.6][trial % 5] + rng.range(-0.01, 0.01);
            let cos_min = crate::math::cos(half) - 1e-6;
            // A direction at the edge: `fwd` turned by the half-angle about a perpendicular
            // axis, then nudged by a few units in the last place (or more, or none).
            let axis = fwd.any_orthonormal_vector();
            let angle = half * (1.0 + [0.0, 1e-7, -1e-7, 3e-7, -3e-7, 1e-5, -1e-3][trial % 7]);
            let dir = glam::Quat::from_axis_angle(axis, angle) * fwd;
            let dist = match trial % 13 {
                0 => 0.0,
                1 => 1e-22,
                2 => 3e-21,
                3 => 1e-20,
                4 => 1e-12,
                _ => crate::math::powf(10.0, rng.range(-4.0, 0.95)),
            };
            // Offsets far below a coordinate's last place vanish: tiny ones are taken at the
            // origin.
            let here = if dist < 1e-6 { Vec3::ZERO } else { here };
            let there = here + dir * dist;
            let pts = [(here, Vec3::Z), (there, Vec3::X)];
            let l = lanes(&pts);
            let probe = Probe {
                cone: Some((fwd, cos_min)),
                ..plain(here, 0, 81.0)
            };
            let k = fold(&l, probe, &[(0, 2)], &[], &mut []);
            let offset = there - here;
            let len = offset.length_squared().sqrt();
            let walks =
                offset.length_squared() <= 81.0 && (len == 0.0 || fwd.dot(offset) / len >= cos_min);
            admitted[walks as usize] += 1;
            if k.count != walks as u32 {
                differ.push((trial, k.count, walks));
            }
        }
        assert!(differ.is_empty(), "(trial, kernel, walks): {differ:?}");
        // Both answers occur at the edge: the test can tell the two forms apart.
        assert!(admitted[0] > 1000 && admitted[1] > 1000, "{admitted:?}");
    }

    #[test]
    fn a_flat_world_folds_two_components_with_the_bits_of_three() {
        // Records in the plane y = 0 (some at −0) fold x and z only; every sum must keep the
        // bits the three-component fold gives the same records. Any y off the plane, in a
        // position, heading or velocity, makes the world not flat.
        let mut rng = crate::world::Rng::new(23, 0);
        let zero = |rng: &mut crate::world::Rng| if rng.range(0.0, 1.0) < 0.5 { 0.0 } else { -0.0 };
        let pts: Vec<(Vec3, Vec3)> = (0..1500)
            .map(|_| {
                let p = Vec3::new(rng.range(-8.0, 8.0), zero(&mut rng), rng.range(-8.0, 8.0));
                let v = Vec3::new(rng.range(-3.0, 3.0), zero(&mut rng), rng.range(-3.0, 3.0));
                (p, v)
            })
            .collect();
        let flat = lanes(&pts);
        assert!(flat.flat);
        let mut solid = flat.clone();
        solid.flat = false;
        let sep = GroupQuery::Separation { radius: 1.5 };
        let mean = GroupQuery::Mean { radius: 3.0 };
        let rows = [(0, 7), (7, 300), (300, 301), (301, 1500)];
        // A perceiver above the plane (a probe, not a record) folds three components.
        for (me, lift) in [(0, 0.0), (299, 0.0), (300, -0.0), (1499, 0.0), (300, 0.5)] {
            for headings in [false, true] {
                for q in [&[sep][..], &[sep, mean], &[mean, sep, mean], &[mean]] {
                    let probe = Probe {
                        headings,
                        ..plain(pts[me].0 + Vec3::Y * lift, me, 36.0)
                    };
                    let (mut a, mut b) = (
                        vec![GroupSum::default(); q.len()],
                        vec![GroupSum::default(); q.len()],
                    );
                    let two = fold(&flat, probe, &rows, q, &mut a);
                    let three = fold(&solid, probe, &rows, q, &mut b);
                    assert!(two.count > 50, "{}", two.count);
                    assert_eq!(sum_bits(&two, &a), sum_bits(&three, &b), "me {me}, {q:?}");
                }
            }
        }
        // Off the plane: a single y makes every fold three-component.
        for part in 0..3 {
            let mut p = pts.clone();
            match part {
                0 => p[5].0.y = 1e-30,
                1 => p[5].1.y = -2.0,
                _ => p[5].1 = Vec3::new(0.0, 1.0, 0.0),
            }
            assert!(!lanes(&p).flat, "part {part}");
        }
    }

    #[test]
    fn a_cone_that_hides_nothing_gives_the_sums_of_no_cone_bit_for_bit() {
        // A cone is tested a batch at a time before its perceived lanes are folded, long rows
        // cut into batches of `STEPS` steps; with a bound every direction passes (cosine ≥ −2)
        // it perceives what no cone does, and its sums must keep every bit: the same lanes,
        // folded in the same order. Random points, rows of every length up to four batches.
        let mut rng = crate::world::Rng::new(5, 0);
        let pts: Vec<(Vec3, Vec3)> = (0..2000)
            .map(|_| {
                let p = Vec3::new(rng.range(-6.0, 6.0), rng.range(-6.0, 6.0), 0.0);
                let v = Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                (p, v)
            })
            .collect();
        let l = lanes(&pts);
        let queries = [
            GroupQuery::Separation { radius: 1.5 },
            GroupQuery::Mean { radius: 3.0 },
        ];
        let mut rows = Vec::new();
        let mut start = 0;
        for len in [1, 3, 4, 5, 17, 255, 256, 257, 1000, 0, 9, 62] {
            rows.push((start, start + len));
            start += len;
        }
        for (me, smell2) in [(700, 0.0), (3, 4.0), (1999, 0.0)] {
            let probe = |cone| Probe {
                here: pts[me].0,
                me,
                vision2: 25.0,
                smell2,
                cone,
                headings: true,
            };
            for q in [&queries[..1], &queries[..]] {
                let (mut a, mut b) = ([GroupSum::default(); 2], [GroupSum::default(); 2]);
                let plain = fold(&l, probe(None), &rows, q, &mut a);
                let coned = fold(&l, probe(Some((Vec3::X, -2.0))), &rows, q, &mut b);
                assert!(plain.count > 100, "{}", plain.count);
                assert_eq!(
                    sum_bits(&plain, &[]),
                    sum_bits(&coned, &[]),
                    "me {me}, smell² {smell2}"
                );
                assert_eq!(sum_bits(&plain, &a).4, sum_bits(&coned, &b).4);
            }
        }
    }

    #[test]
    fn headings_are_summed_only_when_asked_and_nothing_else_changes() {
        // Ten neighbors in a row (two whole steps and a partial one), with and without a cone.
        let pts: Vec<(Vec3, Vec3)> = (0..11)
            .map(|k| {
                (
                    Vec3::new(k as f32 * 0.5, 0.0, 1.0),
                    Vec3::new(0.0, 1.0, 2.0),
                )
            })
            .collect();
        let l = lanes(&pts);
        for cone in [None, Some((Vec3::X, -0.5))] {
            let probe = |headings| Probe {
                here: Vec3::ZERO,
                me: 0,
                vision2: 100.0,
                smell2: 0.0,
                cone,
                headings,
            };
            // A lone separation (the boid's own instance) and two queries (the general one).
            let sep = GroupQuery::Separation { radius: 1.2 };
            let mean = GroupQuery::Mean { radius: 2.6 };
            for queries in [&[sep][..], &[sep, mean][..]] {
                let (mut a, mut b) = ([GroupSum::default(); 2], [GroupSum::default(); 2]);
                let with = fold(&l, probe(true), &[(0, 11)], queries, &mut a);
                let without = fold(&l, probe(false), &[(0, 11)], queries, &mut b);
                let case = format!("{cone:?} {}", queries.len());
                assert_eq!(with.count, 10, "{case}");
                let unit = Vec3A::new(0.0, 1.0, 2.0).normalize();
                assert!((with.heading - unit * 10.0).length() < 1e-5, "{case}");
                assert_eq!(without.heading, Vec3A::ZERO, "{case}");
                let without_headings = KinSums {
                    heading: Vec3A::ZERO,
                    ..with
                };
                assert_eq!(without_headings, without, "{case}");
                assert_eq!(a, b, "{case}");
                // Within 1.2 of the origin: (0.5, 0, 1) only (slot 0 is the perceiver's own);
                // within 2.6: x up to 2.0 (√(2² + 1) ≤ 2.6 < √(2.5² + 1)), four of them.
                assert_eq!(a[0].n, 1, "{case}");
                if queries.len() == 2 {
                    assert_eq!(a[1].n, 4, "{case}");
                }
            }
        }
    }
}
