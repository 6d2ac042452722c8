//! What explains an agent's move, gathered during its pass when asked ([`Explain`]): per
//! explained frame, the steering term actually in control (the leaf that won a priority list,
//! the heaviest part of a blend), its target and distance, the steering vector, avoid pressures,
//! a pursuit's predicted intercept point, the percepts, time in behavior, the blackboard and
//! "why not" for the higher-priority behaviors; per decision, every clause of the condition that
//! fired with its value, the script conditions' results and the blackboard.
//!
//! Read-only observation: every condition and recipe is re-evaluated on copies of the agent's
//! mind and random stream, so the run is bit for bit the same with explaining on or off
//! (`tests/explain.rs` checks it). The values are what the agent saw at the start of the tick.

use crate::ctx::{value, Ctx};
use crate::decision::{self, focus, Transitions};
use crate::perception::{Category, Percept, Source};
use crate::species::{
    Behavior, CondNode, Recipe, RecipeNode, SlotKind, Species, Target, ValueNode,
};
use crate::steering::recipe::{self, Scratch};
use crate::steering::{avoid, goal, Steer};
use crate::world::{Agent, MemValue, Mind, Rng};
use glam::Vec3;
use serde_json::{json, Map, Value};

/// What a tick explains. The default explains nothing and costs nothing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Explain {
    /// Explain every agent's frame on the ticks after which `tick % every == 0` (the recorded
    /// frames of a recording with this interval), and every decision of every tick; 0: off.
    pub every: u32,
    /// Explain only this agent (by id), every tick (the live page's selected agent).
    pub only: Option<u32>,
}

impl Explain {
    /// Whether anything is explained at all.
    pub fn on(&self) -> bool {
        self.every > 0 || self.only.is_some()
    }
    /// Whether agent `id`'s pass during tick `tick` (which produces tick `tick + 1`) explains
    /// its frame; its decisions are explained whenever [`Explain::covers`] holds.
    pub fn frame(&self, tick: u64, id: u32) -> bool {
        match self.only {
            Some(o) => o == id,
            None => self.every > 0 && (tick + 1).is_multiple_of(self.every as u64),
        }
    }
    /// Whether agent `id`'s decisions are explained.
    pub fn covers(&self, id: u32) -> bool {
        match self.only {
            Some(o) => o == id,
            None => self.every > 0,
        }
    }
}

/// One agent's explanations of a tick.
#[derive(Debug, Default)]
pub(crate) struct Explained {
    pub(crate) decision: Option<Value>,
    pub(crate) frame: Option<Value>,
}

/// What arbitration reads and may change, saved before it so that the decision can be
/// re-evaluated as it was made.
#[derive(Clone, Copy)]
pub(super) struct Before {
    latches: u64,
    entered_tick: u64,
    current: u16,
    rng: Rng,
}

impl Before {
    /// The state before arbitration.
    pub(super) fn of(mind: &Mind, rng: &Rng) -> Before {
        Before {
            latches: mind.latches,
            entered_tick: mind.entered_tick,
            current: mind.current,
            rng: *rng,
        }
    }
    /// A copy of `mind` as it was before arbitration (what conditions read of it).
    fn mind(&self, mind: &Mind) -> Mind {
        let mut m = mind.clone();
        m.latches = self.latches;
        m.entered_tick = self.entered_tick;
        m.current = self.current;
        m
    }
}

/// A number rounded to 1e-4, so the file stays short.
fn r(x: f32) -> Value {
    if !x.is_finite() {
        return Value::Null;
    }
    json!(((x as f64) * 1e4).round() / 1e4)
}

fn v3(v: Vec3) -> Value {
    json!([r(v.x), r(v.y), r(v.z)])
}

/// The name of an enum variant from its debug text (`AvoidStatic(..)` → `AvoidStatic`).
fn variant(debug: String) -> String {
    let end = debug
        .find(|c: char| !c.is_alphanumeric() && c != '_')
        .unwrap_or(debug.len());
    debug[..end].to_string()
}

fn slot_name(sp: &Species, slot: u16, steer: bool) -> String {
    sp.slots
        .iter()
        .find(|s| s.index == slot && (s.kind == SlotKind::Steer) == steer)
        .map_or_else(|| format!("slot {slot}"), |s| s.name.clone())
}

