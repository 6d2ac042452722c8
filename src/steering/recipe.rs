//! Evaluating a behavior's steering recipe (a primitive, a priority list or a weighted blend) for
//! one agent, every tick, from its percepts. Script-built recipes are cached terms evaluated here
//! natively.

use super::avoid::{self, MovingObstacle};
use super::group::{self, Neighbor};
use super::{blend_from, escape, goal, wander, Blend, Kinematics, Steer, Term};
use crate::ctx::{self, Ctx};
use crate::perception::{Category, GroupQuery, GroupSum, Percept, Sense, Source};
use crate::species::{Recipe, RecipeNode, Target};
use crate::world::{Mind, Rng};
use glam::Vec3;

/// Scratch buffers reused across agents by one worker.
#[derive(Debug, Default)]
pub struct Scratch {
    neighbors: Vec<Neighbor>,
    kin_ready: bool,
    own_velocity: Option<Vec3>,
    /// The reach of the agent's senses (`query_radius`), worked out once per agent.
    reach: Option<f32>,
    moving: Vec<MovingObstacle>,
    /// Position of a planned-path target, if the agent follows a plan.
    pub plan_target: Option<Vec3>,
    /// The percepts a focused behavior steers from ([`crate::decision::focus`]), reused.
    pub focused: Vec<Percept>,
}

impl Scratch {
    /// Clears per-agent state.
    pub fn reset(&mut self) {
        self.kin_ready = false;
        self.own_velocity = None;
        self.reach = None;
        self.plan_target = None;
    }
    /// Gives the agent's own velocity when it is already known (`kin.velocity()`, bit for bit).
    pub fn set_velocity(&mut self, v: Option<Vec3>) {
        self.own_velocity = v;
    }
    /// The agent's own velocity (`kin.velocity()`, two `sin_cos`), computed once per agent.
    fn velocity(&mut self, kin: &Kinematics) -> Vec3 {
        *self.own_velocity.get_or_insert_with(|| kin.velocity())
    }
    fn kin<'a>(&'a mut self, ctx: &Ctx) -> &'a [Neighbor] {
        if !self.kin_ready {
            self.neighbors.clear();
            for p in ctx.percepts {
                if let (Source::Agent(j), Category::Kin | Category::Mate) =
                    (p.source(), p.category())
                {
                    let Some(velocity) = ctx.perception.velocity(j as usize) else {
                        continue;
                    };
                    self.neighbors.push(Neighbor {
                        offset: p.offset,
                        dist: p.dist,
                        velocity,
                    });
                }
            }
            self.kin_ready = true;
        }
        &self.neighbors
    }
}

fn target_point(t: &Target, ctx: &Ctx, station: Option<Vec3>) -> Option<Vec3> {
    match *t {
        Target::Nearest(c) => ctx.nearest(c).map(|p| ctx.agent.pos + p.offset),
        Target::Centroid(c) => {
            (ctx.summaries[c as usize].count > 0).then(|| ctx.summaries[c as usize].centroid)
        }
        Target::Point(p) => Some(p),
        Target::Home => Some(ctx.world.bounds.center()),
        Target::Station => station,
    }
}

fn force(velocity: Vec3, f: Vec3) -> Steer {
    if f == Vec3::ZERO || !f.is_finite() {
        Steer::None
    } else {
        Steer::Velocity(velocity + f)
    }
}

/// The neighborhood sums a group rule reads, for a species whose perception reaches `reach`;
/// `None` for other primitives, and for alignment and cohesion over every neighbor perceived
/// (the kin summary's means give them).
pub fn group_query(r: &Recipe, reach: f32) -> Option<GroupQuery> {
    match r {
        Recipe::Separation(g) => Some(GroupQuery::Separation { radius: g.radius }),
        Recipe::Alignment(g) | Recipe::Cohesion(g) => {
            (g.radius < reach).then_some(GroupQuery::Mean { radius: g.radius })
        }
        Recipe::Zones(z) => Some(z.query()),
        Recipe::Vicsek(v) => Some(GroupQuery::Headings { radius: v.radius }),
        _ => None,
    }
}

/// The agent's sums of `q`: folded by perception over every kin perceived, or (for a context
/// built without them) over the kin among its kept percepts.
fn group_sum(ctx: &Ctx, scratch: &mut Scratch, q: &GroupQuery) -> GroupSum {
    ctx.group(q)
        .unwrap_or_else(|| group::fold(scratch.kin(ctx), q))
}

