//! What a squad's members read of it in their scripts (seed 004): the tables every member shares
//! ([`SquadShared`]), each member's view ([`SquadView`]) gathered for a tick on the [`Board`]
//! (published on `World::squads`), and the plans scripts make with `plan_path` ([`Planned`]),
//! adopted after the tick.
//!
//! Data the world holds, so it lives here (the world imports nothing above it: formations and
//! terrain sit below it); `crate::squad` fills it between ticks and re-exports every type.

use super::AgentId;
use crate::formation::{Formation, Plan, PlanningParams, TaskClass};
use crate::terrain::{CostGrid, Terrain};
use glam::{Vec2, Vec3};
use std::sync::{Arc, Mutex};

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
    pub(crate) views: Vec<(AgentId, SquadView)>,
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