/// A value expression as text.
fn value_text(v: &ValueNode, sp: &Species) -> String {
    match v {
        ValueNode::Const(x) => format!("{x}"),
        ValueNode::Drive(d) => format!("{d:?}").to_lowercase(),
        ValueNode::Distance(c) => format!("distance({c:?})"),
        ValueNode::Count(c) => format!("count({c:?})"),
        ValueNode::Strength(c) => format!("strength({c:?})"),
        ValueNode::Speed => "speed".into(),
        ValueNode::TimeInBehavior => "time_in_behavior".into(),
        ValueNode::Attribute(a) => format!("{a:?}").to_lowercase(),
        ValueNode::KinSpeed => "kin_speed".into(),
        ValueNode::OneMinus(x) => format!("1 - {}", value_text(x, sp)),
        ValueNode::Mul(a, b) => format!("{} * {}", value_text(a, sp), value_text(b, sp)),
        ValueNode::Add(a, b) => format!("{} + {}", value_text(a, sp), value_text(b, sp)),
        ValueNode::Script(s) => format!("{}()", slot_name(sp, *s, false)),
    }
}

/// A condition's clauses with their values: `{c: text, v: held, x: value read, k: [clauses]}`.
/// Every clause of an `All`/`Any` is evaluated (no short cut), on the copies given.
pub fn clauses(c: &CondNode, ctx: &Ctx, mind: &mut Mind, rng: &mut Rng) -> Value {
    let sp = ctx.species;
    let node = |text: String, held: bool| json!({ "c": text, "v": held });
    match c {
        CondNode::All(v) | CondNode::Any(v) => {
            let k: Vec<Value> = v.iter().map(|c| clauses(c, ctx, mind, rng)).collect();
            let held = |k: &Value| k["v"] == Value::Bool(true);
            let (text, held) = match c {
                CondNode::All(_) => ("all", k.iter().all(held)),
                _ => ("any", k.iter().any(held)),
            };
            json!({ "c": text, "v": held, "k": k })
        }
        CondNode::Not(x) => {
            let k = clauses(x, ctx, mind, rng);
            let held = k["v"] != Value::Bool(true);
            json!({ "c": "not", "v": held, "k": [k] })
        }
        CondNode::Above(v, x) | CondNode::Below(v, x) => {
            let got = value(v, ctx, mind);
            let (op, held) = match c {
                CondNode::Above(..) => (">", got > *x),
                _ => ("<", got < *x),
            };
            json!({ "c": format!("{} {op} {x}", value_text(v, sp)), "v": held, "x": r(got) })
        }
        CondNode::Latch { on, off, .. } => {
            let held = decision::cond(c, ctx, &mut mind.clone(), &mut rng.clone());
            let k = [
                clauses(on, ctx, &mut mind.clone(), &mut rng.clone()),
                clauses(off, ctx, &mut mind.clone(), &mut rng.clone()),
            ];
            json!({ "c": "latch (on, off)", "v": held, "k": k })
        }
        CondNode::Script(slot) => {
            let got = mind
                .script_values
                .get(*slot as usize)
                .copied()
                .unwrap_or(0.0);
            json!({ "c": format!("{}()", slot_name(sp, *slot, false)), "v": got != 0.0, "x": r(got), "script": true })
        }
        CondNode::Within(k, d) => {
            let got = ctx.summaries[*k as usize].nearest_dist;
            json!({ "c": format!("within({k:?}, {d})"), "v": got <= *d, "x": r(got) })
        }
        CondNode::TimeIn(t) => {
            let got = ctx.time_in_behavior(mind);
            json!({ "c": format!("time_in({t})"), "v": got >= *t, "x": r(got) })
        }
        other => {
            let held = decision::cond(other, ctx, mind, rng);
            node(format!("{other:?}"), held)
        }
    }
}

/// The first clause that kept a condition from holding, as text.
fn failing(tree: &Value) -> String {
    let text = tree["c"].as_str().unwrap_or("?");
    match (text, tree["k"].as_array()) {
        ("all", Some(k)) => k
            .iter()
            .find(|k| k["v"] != Value::Bool(true))
            .map_or_else(|| "all".into(), failing),
        ("any", Some(k)) => {
            let parts: Vec<String> = k.iter().map(failing).collect();
            format!("none of: {}", parts.join("; "))
        }
        ("not", Some(k)) => format!("not ({} holds)", k[0]["c"].as_str().unwrap_or("?")),
        _ => match tree.get("x") {
            Some(x) => format!("{text} (is {x})"),
            None => text.to_string(),
        },
    }
}

