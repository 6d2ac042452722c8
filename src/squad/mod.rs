//! Squads on terrain at run time: the runtime half of seed 004.
//!
//! Not a tick stage: a layer above the core that [`crate::scenario::Run`] (and the script-test
//! world, `testing`) drives between ticks, sequentially and in member order, so runs
//! stay bit-identical whatever the thread count.
//!
//! - At load ([`setup`]): the terrain is read, each walking species gets its cost grid from its
//!   `body.mobility`, and each squad is checked and planned (formation-aware A*, smoothing into
//!   the key-point and transition tables, follower paths: [`crate::formation`]).
//! - At the start ([`Squads::start`]): the members are spawned at their formation slots around
//!   the start, on the ground, facing the first leg. The leader is the one the scenario chose
//!   (`leader: Slot(n)`, `Role("…")` or `Random`; slot 0 by default), kept for the run.
//! - Before every tick ([`Squads::before_tick`]): the leader's progress along the smoothed path
//!   (the key points) is its projection on the current leg. The leader is given a point
//!   [`LOOKAHEAD`] metres further along the path, shortened to nothing while a follower lags more
//!   than [`LAG_GO`] metres behind its slot (at [`LAG_STOP`] the leader waits). Each follower's
//!   slot is its member path at the leader's progress — its formation slot at key points and the
//!   linear interpolation between old and new slot into a transition — and its target leads the
//!   slot by the distance it would lag at the slot's speed. A target that cannot be walked to in
//!   a straight line clear of blocked cells is replaced by a local detour ([`route`]). The
//!   targets go to `Pipeline::plan_targets`, read by the `FollowPlan` steering primitive; the
//!   tables and slots are published on `World::squads` for scripts ([`script`]).
//! - After every tick ([`Squads::after_tick`]): every walking agent is put back on the ground
//!   ([`ground`]), plans made by scripts' `plan_path` are adopted, the formation error is
//!   measured, and blocked members and leaders are detected: a follower that has not come
//!   [`STUCK_GAIN`] metres closer to its slot in [`STUCK_SECONDS`] takes a local A* detour for
//!   [`DETOUR_SECONDS`]; when that happens twice in a row, or the leader makes no progress for
//!   [`LEADER_STALL_SECONDS`] without waiting, the squad re-plans from the leader's position (at
//!   most once per [`REPLAN_COOLDOWN`] seconds).
//!
//! Files: this one holds the constants, the ground and [`Squads`] (start, spawning, putting
//! walkers on the ground); `slots.rs` one [`Squad`]: its plan, the leader's progress and the
//! members' slots; `upkeep.rs` the work before and after every tick (targets, detours, measures,
//! re-plans). What members' scripts read of their squad is world data
//! (`crate::world::board`, published on `World::squads`); the script API that reads it is
//! `crate::script::squad`. Both are re-exported here.

pub mod ground;
pub mod record;
pub mod route;
pub mod setup;

mod slots;
#[cfg(test)]
mod tests;
mod upkeep;

/// The squad part of the script API, kept with the script host (`crate::script::squad`).
pub use crate::script::squad as script;
pub use crate::script::squad::task_named;
pub use crate::world::board::{Board, Planned, SquadShared, SquadView, TransitionRow};
pub use setup::{shape_named, SquadSetup, SHAPE_NAMES};
pub use slots::{Progress, Squad, SquadStats};

use crate::formation::follow::key_headings;
use crate::formation::Planner;
use crate::species::SpeciesSet;
use crate::terrain::{CostGrid, Terrain};
use crate::tick::Pipeline;
use crate::world::{AgentId, World};
use glam::Vec3;
use route::Router;
use slots::on_ground;
use std::sync::Arc;

/// How far ahead along the path the leader aims (m).
pub const LOOKAHEAD: f32 = 3.0;
/// A follower this far behind its slot (m) starts slowing the leader down.
pub const LAG_GO: f32 = 3.0;
/// A follower this far behind its slot (m) stops the leader.
pub const LAG_STOP: f32 = 6.0;
/// The leader has arrived within this distance of the last key point (m).
pub const FINISH_RADIUS: f32 = 1.0;
/// Clearance kept from blocked cells by the straight way to a target (m).
pub const CLEARANCE: f32 = 0.3;
/// A follower that has not come [`STUCK_GAIN`] closer to its slot in this time (s) is blocked.
pub const STUCK_SECONDS: f32 = 3.0;
/// See [`STUCK_SECONDS`] (m).
pub const STUCK_GAIN: f32 = 0.25;
/// Followers closer than this to their slot (m) are never blocked.
pub const STUCK_MIN_DIST: f32 = 2.0;
/// How long a blocked follower follows a local A* detour (s).
pub const DETOUR_SECONDS: f32 = 5.0;
/// The leader is blocked after this long (s) without 0.5 m of progress while not waiting.
pub const LEADER_STALL_SECONDS: f32 = 6.0;
/// Least time between two re-plans of a squad (s).
pub const REPLAN_COOLDOWN: f32 = 10.0;
/// Height (m) above the ground at which plans are drawn in `world.json`.
pub const DRAW_LIFT: f32 = 0.5;

