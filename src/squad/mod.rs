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

pub mod ground;
pub mod record;
pub mod route;
pub mod script;
pub mod setup;

pub use setup::{shape_named, task_named, SquadSetup, SHAPE_NAMES};

use crate::formation::follow::key_headings;
use crate::formation::{Formation, Plan, PlanRequest, Planner, PlanningParams, TaskClass};
use crate::species::SpeciesSet;
use crate::terrain::{CostGrid, Terrain};
use crate::tick::Pipeline;
use crate::world::{AgentId, World};
use glam::{Vec2, Vec3};
use route::Router;
use std::sync::{Arc, Mutex};

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

/// A plan made by a script's `plan_path`, adopted after the tick.
#[derive(Debug, Clone)]
pub struct Planned {
    /// Who asked.
    pub agent: AgentId,
    /// The new goal, world `(x, z)`.
    pub goal: Vec2,
    /// The formation list of the plan, as indices into the squad's formations.
    pub order: Vec<usize>,
    /// The task class planned with.
    pub task: TaskClass,
    /// The plan.
    pub plan: Plan,
}

/// A row of the transition table as scripts see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransitionRow {
    /// Where the new formation holds, on the ground.
    pub at: Vec3,
    /// Formation before, as an index into the squad's formations.
    pub from: usize,
    /// Formation after.
    pub to: usize,
    /// Index of the key point at this place.
    pub key: usize,
}

/// What every member of a squad shares: the planning inputs and the current tables.
#[derive(Debug)]
pub struct SquadShared {
    /// Index of the squad in the scenario.
    pub squad: usize,
    /// The members' cost grid.
    pub grid: Arc<CostGrid>,
    /// The terrain.
    pub terrain: Arc<Terrain>,
    /// Every formation the squad may take, in the scenario's order.
    pub formations: Vec<Formation>,
    /// The current plan's formation list, as indices into `formations`.
    pub order: Vec<usize>,
    /// The leader's member index.
    pub leader: usize,
    /// Task class of the current plan.
    pub task: TaskClass,
    /// Seed 004's planning constants of the squad.
    pub planning: PlanningParams,
    /// Goal, on the ground.
    pub goal: Vec3,
    /// The key-point table, on the ground.
    pub key_points: Vec<Vec3>,
    /// The formation held at each key point, as an index into `formations`.
    pub key_formations: Vec<usize>,
    /// The transition table.
    pub transitions: Vec<TransitionRow>,
    /// Plans made by scripts during the tick.
    pub requests: Arc<Mutex<Vec<Planned>>>,
}

/// One member's view of its squad, bound into its script view.
#[derive(Debug, Clone)]
pub struct SquadView {
    /// Shared tables.
    pub shared: Arc<SquadShared>,
    /// The member's index in the squad.
    pub member: usize,
    /// Its slot at the leader's progress, on the ground (the leader's: its point on the path).
    pub slot: Vec3,
    /// The leader's position.
    pub leader_pos: Vec3,
    /// Whether the leader has reached the end of the path.
    pub at_goal: bool,
    /// Formation held now, as an index into the squad's formations.
    pub formation: usize,
    /// Why the last `plan_path` of this call failed ("" when none did).
    pub error: String,
}

impl SquadView {
    /// Whether this member leads.
    pub fn is_leader(&self) -> bool {
        self.member == self.shared.leader
    }
}

/// The squads' views for one tick, by agent id.
#[derive(Debug, Default)]
pub struct Board {
    views: Vec<(AgentId, SquadView)>,
}

impl Board {
    /// The view of agent `id`, if it is a squad member.
    pub fn view(&self, id: AgentId) -> Option<SquadView> {
        self.views
            .binary_search_by_key(&id, |(a, _)| *a)
            .ok()
            .map(|i| self.views[i].1.clone())
    }
}

/// The leader's progress along the key points.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Progress {
    /// Current leg (from key point `leg` to `leg + 1`).
    pub leg: usize,
    /// Fraction of the leg covered, in [0, 1]; never decreases on a leg.
    pub t: f32,
    /// The leader has reached the last key point.
    pub finished: bool,
}