/// Why each behavior ranked above `above` (by priority level) did not start: on cooldown, on
/// the stack, or the first clause of its `when` that failed.
fn why_not(ctx: &Ctx, mind: &Mind, rng: &Rng, above: u8, current: u16) -> Value {
    let sp = ctx.species;
    let mut out = Vec::new();
    for (i, b) in sp.behaviors.iter().enumerate() {
        // Steps of a sequence or fallback never start by their own `when`.
        let step = b
            .parent
            .is_some_and(|p| sp.behaviors[p as usize].compose != crate::species::Compose::Select);
        if b.priority >= above || i as u16 == current || step {
            continue;
        }
        let why = if !mind.cooldowns.ready(i as u16, ctx.tick) {
            "cooling down".to_string()
        } else if mind.stack().contains(&(i as u16)) {
            "on the stack".to_string()
        } else {
            let tree = clauses(&b.when, ctx, &mut mind.clone(), &mut rng.clone());
            if tree["v"] == Value::Bool(true) {
                "its `when` holds but it is done on entry".to_string()
            } else {
                failing(&tree)
            }
        };
        out.push(json!({ "b": &*b.name, "p": b.priority, "why": why }));
    }
    Value::Array(out)
}

/// The blackboard as a JSON object.
pub fn memory(a: &Agent) -> Value {
    let mut m = Map::new();
    for (k, v) in &a.memory {
        let v = match v {
            MemValue::Bool(b) => json!(b),
            MemValue::Int(i) => json!(i),
            MemValue::Float(f) => r(*f),
            MemValue::Vec3(p) => v3(*p),
            MemValue::Str(s) => json!(s),
        };
        m.insert(k.to_string(), v);
    }
    Value::Object(m)
}

/// The script conditions' and numbers' latest results.
fn scripts(sp: &Species, mind: &Mind) -> Value {
    let v: Vec<Value> = sp
        .slots
        .iter()
        .filter(|s| s.kind != SlotKind::Steer)
        .map(|s| {
            let got = mind.script_values.get(s.index as usize).copied();
            json!({ "f": s.name, "v": got.map_or(Value::Null, r) })
        })
        .collect();
    Value::Array(v)
}

/// In a species with composed behaviors, the condition that fired may belong to a composed
/// behavior above either end (an outer `done` or `fail`, an interrupting list member's `when`):
/// the one the transition records.
fn fired_in_tree<'a>(sp: &'a Species, t: &crate::decision::Transition) -> &'a CondNode {
    t.fired()
        .and_then(|c| c.node(sp))
        .unwrap_or(&sp.behaviors[t.from as usize].done)
}

/// One decision explained: `{type: "decision", tick, id, from, to, cause, clauses, why_not,
/// scripts, memory}`. `tick` is the tick the decision was made on (as in `events.jsonl`).
pub(super) fn decision(
    ctx: &Ctx,
    mind: &Mind,
    before: &Before,
    transitions: &Transitions,
    id: u32,
) -> Option<Value> {
    let sp = ctx.species;
    let first = transitions[0].as_ref()?;
    let last = transitions.iter().flatten().last()?;
    let mut m = before.mind(mind);
    let mut rng = before.rng;
    let fired: &CondNode = match first.cause {
        _ if sp.depth > 0 => fired_in_tree(sp, first),
        crate::events::Cause::Interrupted => &sp.behaviors[first.to as usize].when,
        _ => &sp.behaviors[first.from as usize].done,
    };
    let tree = clauses(fired, ctx, &mut m, &mut rng);
    let to: &Behavior = &sp.behaviors[last.to as usize];
    let why = why_not(ctx, &before.mind(mind), &before.rng, to.priority, last.to);
    Some(json!({
        "type": "decision",
        "tick": ctx.tick,
        "id": id,
        "from": sp.behavior_name(first.from),
        "to": sp.behavior_name(last.to),
        "cause": format!("{:?}", first.cause).to_lowercase(),
        "clauses": tree,
        "why_not": why,
        "scripts": scripts(sp, mind),
        "memory": memory(ctx.agent),
    }))
}