/// A scenario's terrain with each walking species' cost grid.
#[derive(Debug, Clone)]
pub struct Ground {
    /// The terrain, features applied.
    pub terrain: Arc<Terrain>,
    /// By species index: the cost grid of each walking species (`body.on_ground`), built from
    /// its `body.mobility`; `None` for the others.
    pub grids: Vec<Option<Arc<CostGrid>>>,
}

/// The scenario's terrain and squads at run time.
#[derive(Debug, Default)]
pub struct Squads {
    /// The terrain and walking species' grids, when the scenario has terrain.
    pub ground: Option<Arc<Ground>>,
    /// The squads, in scenario order.
    pub squads: Vec<Squad>,
    /// Steps of walking agents cut back because they ended on a blocked cell (all agents).
    pub blocked_steps: u64,
    router: Router,
    planner: Planner,
}

impl Squads {
    /// A copy of the squads' state with fresh search buffers (for trying a new version of the
    /// scenario out on a copy of the run).
    pub fn fork(&self) -> Squads {
        Squads {
            ground: self.ground.clone(),
            squads: self.squads.clone(),
            blocked_steps: self.blocked_steps,
            router: Router::default(),
            planner: Planner::new(),
        }
    }

    /// Spawns every squad's members at their slots of the first key point, on the ground,
    /// facing the first leg, and puts every walking agent already in `world` on the ground.
    pub fn start(
        ground: Option<Arc<Ground>>,
        setups: &[SquadSetup],
        world: &mut World,
        pipeline: &mut Pipeline,
    ) -> Squads {
        let mut out = Squads {
            ground: ground.clone(),
            ..Squads::default()
        };
        let Some(g) = ground else {
            return out;
        };
        world.terrain = Some(g.terrain.clone());
        for s in setups {
            out.add(s, world, pipeline);
        }
        let set = pipeline.species.clone();
        out.settle(world, &set, false);
        for a in &mut world.agents {
            a.prev_pos = a.pos;
        }
        out
    }

    /// Spawns the members of one more squad at its slots of the first key point, on the ground,
    /// facing the first leg, and returns their ids by member index (what [`Squads::start`] does
    /// for each squad). The squad's species needs a grid in `self.ground`; nothing happens
    /// without ground.
    pub fn add(
        &mut self,
        s: &SquadSetup,
        world: &mut World,
        pipeline: &mut Pipeline,
    ) -> Vec<AgentId> {
        let Some(g) = self.ground.clone() else {
            return Vec::new();
        };
        let grid = g.grids[s.species].clone().expect("checked at load");
        let h = key_headings(&s.plan.key_points)[0];
        let yaw = crate::frame::heading_of(Vec3::new(h.x, 0.0, h.y)).map_or(0.0, |x| x.0);
        let members: Vec<AgentId> = s
            .plan
            .member_paths
            .iter()
            .map(|mp| {
                let p = mp.waypoints[0];
                let p = if route::free_at(&grid, p) {
                    p
                } else {
                    route::nearest_free(&grid, p, route::NEAREST_FREE_RADIUS).unwrap_or(p)
                };
                pipeline.spawn(world, s.species, on_ground(&g.terrain, p), yaw, 0.0)
            })
            .collect();
        let k = self.squads.len();
        self.squads.push(Squad::new(k, s, members.clone(), &g));
        members
    }

    /// Puts every walking agent on the ground (their pitch along the slope), as at the start.
    pub fn settle_all(&mut self, world: &mut World, set: &SpeciesSet) {
        self.settle(world, set, false);
    }

    /// Puts every walking agent on the ground; with `cut_blocked`, steps that ended on a
    /// blocked cell are cut back and counted.
    fn settle(&mut self, world: &mut World, set: &SpeciesSet, cut_blocked: bool) {
        let Some(g) = &self.ground else {
            return;
        };
        for a in &mut world.agents {
            let Some(sp) = set.species.get(a.species.0 as usize) else {
                continue;
            };
            if !sp.def.body.on_ground {
                continue;
            }
            let grid = if cut_blocked {
                g.grids.get(a.species.0 as usize).cloned().flatten()
            } else {
                None
            };
            let limit = sp.def.body.limits.pitch_limit();
            if ground::settle(a, &g.terrain, grid.as_deref(), limit) == ground::Settled::Blocked {
                self.blocked_steps += 1;
                if let Some(sq) = self.squads.iter_mut().find(|s| s.members.contains(&a.id)) {
                    sq.stats.blocked_steps += 1;
                }
            }
        }
    }
}