/// Evaluates a leaf primitive.
fn leaf(
    r: &Recipe,
    ctx: &Ctx,
    station: Option<Vec3>,
    rng: &mut Rng,
    scratch: &mut Scratch,
) -> Steer {
    let kin = ctx.kin();
    let limits = &ctx.species.body.limits;
    let vmax = limits.max_speed;
    let vr = ctx.species.senses.vision_radius;
    match r {
        Recipe::AvoidStatic(p) => avoid::avoid_static(
            &kin,
            ctx.static_pressures(p),
            vr,
            ctx.agent.diagonal(),
            vmax,
            ctx.dt,
            p,
        ),
        Recipe::AvoidDynamic(p) => {
            let mut v = std::mem::take(&mut scratch.moving);
            ctx.moving_obstacles(p, &mut v);
            let half_angle = ctx.species.senses.vision_half_angle;
            let size = ctx.agent.diagonal();
            let s = avoid::avoid_dynamic(&kin, &v, vr, half_angle, size, ctx.dt, p);
            scratch.moving = v;
            s
        }
        Recipe::PredictCollision(l) => {
            let obstacles = ctx.percepts.iter().filter_map(|p| match p.source() {
                Source::Obstacle(k) => {
                    let o = &ctx.world.obstacles[k as usize];
                    Some((
                        o.shape.center(),
                        o.shape.bounding_radius() + ctx.agent.radius(),
                    ))
                }
                _ => None,
            });
            avoid::predict_collision(&kin, obstacles, l.horizon, l.margin, vmax)
        }
        Recipe::Contain(l) => {
            // The agent's cached forward vector is its kin's (same heading).
            let forward = ctx.agent.forward();
            avoid::contain_facing(&kin, forward, &ctx.world.bounds, l.margin, l.horizon, vmax)
        }
        Recipe::Chase(c) => match ctx.nearest(c.target) {
            None => Steer::None,
            Some(p) if p.sense() == Sense::Vision => {
                goal::goal_by_vision(p.bearing, p.elevation, p.dist, c.d0, vmax, &c.rules())
            }
            Some(p) => goal::goal_by_smell(p.bearing, p.elevation, vmax, &c.rules()),
        },
        Recipe::Escape(e) => match ctx.nearest(e.from) {
            None => Steer::None,
            Some(p) if e.paper && p.sense() == Sense::Vision => {
                escape::escape_by_vision(p.bearing, p.elevation, p.dist, vr, vmax, &e.rules())
            }
            Some(p) if e.paper => {
                escape::escape_by_smell(p.bearing, p.elevation, kin.speed, vmax, &e.rules())
            }
            Some(p) => escape::escape_leveled(
                p.sense() == Sense::Vision,
                p.bearing,
                p.elevation,
                kin.pitch,
                p.dist,
                vr,
                kin.speed,
                vmax,
                &e.rules(),
                &e.leveling(),
            ),
        },
        Recipe::EscapeMirror(e) => match ctx.nearest(e.from) {
            None => Steer::None,
            Some(p) => escape::escape_mirror(&kin, kin.pos + p.offset, vmax),
        },
        Recipe::Pursue(pd) => match ctx.nearest(pd.target) {
            None => Steer::None,
            Some(p) => {
                let now = kin.pos + p.offset;
                let before = match p.source() {
                    Source::Agent(j) => ctx.perception.prev_pos(j as usize).unwrap_or(now),
                    _ => now,
                };
                goal::pursue(&kin, now, before, ctx.dt, pd.prediction, vmax)
            }
        },
        Recipe::Seek(s) => target_point(&s.target, ctx, station)
            .map_or(Steer::None, |t| super::seek(&kin, t, vmax * s.speed)),
        Recipe::Flee(s) => target_point(&s.target, ctx, station)
            .map_or(Steer::None, |t| super::flee(&kin, t, vmax * s.speed)),
        Recipe::Arrive(s) => target_point(&s.target, ctx, station).map_or(Steer::None, |t| {
            super::arrive(&kin, t, vmax * s.speed, s.slow_radius)
        }),
        Recipe::HoldStation(h) => station.map_or(Steer::None, |t| {
            super::arrive(&kin, t, vmax * h.speed, h.slow_radius)
        }),
        Recipe::Separation(g) | Recipe::Alignment(g) | Recipe::Cohesion(g) => {
            let own_velocity = scratch.velocity(&kin);
            let m1 = ctx.agent.attrs.mass;
            let reach = *scratch
                .reach
                .get_or_insert_with(|| ctx.species.senses.query_radius());
            let f = match (r, group_query(r, reach)) {
                // Over every kin perceived: the kin summary's means.
                (Recipe::Alignment(_), None) => {
                    let sm = &ctx.summaries[Category::Kin as usize];
                    let mean = (sm.count > 0).then_some(sm.mean_velocity);
                    group::alignment_of(mean, own_velocity, m1, g.k)
                }
                (Recipe::Cohesion(_), None) => {
                    let sm = &ctx.summaries[Category::Kin as usize];
                    let mean = (sm.count > 0).then(|| sm.centroid - ctx.agent.pos);
                    group::cohesion_of(mean, g.k)
                }
                (_, Some(q)) => {
                    let sum = group_sum(ctx, scratch, &q);
                    match r {
                        Recipe::Separation(_) => {
                            group::separation_of(&sum, m1, g.k, ctx.agent.size.z, g.factor)
                        }
                        Recipe::Alignment(_) => {
                            group::alignment_of(group::mean(sum.b, sum.n), own_velocity, m1, g.k)
                        }
                        _ => group::cohesion_of(group::mean(sum.a, sum.n), g.k),
                    }
                }
                (_, None) => Vec3::ZERO,
            };
            force(own_velocity, f)
        }
        Recipe::Zones(z) => {
            let sum = group_sum(ctx, scratch, &z.query());
            group::ra_zones_of(&sum, kin.speed.max(0.5 * vmax))
        }
        Recipe::Vicsek(v) => {
            let u = (rng.next_f32(), rng.next_f32());
            let sum = group_sum(ctx, scratch, &GroupQuery::Headings { radius: v.radius });
            group::vicsek_of(kin.forward(), &sum, v.speed * vmax, v.noise, u)
        }
        Recipe::Disperse(d) => {
            // Seed 003 group escape (1): a fish slower than v_d re-draws its speed in
            // [V_min, V_max] and keeps its heading.
            group::disperse(kin.speed, d.below * vmax, limits.min_speed, vmax, rng)
        }
        Recipe::Wander(w) => {
            let u = (rng.next_f32(), rng.next_f32());
            wander::wander(kin.pitch, vmax, w, u)
        }
        Recipe::Cruise(c) => Steer::Turn {
            yaw: 0.0,
            pitch: -0.1 * kin.pitch,
            speed: c.speed * vmax,
        },
        Recipe::Stop => Steer::Turn {
            yaw: 0.0,
            pitch: 0.0,
            speed: 0.0,
        },
        Recipe::FollowPlan(c) => match scratch.plan_target {
            Some(t) => super::arrive(&kin, t, c.speed * vmax, 1.0),
            None => Steer::None,
        },
        // Composite recipes are resolved into `RecipeNode`s at load time.
        Recipe::Priority(_) | Recipe::Blend(_) | Recipe::Script(_) => Steer::None,
    }
}