/// What a frame's steering explanation needs besides the agent's context.
pub(super) struct Steering<'a> {
    /// The random stream as steering started.
    pub rng: Rng,
    /// The agent's own velocity, as the pass's scratch had it.
    pub velocity: Option<Vec3>,
    /// A planned path's target.
    pub plan_target: Option<Vec3>,
    /// The steering the agent used.
    pub steer: Steer,
    /// Agent ids by index at the start of the tick (percept sources name agents by index).
    pub ids: &'a [u32],
}

/// The leaf in control of a recipe: for a priority list the first entry with something to do,
/// for a blend its heaviest part that steers; with the path of lists and blends to it.
fn winner<'r>(
    node: &'r RecipeNode,
    ctx: &Ctx,
    mind: &Mind,
    rng: &mut Rng,
    scratch: &mut Scratch,
    path: &mut Vec<String>,
) -> (Steer, Option<&'r Recipe>) {
    match node {
        RecipeNode::Leaf(r) => {
            let s = recipe::evaluate(node, ctx, mind, rng, scratch, 1);
            path.push(variant(format!("{r:?}")));
            (s, Some(r))
        }
        RecipeNode::Priority(v) => {
            for (k, r) in v.iter().enumerate() {
                let mut sub = Vec::new();
                let (s, leaf) = winner(r, ctx, mind, rng, scratch, &mut sub);
                if !s.is_none() {
                    path.push(format!("Priority[{}/{}]", k + 1, v.len()));
                    path.extend(sub);
                    return (s, leaf);
                }
            }
            path.push("Priority (nothing to do)".into());
            (Steer::None, None)
        }
        RecipeNode::Blend(v) => {
            let kin = ctx.kin();
            let mut best: Option<(f32, usize, Vec<String>, Option<&'r Recipe>)> = None;
            for (k, (w, by, r)) in v.iter().enumerate().take(16) {
                let f = by.as_ref().map_or(1.0, |b| value(b, ctx, mind));
                let weight = w * f;
                if weight == 0.0 {
                    continue;
                }
                let mut sub = Vec::new();
                let (s, leaf) = winner(r, ctx, mind, &mut rng.clone(), scratch, &mut sub);
                if s.is_none() {
                    continue;
                }
                let pull = weight.abs() * s.desired_velocity(&kin).length();
                if best.as_ref().is_none_or(|b| pull > b.0) {
                    best = Some((pull, k, sub, leaf));
                }
            }
            let s = recipe::evaluate(node, ctx, mind, rng, scratch, 1);
            match best {
                Some((_, k, sub, leaf)) => {
                    path.push(format!("Blend[{}/{}]", k + 1, v.len()));
                    path.extend(sub);
                    (s, leaf)
                }
                None => {
                    path.push("Blend (nothing to do)".into());
                    (s, None)
                }
            }
        }
        RecipeNode::Script(slot) => {
            path.push(format!("script {}()", slot_name(ctx.species, *slot, true)));
            (recipe::evaluate(node, ctx, mind, rng, scratch, 1), None)
        }
    }
}

/// A percept's source and position.
fn source(p: &Percept, ctx: &Ctx, ids: &[u32]) -> Value {
    let (kind, id) = match p.source() {
        Source::Agent(j) => ("agent", ids.get(j as usize).map(|&i| i as i64)),
        Source::Food(k) => ("food", ctx.world.food.get(k as usize).map(|f| f.id as i64)),
        Source::Obstacle(k) => ("obstacle", Some(k as i64)),
        Source::Injected => ("injected", None),
    };
    json!({
        "kind": kind,
        "id": id,
        "category": format!("{:?}", p.category()),
        "pos": v3(ctx.agent.pos + p.offset),
        "dist": r(p.dist),
    })
}

/// The target of the leaf in control, and a pursuit's predicted intercept point.
fn target(
    leaf: &Recipe,
    ctx: &Ctx,
    plan: Option<Vec3>,
    station: Option<Vec3>,
    ids: &[u32],
) -> (Value, Value) {
    let nearest = |c: Category| ctx.nearest(c).map_or(Value::Null, |p| source(p, ctx, ids));
    let point =
        |p: Vec3| json!({ "kind": "point", "pos": v3(p), "dist": r(p.distance(ctx.agent.pos)) });
    match leaf {
        Recipe::Chase(c) => (nearest(c.target), Value::Null),
        Recipe::Escape(e) | Recipe::EscapeMirror(e) => (nearest(e.from), Value::Null),
        Recipe::Pursue(pd) => match ctx.nearest(pd.target) {
            None => (Value::Null, Value::Null),
            Some(p) => {
                let now = ctx.agent.pos + p.offset;
                let before = match p.source() {
                    Source::Agent(j) => ctx.perception.prev_pos(j as usize).unwrap_or(now),
                    _ => now,
                };
                let vel = if ctx.dt > 0.0 {
                    (now - before) / ctx.dt
                } else {
                    Vec3::ZERO
                };
                let vmax = ctx.species.body.limits.max_speed;
                let aim = goal::intercept_point(ctx.agent.pos, vmax, now, vel);
                (source(p, ctx, ids), v3(aim))
            }
        },
        Recipe::Seek(s) | Recipe::Flee(s) | Recipe::Arrive(s) => {
            let t = match s.target {
                Target::Nearest(c) => return (nearest(c), Value::Null),
                Target::Centroid(c) => (ctx.summaries[c as usize].count > 0)
                    .then(|| ctx.summaries[c as usize].centroid),
                Target::Point(p) => Some(p),
                Target::Home => Some(ctx.world.bounds.center()),
                Target::Station => station,
            };
            (t.map_or(Value::Null, point), Value::Null)
        }
        Recipe::AvoidStatic(_) | Recipe::PredictCollision(_) => {
            (nearest(Category::Obstacle), Value::Null)
        }
        Recipe::FollowPlan(_) => (plan.map_or(Value::Null, point), Value::Null),
        Recipe::HoldStation(_) => (station.map_or(Value::Null, point), Value::Null),
        _ => (Value::Null, Value::Null),
    }
}

/// One agent's frame explained: `{type: "frame", tick, id, behavior, time_in_behavior, term,
/// target, steer, intercept, pressures, percepts, why_not, memory}`; `tick` is the recorded
/// tick (the one this pass produces).
pub(super) fn frame(ctx: &Ctx, mind: &Mind, b: &Behavior, st: &Steering) -> Value {
    let sp = ctx.species;
    let mut scratch = Scratch::default();
    scratch.set_velocity(st.velocity);
    scratch.plan_target = st.plan_target;
    let mut rng = st.rng;
    let mut path = Vec::new();
    // The focused context, as steering saw it.
    let mut kept = Vec::new();
    let narrowed;
    let focused;
    let sctx = match b.focus {
        None => ctx,
        Some(f) => {
            narrowed = focus::narrow(f, ctx.percepts, ctx.summaries, &mut kept);
            focused = Ctx {
                percepts: &kept,
                summaries: &narrowed,
                group_sums: if f.contains(Category::Kin) {
                    ctx.group_sums
                } else {
                    &[]
                },
                ..*ctx
            };
            &focused
        }
    };
    let (_, leaf) = winner(&b.steer, sctx, mind, &mut rng, &mut scratch, &mut path);
    let (target, intercept) = leaf.map_or((Value::Null, Value::Null), |l| {
        target(l, sctx, st.plan_target, mind.station(), st.ids)
    });
    let kin = ctx.kin();
    let p = ctx.static_pressures(&sp.avoid);
    let m_min = avoid::static_m_min(sp.senses.vision_radius, sp.avoid.m0);
    let percepts: Vec<Value> = ctx
        .percepts
        .iter()
        .map(|p| json!({ "c": format!("{:?}", p.category()), "pos": v3(ctx.agent.pos + p.offset) }))
        .collect();
    json!({
        "type": "frame",
        "tick": ctx.tick + 1,
        "id": ctx.agent.id.0,
        "behavior": &*b.name,
        "time_in_behavior": r(ctx.time_in_behavior(mind)),
        "term": path.join(" > "),
        "target": target,
        "steer": v3(st.steer.desired_velocity(&kin)),
        "intercept": intercept,
        "pressures": {
            "left": r(p.left), "right": r(p.right), "up": r(p.up), "down": r(p.down),
            "threshold": r(m_min),
        },
        // Fish-only fields the panel hides for other bodies: drives off, walkers.
        "drives": sp.drives.native,
        "anim": !sp.body.on_ground,
        "vision": {
            "radius": r(sp.senses.vision_radius),
            "half_angle": r(sp.senses.vision_half_angle),
            "smell": r(sp.senses.smell_radius),
        },
        "percepts": percepts,
        "why_not": why_not(ctx, mind, &st.rng, b.priority, mind.current),
        "scripts": scripts(sp, mind),
        "memory": memory(ctx.agent),
    })
}

#[cfg(test)]
mod tests {
    use super::Explain;
    use crate::scenario::{Overrides, Run, Scenario};

    fn run(file: &str) -> Run {
        let sc = Scenario::load(std::path::Path::new(file)).expect("scenario loads");
        Run::new(
            sc,
            Overrides {
                seed: None,
                duration: Some(12.0),
                set: Vec::new(),
            },
        )
    }

    /// Every tick's events and, every 10 ticks, every agent's whole record, as text (floats in
    /// their round-trip form, so equal text is equal bits).
    fn trace(file: &str, explain: Explain, ticks: u64) -> (Vec<String>, Vec<serde_json::Value>) {
        let mut r = run(file);
        r.pipeline.explain = explain;
        let mut out = Vec::new();
        let mut explained = Vec::new();
        for _ in 0..ticks {
            r.step();
            out.push(format!("{:?}", r.pipeline.events));
            if r.world.tick.is_multiple_of(10) {
                out.push(format!("{:?}", r.world.agents));
            }
            explained.extend(r.pipeline.explained.iter().cloned());
        }
        (out, explained)
    }

    #[test]
    fn explaining_changes_nothing_in_the_run() {
        for file in ["scenarios/showcase.ron", "scenarios/squad_march.ron"] {
            let (off, none) = trace(file, Explain::default(), 120);
            assert!(none.is_empty());
            let every = Explain {
                every: 2,
                only: None,
            };
            let (on, explained) = trace(file, every, 120);
            assert!(!explained.is_empty(), "{file}: nothing explained");
            assert_eq!(off.len(), on.len());
            for (k, (a, b)) in off.iter().zip(&on).enumerate() {
                assert!(a == b, "{file}: record {k} differs with explaining on");
            }
            let only = Explain {
                every: 0,
                only: Some(3),
            };
            let (one, explained) = trace(file, only, 120);
            assert_eq!(off, one, "{file}: explaining one agent changed the run");
            assert!(explained.iter().all(|v| v["id"] == 3));
            assert_eq!(
                explained.iter().filter(|v| v["type"] == "frame").count(),
                120,
                "{file}: one frame a tick for the inspected agent"
            );
        }
    }

    #[test]
    fn frames_and_decisions_say_what_moves_the_agent() {
        let every = Explain {
            every: 2,
            only: None,
        };
        let (_, explained) = trace("scenarios/showcase.ron", every, 160);
        let frames: Vec<_> = explained.iter().filter(|v| v["type"] == "frame").collect();
        let agents = run("scenarios/showcase.ron").world.agents.len();
        // Every agent on every even tick (the showcase spawns no one before 8 s).
        assert_eq!(frames.len(), agents * 80);
        for f in &frames {
            assert_eq!(f["tick"].as_u64().unwrap() % 2, 0);
            assert!(!f["term"].as_str().unwrap().is_empty(), "{f}");
            assert!(f["time_in_behavior"].as_f64().unwrap() >= 0.0);
            // Jellyfish see nothing: a radius of 0.
            assert!(f["vision"]["radius"].as_f64().unwrap() >= 0.0);
            assert_eq!(f["steer"].as_array().unwrap().len(), 3);
        }
        // Somebody has a target with a position and a distance.
        assert!(frames.iter().any(|f| f["target"]["pos"].is_array()
            && f["target"]["dist"].as_f64().is_some_and(|d| d >= 0.0)));
        // A priority list names the entry in control.
        assert!(frames
            .iter()
            .any(|f| f["term"].as_str().unwrap().contains("Priority[")));
        let decisions: Vec<_> = explained
            .iter()
            .filter(|v| v["type"] == "decision")
            .collect();
        assert!(!decisions.is_empty());
        for d in &decisions {
            assert!(d["clauses"]["c"].is_string(), "{d}");
            assert!(d["why_not"].is_array() && d["memory"].is_object());
        }
        // Interrupts fired on their `when`: its clauses held when re-read.
        let interrupts: Vec<_> = decisions
            .iter()
            .filter(|d| d["cause"] == "interrupted")
            .collect();
        assert!(!interrupts.is_empty());
        let held = interrupts
            .iter()
            .filter(|d| d["clauses"]["v"] == true)
            .count();
        assert!(
            held * 10 >= interrupts.len() * 9,
            "{held} of {}",
            interrupts.len()
        );
    }
}
