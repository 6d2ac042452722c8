//! One squad at run time (seed 004): its plan, the leader's progress along the key points, each
//! member's slot at that progress, its running measures, and adopting a new plan (from a script
//! or a re-plan from the leader's position).

use super::{Ground, SquadSetup, FINISH_RADIUS, LOOKAHEAD};
use crate::formation::{Formation, Plan, PlanRequest, Planner, PlanningParams, TaskClass};
use crate::terrain::{CostGrid, Terrain};
use crate::world::board::{SquadShared, TransitionRow};
use crate::world::AgentId;
use glam::{Vec2, Vec3};
use std::sync::Arc;

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
/// Whether a follower is blocked: its best distance from its slot, how long since it improved
/// on it, its detour and how many times in a row it was found blocked.
pub(super) struct Tracker {
    pub(super) tracking: bool,
    pub(super) best: f32,
    pub(super) since: u32,
    pub(super) detour_until: u64,
    pub(super) strikes: u32,
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
    pub(super) terrain: Arc<Terrain>,
    pub(super) shared: Arc<SquadShared>,
    pub(super) trackers: Vec<Tracker>,
    pub(super) prev_slots: Vec<Vec2>,
    pub(super) leader_best: f32,
    pub(super) leader_since: u32,
    pub(super) last_replan: Option<u64>,
}

/// The fraction of segment `a`–`b` at `p`'s projection on it, in [0, 1] (1 for a point segment).
fn project(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// Distance from `p` to segment `a`–`b`.
fn dist_to_segment(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    p.distance(a.lerp(b, project(p, a, b)))
}

/// The ground under world `(x, z)` point `p`.
pub(super) fn on_ground(t: &Terrain, p: Vec2) -> Vec3 {
    Vec3::new(p.x, t.height_at(p.x, p.y), p.y)
}

impl Squad {
    pub(super) fn new(
        index: usize,
        setup: &SquadSetup,
        members: Vec<AgentId>,
        ground: &Ground,
    ) -> Squad {
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

    pub(super) fn adopt(&mut self, plan: Plan, order: Vec<usize>, task: TaskClass, goal: Vec2) {
        self.plan = plan;
        self.order = order;
        self.task = task;
        self.goal = goal;
        self.reset_plan_state();
    }

    /// Re-plans from the leader's position `from` to the same goal; `false` when no path.
    pub(super) fn replan(&mut self, planner: &mut Planner, from: Vec2) -> bool {
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