/// Running measures of a squad.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SquadStats {
    /// Sum of the followers' distances from their slots, one sample per follower per tick.
    pub error_sum: f64,
    /// Number of samples in `error_sum`.
    pub error_samples: u64,
    /// Largest distance of a follower from its slot.
    pub error_max: f32,
    /// Steps of members cut back because they ended on a blocked cell.
    pub blocked_steps: u64,
    /// Times a follower was found blocked.
    pub stuck: u32,
    /// Member-ticks spent on a local detour.
    pub detour_ticks: u64,
    /// Re-plans made because a member was blocked.
    pub replans: u32,
    /// Re-plans that found no path (the old plan is kept).
    pub failed_replans: u32,
    /// Plans adopted from scripts' `plan_path`.
    pub script_plans: u32,
}

impl SquadStats {
    /// Mean distance of a follower from its slot over the run so far (m).
    pub fn mean_error(&self) -> f32 {
        if self.error_samples == 0 {
            0.0
        } else {
            (self.error_sum / self.error_samples as f64) as f32
        }
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct Tracker {
    tracking: bool,
    best: f32,
    since: u32,
    detour_until: u64,
    strikes: u32,
}

/// One squad at run time.
#[derive(Debug, Clone)]
pub struct Squad {
    /// Index in the scenario.
    pub index: usize,
    /// Species index of the members.
    pub species: usize,
    /// Member ids, by member index.
    pub members: Vec<AgentId>,
    /// The leader's member index.
    pub leader: usize,
    /// Every formation the squad may take, in the scenario's order.
    pub formations: Vec<Formation>,
    /// The current plan's formation list, as indices into `formations`.
    pub order: Vec<usize>,
    /// Task class of the current plan.
    pub task: TaskClass,
    /// Seed 004's planning constants of the squad (relaxation step, task-class factors, …).
    pub planning: PlanningParams,
    /// Goal, world `(x, z)`.
    pub goal: Vec2,
    /// The current plan.
    pub plan: Plan,
    /// The members' cost grid.
    pub grid: Arc<CostGrid>,
    /// The leader's progress along the plan.
    pub progress: Progress,
    /// Measures so far.
    pub stats: SquadStats,
    /// Each member's target of the last tick, on the ground.
    pub targets: Vec<Vec3>,
    terrain: Arc<Terrain>,
    shared: Arc<SquadShared>,
    trackers: Vec<Tracker>,
    prev_slots: Vec<Vec2>,
    leader_best: f32,
    leader_since: u32,
    last_replan: Option<u64>,
}

fn project(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

fn dist_to_segment(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    p.distance(a.lerp(b, project(p, a, b)))
}

fn on_ground(t: &Terrain, p: Vec2) -> Vec3 {
    Vec3::new(p.x, t.height_at(p.x, p.y), p.y)
}

impl Squad {
    fn new(index: usize, setup: &SquadSetup, members: Vec<AgentId>, ground: &Ground) -> Squad {
        let grid = ground.grids[setup.species]
            .clone()
            .expect("squad species walk (checked at load)");
        let n = members.len();
        let mut s = Squad {
            index,
            species: setup.species,
            members,
            leader: setup.leader,
            order: (0..setup.formations.len()).collect(),
            formations: setup.formations.clone(),
            task: setup.task,
            planning: setup.planning,
            goal: setup.goal,
            plan: setup.plan.clone(),
            grid,
            progress: Progress::default(),
            stats: SquadStats::default(),
            targets: vec![Vec3::ZERO; n],
            terrain: ground.terrain.clone(),
            shared: Arc::new(SquadShared {
                squad: index,
                grid: Arc::new(CostGrid::open(1, 1, 1.0, Vec2::ZERO)),
                terrain: ground.terrain.clone(),
                formations: Vec::new(),
                order: Vec::new(),
                leader: 0,
                task: setup.task,
                planning: setup.planning,
                goal: Vec3::ZERO,
                key_points: Vec::new(),
                key_formations: Vec::new(),
                transitions: Vec::new(),
                requests: Arc::default(),
            }),
            trackers: vec![Tracker::default(); n],
            prev_slots: Vec::new(),
            leader_best: 0.0,
            leader_since: 0,
            last_replan: None,
        };
        s.reset_plan_state();
        s
    }

    /// Rebuilds the shared tables and resets progress and trackers after a new plan.
    fn reset_plan_state(&mut self) {
        let t = &self.terrain;
        let requests = self.shared.requests.clone();
        self.shared = Arc::new(SquadShared {
            squad: self.index,
            grid: self.grid.clone(),
            terrain: t.clone(),
            formations: self.formations.clone(),
            order: self.order.clone(),
            leader: self.leader,
            task: self.task,
            planning: self.planning,
            goal: on_ground(t, self.goal),
            key_points: self
                .plan
                .key_points
                .iter()
                .map(|k| on_ground(t, k.pos))
                .collect(),
            key_formations: self
                .plan
                .key_points
                .iter()
                .enumerate()
                .map(|(j, k)| self.order[self.plan.held.get(j).copied().unwrap_or(k.formation)])
                .collect(),
            transitions: self
                .plan
                .transitions
                .iter()
                .map(|x| TransitionRow {
                    at: on_ground(t, x.pos),
                    from: self.order[x.from],
                    to: self.order[x.to],
                    key: x.key_index,
                })
                .collect(),
            requests,
        });
        self.progress = Progress::default();
        self.trackers = vec![Tracker::default(); self.members.len()];
        self.prev_slots = (0..self.members.len()).map(|m| self.slot(m)).collect();
        self.leader_best = 0.0;
        self.leader_since = 0;
    }

    /// The shared tables members' scripts read.
    pub fn shared(&self) -> &Arc<SquadShared> {
        &self.shared
    }

    /// The formation `i` of the current plan's list (an index held in the plan's tables) as an
    /// index into [`Squad::formations`].
    pub fn formation_of(&self, i: usize) -> usize {
        self.order[i]
    }

    /// Member `m`'s slot at the leader's progress, world `(x, z)`: its member path at the same
    /// fraction of the same leg; for the leader, its point on the key-point path.
    pub fn slot(&self, m: usize) -> Vec2 {
        let keys = &self.plan.key_points;
        let Progress { leg, t, .. } = self.progress;
        if keys.len() < 2 {
            return self.plan.member_paths[m].waypoints[0];
        }
        if m == self.leader {
            keys[leg].pos.lerp(keys[leg + 1].pos, t)
        } else {
            self.plan.member_paths[m].position_at(leg, t)
        }
    }

    /// Member `m`'s slot at the goal.
    pub fn final_slot(&self, m: usize) -> Vec2 {
        *self.plan.member_paths[m]
            .waypoints
            .last()
            .expect("a plan has a key point")
    }

    /// Distance covered along the key points (m).
    pub fn distance_done(&self) -> f32 {
        let keys = &self.plan.key_points;
        if keys.len() < 2 {
            return 0.0;
        }
        let before: f32 = keys[..=self.progress.leg]
            .windows(2)
            .map(|w| w[0].pos.distance(w[1].pos))
            .sum();
        before
            + self.progress.t
                * keys[self.progress.leg]
                    .pos
                    .distance(keys[self.progress.leg + 1].pos)
    }

    /// The formation held now, as an index into [`Squad::formations`]: the one the members'
    /// slots take at the start of the current leg ([`Plan::held`]; at the last key point once
    /// arrived). It is the key point's own formation except where a widening transition is held
    /// over the leg after it: there the squad still holds the narrow formation, and so does this.
    pub fn formation_now(&self) -> usize {
        let k = &self.plan.key_points;
        let i = if self.progress.finished {
            k.len() - 1
        } else {
            self.progress.leg
        };
        let f = self.plan.held.get(i).copied().unwrap_or(k[i].formation);
        self.order[f]
    }

    /// Advances the progress from the leader's position `p`: its projection on the current
    /// leg, moving to the next leg at the key point (or when the leader has cut the corner and
    /// is nearer the next leg).
    pub fn update_progress(&mut self, p: Vec2) {
        let keys = &self.plan.key_points;
        if keys.len() < 2 {
            self.progress.finished |= p.distance(keys[0].pos) <= FINISH_RADIUS;
            return;
        }
        if self.progress.finished {
            return;
        }
        loop {
            let leg = self.progress.leg;
            let (a, b) = (keys[leg].pos, keys[leg + 1].pos);
            self.progress.t = self.progress.t.max(project(p, a, b));
            if leg + 2 == keys.len() {
                if self.progress.t >= 1.0 - 1e-3 || p.distance(b) <= FINISH_RADIUS {
                    self.progress.t = 1.0;
                    self.progress.finished = true;
                }
                return;
            }
            let c = keys[leg + 2].pos;
            let past = self.progress.t >= 1.0 - 1e-3
                || (p.distance(b) <= LOOKAHEAD
                    && dist_to_segment(p, b, c) < dist_to_segment(p, a, b));
            if !past {
                return;
            }
            self.progress.leg += 1;
            self.progress.t = 0.0;
        }
    }

    /// The point `dist` metres further along the key points than the leader's progress.
    pub fn point_ahead(&self, dist: f32) -> Vec2 {
        let keys = &self.plan.key_points;
        if keys.len() < 2 || self.progress.finished {
            return keys[keys.len() - 1].pos;
        }
        let mut leg = self.progress.leg;
        let mut pos = keys[leg].pos.lerp(keys[leg + 1].pos, self.progress.t);
        let mut left = dist;
        loop {
            let b = keys[leg + 1].pos;
            let d = pos.distance(b);
            if d >= left && d > 0.0 {
                return pos + (b - pos) / d * left;
            }
            left -= d;
            pos = b;
            leg += 1;
            if leg + 1 >= keys.len() {
                return pos;
            }
        }
    }

    fn adopt(&mut self, plan: Plan, order: Vec<usize>, task: TaskClass, goal: Vec2) {
        self.plan = plan;
        self.order = order;
        self.task = task;
        self.goal = goal;
        self.reset_plan_state();
    }

    /// Re-plans from the leader's position `from` to the same goal; `false` when no path.
    fn replan(&mut self, planner: &mut Planner, from: Vec2) -> bool {
        let formations: Vec<Formation> = self
            .order
            .iter()
            .map(|&i| self.formations[i].clone())
            .collect();
        match planner.plan(&PlanRequest {
            grid: &self.grid,
            start: from,
            goal: self.goal,
            formations: &formations,
            leader: self.leader,
            weights: self.task.weights_with(&self.planning),
        }) {
            Ok(p) => {
                let (order, task, goal) = (self.order.clone(), self.task, self.goal);
                self.adopt(p, order, task, goal);
                true
            }
            Err(_) => false,
        }
    }
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

    /// Sets every member's target in `pipeline.plan_targets` and publishes the squads' views on
    /// `world.squads`. Does nothing when there are no squads.
    pub fn before_tick(&mut self, world: &mut World, pipeline: &mut Pipeline) {
        if self.squads.is_empty() {
            return;
        }
        let n = world.agents.len();
        pipeline.plan_targets.clear();
        pipeline.plan_targets.resize(n, None);
        let mut views = Vec::new();
        let dt = world.dt.max(1e-6);
        for sq in &mut self.squads {
            let idx: Vec<Option<usize>> =
                sq.members.iter().map(|&id| world.agent_index(id)).collect();
            let Some(li) = idx[sq.leader] else {
                continue;
            };
            let lp = world.agents[li].pos;
            sq.update_progress(Vec2::new(lp.x, lp.z));
            let slots: Vec<Vec2> = (0..sq.members.len()).map(|m| sq.slot(m)).collect();
            let xz = |i: usize| Vec2::new(world.agents[i].pos.x, world.agents[i].pos.z);
            let max_lag = idx
                .iter()
                .enumerate()
                .filter(|&(m, _)| m != sq.leader)
                .filter_map(|(m, i)| i.map(|i| xz(i).distance(slots[m])))
                .fold(0.0f32, f32::max);
            let go = ((LAG_STOP - max_lag) / (LAG_STOP - LAG_GO)).clamp(0.0, 1.0);
            let vmax = pipeline
                .species
                .species
                .get(sq.species)
                .map_or(1.0, |s| s.def.body.limits.max_speed)
                .max(1e-3);
            let shared = sq.shared.clone();
            let formation = sq.formation_now();
            for (m, i) in idx.iter().enumerate() {
                let Some(i) = *i else { continue };
                let want = if m == sq.leader {
                    sq.point_ahead(LOOKAHEAD * go)
                } else {
                    // Lead the slot by the lag of `arrive` at the slot's speed (v / v_max).
                    let v = (slots[m] - sq.prev_slots[m]) / dt;
                    slots[m] + (v / vmax).clamp_length_max(1.0)
                };
                let force = sq.trackers[m].detour_until > world.tick;
                let (to, detour) = self.router.route(&sq.grid, xz(i), want, CLEARANCE, force);
                sq.stats.detour_ticks += u64::from(detour);
                let target = on_ground(&sq.terrain, to);
                sq.targets[m] = target;
                pipeline.plan_targets[i] = Some(target);
                views.push((
                    sq.members[m],
                    SquadView {
                        shared: shared.clone(),
                        member: m,
                        slot: on_ground(&sq.terrain, slots[m]),
                        leader_pos: lp,
                        at_goal: sq.progress.finished,
                        formation,
                        error: String::new(),
                    },
                ));
            }
            sq.prev_slots = slots;
        }
        views.sort_by_key(|(id, _)| *id);
        world.squads = Some(Arc::new(Board { views }));
    }

    /// Puts walking agents on the ground, adopts plans made by scripts, measures the formation
    /// error and re-plans blocked squads.
    pub fn after_tick(&mut self, world: &mut World, set: &SpeciesSet) {
        self.settle(world, set, true);
        let dt = world.dt.max(1e-6);
        let tick = world.tick;
        for sq in &mut self.squads {
            let mut asked =
                std::mem::take(&mut *sq.shared.requests.lock().unwrap_or_else(|e| e.into_inner()));
            // Several members may ask in one tick: the last in id order wins.
            asked.sort_by_key(|p| p.agent);
            if let Some(p) = asked.pop() {
                sq.adopt(p.plan, p.order, p.task, p.goal);
                sq.stats.script_plans += 1;
            }
            let idx: Vec<Option<usize>> =
                sq.members.iter().map(|&id| world.agent_index(id)).collect();
            let Some(li) = idx[sq.leader] else {
                continue;
            };
            let xz = |i: usize| Vec2::new(world.agents[i].pos.x, world.agents[i].pos.z);
            let lp = xz(li);
            sq.update_progress(lp);
            let mut max_lag = 0.0f32;
            let mut strikes = false;
            for (m, i) in idx.iter().enumerate() {
                let Some(i) = *i else { continue };
                if m == sq.leader {
                    continue;
                }
                let d = xz(i).distance(sq.slot(m));
                max_lag = max_lag.max(d);
                sq.stats.error_sum += f64::from(d);
                sq.stats.error_samples += 1;
                sq.stats.error_max = sq.stats.error_max.max(d);
                let tr = &mut sq.trackers[m];
                if d < STUCK_MIN_DIST {
                    tr.tracking = false;
                    tr.strikes = 0;
                } else if !tr.tracking || d < tr.best - STUCK_GAIN {
                    tr.tracking = true;
                    tr.best = d;
                    tr.since = 0;
                } else {
                    tr.since += 1;
                    if tr.since as f32 * dt >= STUCK_SECONDS {
                        sq.stats.stuck += 1;
                        tr.since = 0;
                        tr.best = d;
                        tr.detour_until = tick + (DETOUR_SECONDS / dt) as u64;
                        tr.strikes += 1;
                        strikes |= tr.strikes >= 2;
                    }
                }
            }
            let waiting = max_lag > LAG_GO;
            let done = sq.distance_done();
            if done > sq.leader_best + 0.5 {
                sq.leader_best = done;
                sq.leader_since = 0;
            } else if !waiting && !sq.progress.finished {
                sq.leader_since += 1;
            }
            let stalled = sq.leader_since as f32 * dt >= LEADER_STALL_SECONDS;
            let cooled = sq
                .last_replan
                .is_none_or(|t| (tick - t) as f32 * dt >= REPLAN_COOLDOWN);
            if (strikes || stalled) && cooled && !sq.progress.finished {
                sq.last_replan = Some(tick);
                if sq.replan(&mut self.planner, lp) {
                    sq.stats.replans += 1;
                } else {
                    sq.stats.failed_replans += 1;
                    sq.leader_since = 0;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formation::{Shape, TaskClass};

    /// A flat 40 × 40 terrain of 1 m cells and a squad of three in a line (spacing 2) whose
    /// plan runs from (5.5, 5.5) east to (30.5, 5.5), then south to (30.5, 30.5).
    fn squad() -> Squad {
        let terrain = Arc::new(Terrain::from_heights(
            40,
            40,
            1.0,
            Vec2::ZERO,
            vec![0.0; 1600],
        ));
        let grid = Arc::new(CostGrid::open(40, 40, 1.0, Vec2::ZERO));
        let formations = vec![Formation::new(&Shape::Line, 3, 2.0).unwrap()];
        let key = |c: usize, r: usize, i: usize| crate::formation::KeyPoint {
            cell: crate::terrain::Cell::new(c, r),
            pos: Vec2::new(c as f32 + 0.5, r as f32 + 0.5),
            formation: 0,
            path_index: i,
        };
        let key_points = vec![key(5, 5, 0), key(30, 5, 25), key(30, 30, 50)];
        let plan = Plan {
            leader: 0,
            leader_cells: Vec::new(),
            leader_path: Vec::new(),
            formation_along: Vec::new(),
            member_paths: crate::formation::member_paths(&key_points, &formations, 0),
            held: vec![0; key_points.len()],
            key_points,
            transitions: Vec::new(),
            tried: vec![(0.1, 0.9)],
            cost: 50.0,
            expanded: 0,
        };
        let ground = Ground {
            terrain,
            grids: vec![Some(grid)],
        };
        let setup = SquadSetup {
            species: 0,
            formations,
            leader: 0,
            task: TaskClass::MayChangeRarely,
            planning: Default::default(),
            start: Vec2::new(5.5, 5.5),
            goal: Vec2::new(30.5, 30.5),
            plan,
        };
        Squad::new(0, &setup, vec![AgentId(0), AgentId(1), AgentId(2)], &ground)
    }

    #[test]
    fn progress_follows_the_leader_along_the_key_points() {
        let mut s = squad();
        let keys: Vec<Vec2> = s.plan.key_points.iter().map(|k| k.pos).collect();
        assert_eq!(keys.len(), 3, "{keys:?}");
        let len0 = keys[0].distance(keys[1]);
        // Halfway along the first leg, 1 m off the path: projected, not measured from the path.
        s.update_progress(keys[0].lerp(keys[1], 0.5) + Vec2::new(0.0, 1.0));
        assert_eq!(s.progress.leg, 0);
        assert!((s.progress.t - 0.5).abs() < 1e-5);
        assert!((s.distance_done() - 0.5 * len0).abs() < 1e-4);
        // Followers sit on their member paths at the same fraction.
        for m in 1..3 {
            assert_eq!(s.slot(m), s.plan.member_paths[m].position_at(0, 0.5));
        }
        assert_eq!(s.slot(0), keys[0].lerp(keys[1], 0.5));
        // Progress never goes back on a leg.
        s.update_progress(keys[0]);
        assert!((s.progress.t - 0.5).abs() < 1e-5);
        // 3 m ahead along the path, around the corner when it is near.
        assert_eq!(
            s.point_ahead(3.0),
            keys[0].lerp(keys[1], 0.5) + (keys[1] - keys[0]).normalize() * 3.0
        );
        s.update_progress(keys[1] - Vec2::new(1.0, 0.0));
        let ahead = s.point_ahead(3.0);
        assert!(
            (ahead - (keys[1] + (keys[2] - keys[1]).normalize() * 2.0)).length() < 1e-4,
            "{ahead}"
        );
        // Cutting the corner: nearer the second leg and close to the key point, the leader is on it.
        s.update_progress(keys[1] + Vec2::new(-0.3, 1.5));
        assert_eq!(s.progress.leg, 1);
        assert!(s.progress.t > 0.0 && s.progress.t < 0.1);
        assert!(!s.progress.finished);
        // Within a metre of the goal it has arrived: slots are the final ones.
        s.update_progress(keys[2] - Vec2::new(0.0, 0.8));
        assert!(s.progress.finished);
        for m in 0..3 {
            assert_eq!(s.slot(m), s.final_slot(m));
        }
        assert_eq!(s.point_ahead(3.0), keys[2]);
    }

    #[test]
    fn big_terrains_are_downsampled_for_the_viewer() {
        let (cols, rows) = (1030, 520);
        let heights = (0..cols * rows).map(|i| (i % cols) as f32).collect();
        let terrain = Terrain::from_heights(cols, rows, 1.0, Vec2::new(-5.0, 7.0), heights);
        let mut grid = CostGrid::open(cols, rows, 1.0, Vec2::new(-5.0, 7.0));
        grid.blocked[cols + 5] = true; // cell (5, 1): in block (1, 0) when k = 3
        let squads = Squads {
            ground: Some(Arc::new(Ground {
                terrain: Arc::new(terrain),
                grids: vec![Some(Arc::new(grid))],
            })),
            ..Squads::default()
        };
        let v = record::terrain_json(&squads);
        // 1030 × 520 > 512²; halved it is still 515 × 260 = 133,900 ≤ 262,144: k = 2.
        assert_eq!(v["cols"], 515);
        assert_eq!(v["rows"], 260);
        assert_eq!(v["cell"], 2.0);
        let h = v["heights"].as_array().unwrap();
        assert_eq!(h.len(), 515 * 260);
        // Block 1 covers cells 2–3 (centres at heights 2 and 3); its centre is between them.
        assert_eq!(h[1], 2.5);
        let b = v["blocked"].as_array().unwrap();
        assert_eq!(b[2], 1);
        assert_eq!(b.iter().filter(|x| x.as_u64() == Some(1)).count(), 1);
        assert_eq!(record::plans_json(&squads), serde_json::json!([]));
        assert_eq!(
            record::terrain_json(&Squads::default()),
            serde_json::Value::Null
        );
    }
}
