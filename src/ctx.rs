//! What an agent's pass reads this tick (stages 3–6): the world as it was at the start of the
//! tick, perception's rows, its species and its own record — and the values of seed 000 §3's
//! condition and weight expressions computed from them. Decision (stage 4) and steering (stage 5)
//! both read it; it lives below both so that neither imports the other's context.

use crate::frame::Kinematics;
use crate::perception::{
    Category, GroupQueries, GroupQuery, GroupSum, Percept, Perception, Summary,
};
use crate::species::{AttrKind, DriveKind, Species, ValueNode};
use crate::world::{Agent, Mind, World};

/// What a condition or value may read about one agent this tick.
pub struct Ctx<'a> {
    /// The world at the start of the tick (during the agent pass, without its agents: what an
    /// agent reads of another is in `perception`).
    pub world: &'a World,
    /// Perception of the tick: also what every agent looked like at its start (velocity,
    /// radius, previous position).
    pub perception: &'a Perception,
    /// The agent's species.
    pub species: &'a Species,
    /// The agent (state at the start of the tick; drives already updated).
    pub agent: &'a Agent,
    /// Its percepts.
    pub percepts: &'a [Percept],
    /// Its summaries.
    pub summaries: &'a [Summary; Category::COUNT],
    /// The neighborhood sums its species' group rules read ([`crate::perception::Reads`])...
    pub group_queries: &'a GroupQueries,
    /// ... and its sums of them, in the same order, as perception keeps them: of each query
    /// the words it folds into ([`GroupQuery::words`]; empty where perception folded none).
    /// [`Ctx::group`] reads one back.
    pub group_sums: &'a [u32],
    /// Current tick.
    pub tick: u64,
    /// Time step.
    pub dt: f32,
}

impl Ctx<'_> {
    /// Kinematic state.
    pub fn kin(&self) -> Kinematics {
        Kinematics {
            pos: self.agent.pos,
            yaw: self.agent.yaw,
            pitch: self.agent.pitch,
            speed: self.agent.speed,
        }
    }
    /// The agent's sums of a group query, if perception folded them (only the one asked for
    /// is read back from its words).
    #[inline]
    pub fn group(&self, q: &GroupQuery) -> Option<GroupSum> {
        self.group_queries
            .packed(self.group_sums)
            .find(|(listed, _)| *listed == q)
            .map(|(_, words)| GroupSum::unpack(q, words))
    }
    /// Nearest percept of a category.
    pub fn nearest(&self, c: Category) -> Option<&Percept> {
        self.summaries[c as usize]
            .nearest
            .map(|i| &self.percepts[i as usize])
    }
    /// Seconds the agent has been in its current behavior.
    pub fn time_in_behavior(&self, mind: &Mind) -> f32 {
        self.tick.saturating_sub(mind.entered_tick) as f32 * self.dt
    }
}

/// Evaluates a value.
pub fn value(v: &ValueNode, ctx: &Ctx, mind: &Mind) -> f32 {
    match v {
        ValueNode::Const(x) => *x,
        ValueNode::Drive(d) => {
            let dr = &ctx.agent.drives;
            match d {
                DriveKind::Hunger => dr.hunger,
                DriveKind::Libido => dr.libido,
                DriveKind::Fear => dr.fear,
                DriveKind::Fatigue => dr.fatigue,
                DriveKind::State => dr.state,
            }
        }
        ValueNode::Distance(c) => ctx.summaries[*c as usize].nearest_dist,
        ValueNode::Count(c) => ctx.summaries[*c as usize].count as f32,
        // Seed 001: only the nearest's distance is read, and only here.
        ValueNode::Strength(c) => ctx
            .species
            .senses
            .strength
            .at(ctx.summaries[*c as usize].nearest_dist),
        ValueNode::Speed => ctx.agent.speed,
        ValueNode::TimeInBehavior => ctx.time_in_behavior(mind),
        ValueNode::Attribute(a) => match a {
            AttrKind::Age => ctx.agent.attrs.age,
            AttrKind::Mass => ctx.agent.attrs.mass,
        },
        ValueNode::KinSpeed => ctx.summaries[Category::Kin as usize].mean_velocity.length(),
        ValueNode::OneMinus(x) => 1.0 - value(x, ctx, mind),
        ValueNode::Mul(a, b) => value(a, ctx, mind) * value(b, ctx, mind),
        ValueNode::Add(a, b) => value(a, ctx, mind) + value(b, ctx, mind),
        ValueNode::Script(slot) => mind
            .script_values
            .get(*slot as usize)
            .copied()
            .unwrap_or(0.0),
    }
}