/// Evaluates `node`, a child of a node at `depth`: a leaf (most children) directly, without a
/// nested [`evaluate`] (the same result: a leaf at depth 16 or less is evaluated, deeper gives
/// none).
#[inline(always)]
fn child(
    node: &RecipeNode,
    ctx: &Ctx,
    mind: &Mind,
    rng: &mut Rng,
    scratch: &mut Scratch,
    depth: u8,
) -> Steer {
    match node {
        RecipeNode::Leaf(r) if depth < 16 => leaf(r, ctx, mind.station(), rng, scratch),
        _ => evaluate(node, ctx, mind, rng, scratch, depth + 1),
    }
}

/// Evaluates a recipe node.
pub fn evaluate(
    node: &RecipeNode,
    ctx: &Ctx,
    mind: &Mind,
    rng: &mut Rng,
    scratch: &mut Scratch,
    depth: u8,
) -> Steer {
    if depth > 16 {
        return Steer::None;
    }
    match node {
        RecipeNode::Leaf(r) => leaf(r, ctx, mind.station(), rng, scratch),
        RecipeNode::Priority(v) => {
            for r in v {
                let s = child(r, ctx, mind, rng, scratch, depth);
                if !s.is_none() {
                    return s;
                }
            }
            Steer::None
        }
        RecipeNode::Blend(v) => {
            // `blend_from` over the parts, each folded in as soon as it is evaluated.
            let kin = ctx.kin();
            let current = scratch.velocity(&kin);
            let mut blend = Blend::new(current, &kin);
            for (w, by, r) in v.iter().take(16) {
                let f = by.as_ref().map_or(1.0, |b| ctx::value(b, ctx, mind));
                let weight = w * f;
                if weight != 0.0 {
                    blend.add(weight, child(r, ctx, mind, rng, scratch, depth));
                }
            }
            blend.finish()
        }
        RecipeNode::Script(slot) => {
            let kin = ctx.kin();
            let Some(terms) = mind.script_steer.get(*slot as usize) else {
                return Steer::None;
            };
            let mut parts: [(f32, Steer); 8] = [(0.0, Steer::None); 8];
            let n = terms.len().min(8);
            for (k, (w, t)) in terms.iter().take(8).enumerate() {
                let s = match *t {
                    Term::Recipe(i) => ctx
                        .species
                        .recipes
                        .get(i as usize)
                        .map_or(Steer::None, |r| {
                            evaluate(r, ctx, mind, rng, scratch, depth + 1)
                        }),
                    Term::Velocity(v) => Steer::Velocity(v),
                    Term::Turn(y, p, s) => Steer::Turn {
                        yaw: y,
                        pitch: p,
                        speed: s,
                    },
                };
                parts[k] = (*w, s);
            }
            if n == 1 && parts[0].0 == 1.0 {
                parts[0].1
            } else {
                blend_from(scratch.velocity(&kin), &kin, parts[..n].iter().copied())
            }
        }
    }
}
