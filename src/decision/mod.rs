//! Stage 4 of the tick: decision. The prioritized FSM with a behavior stack of seed 000 §3:
//! a higher level interrupts a lower one, a lower one never interrupts a higher one, equal levels
//! may interrupt each other; an interrupted behavior goes on the stack, and whenever a new
//! behavior would start, the top of the stack is compared with it first and resumed if it
//! outranks it. Designers add anti-dithering (minimum time, cooldown, latched conditions).
//!
//! Conditions are native evaluators resolved at load time ([`crate::species::CondNode`]); script
//! conditions read values cached at the species' decision rate ([`scripts`]). Every transition
//! records its cause and the text of the condition that fired. Besides the paper's tests they
//! read seed 001's perceived strength of the nearest percept (`Strength`) and seed 000
//! §4.3–4.4's fuzzy direction sectors of it (`InSector`, `AtLevel`), which the paper uses only
//! inside move-to-goal and escape.

pub mod focus;
pub mod scripts;
pub mod tree;

use crate::events::{Cause, MessageKind};
pub use crate::params::decision::{level_bit, sector_bit};
use crate::perception::Category;
use crate::species::CondNode;
use crate::steering::avoid;
use crate::steering::escape;
use crate::world::{Mind, Rng};
use std::sync::Arc;

pub use crate::ctx::{value, Ctx};

/// Evaluates a condition. Latches and chance draws update `mind` and `rng`.
pub fn cond(c: &CondNode, ctx: &Ctx, mind: &mut Mind, rng: &mut Rng) -> bool {
    match c {
        CondNode::Always => true,
        CondNode::Never => false,
        CondNode::All(v) => v.iter().all(|c| cond(c, ctx, mind, rng)),
        CondNode::Any(v) => v.iter().any(|c| cond(c, ctx, mind, rng)),
        CondNode::Not(c) => !cond(c, ctx, mind, rng),
        CondNode::Above(v, x) => value(v, ctx, mind) > *x,
        CondNode::Below(v, x) => value(v, ctx, mind) < *x,
        CondNode::Latch { bit, on, off } => {
            let mask = 1u64 << bit;
            let latched = mind.latches & mask != 0;
            let now = if latched {
                !cond(off, ctx, mind, rng)
            } else {
                cond(on, ctx, mind, rng)
            };
            if now {
                mind.latches |= mask;
            } else {
                mind.latches &= !mask;
            }
            now
        }
        CondNode::Sees(k) => ctx.summaries[*k as usize].seen > 0,
        CondNode::Smells(k) => {
            let s = &ctx.summaries[*k as usize];
            s.count > s.seen
        }
        CondNode::Perceives(k) => ctx.summaries[*k as usize].count > 0,
        CondNode::Within(k, d) => ctx.summaries[*k as usize].nearest_dist <= *d,
        CondNode::InSector(k, mask) => ctx.nearest(*k).is_some_and(|p| {
            let sector = ctx.species.senses.sectors.horizontal(p.bearing);
            mask & sector_bit(sector) != 0
        }),
        CondNode::AtLevel(k, mask) => ctx.nearest(*k).is_some_and(|p| {
            let level = ctx.species.senses.sectors.vertical(p.elevation);
            mask & level_bit(level) != 0
        }),
        CondNode::EscapeDone => match ctx.nearest(Category::Predator) {
            None => true,
            Some(p) => escape::escape_done(
                &ctx.kin(),
                p.bearing,
                p.offset,
                p.dist,
                ctx.species.senses.vision_radius,
            ),
        },
        CondNode::ObstacleNear => {
            let params = &ctx.species.avoid;
            let p = ctx.static_pressures(params);
            p.max() > avoid::static_m_min(ctx.species.senses.vision_radius, params.m0)
        }
        CondNode::TrafficNear => {
            // One buffer per thread: conditions run every tick for every agent.
            thread_local! {
                static MOVING: std::cell::RefCell<Vec<avoid::MovingObstacle>> =
                    const { std::cell::RefCell::new(Vec::new()) };
            }
            let params = &ctx.species.avoid;
            MOVING.with(|v| {
                let mut v = v.borrow_mut();
                ctx.moving_obstacles(params, &mut v);
                let s = avoid::avoid_dynamic(
                    &ctx.kin(),
                    &v,
                    ctx.species.senses.vision_radius,
                    ctx.species.senses.vision_half_angle,
                    ctx.agent.diagonal(),
                    ctx.dt,
                    params,
                );
                !s.is_none()
            })
        }
        CondNode::Heard(crate::world::Signal::Kind(m)) => {
            ctx.agent.inbox.kind().is_some_and(|k: MessageKind| k == *m)
        }
        CondNode::Heard(crate::world::Signal::Event(e)) => {
            ctx.agent.inbox.heard().is_some_and(|h| h.event == *e)
        }
        CondNode::TimeIn(t) => ctx.time_in_behavior(mind) >= *t,
        CondNode::Chance(p) => rng.next_f32() < p * ctx.dt,
        CondNode::NearBounds(m) => {
            let b = &ctx.world.bounds;
            let q = ctx.agent.pos;
            (q - b.min).min_element() < *m || (b.max - q).min_element() < *m
        }
        CondNode::Contacted => mind.reached,
        CondNode::AtStation(d) => mind
            .station()
            .is_some_and(|s| s.distance(ctx.agent.pos) <= *d),
        CondNode::Script(slot) => {
            mind.script_values
                .get(*slot as usize)
                .copied()
                .unwrap_or(0.0)
                != 0.0
        }
    }
}

/// One behavior change: 8 bytes, so that a whole school's first transitions (one in every
/// agent's outcome in one tick) box 24 bytes each, and copy no shared text across threads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Transition {
    /// Behavior before.
    pub from: u16,
    /// Behavior after.
    pub to: u16,
    /// Why.
    pub cause: Cause,
    /// Which condition fired, of behavior [`Transition::fired_in`] (none when no condition
    /// did); [`Transition::fired`] reads both. Its text is the species' ([`Fired::text`]),
    /// looked up when the event is made.
    pub which: Option<Which>,
    /// The behavior (composed or not) whose condition fired.
    pub fired_in: u16,
}

impl Transition {
    /// From `from` to `to` for `cause`, `fired` the condition that fired, if any.
    pub fn new(from: u16, to: u16, cause: Cause, fired: Option<Fired>) -> Self {
        Transition {
            from,
            to,
            cause,
            which: fired.map(|f| f.which),
            fired_in: fired.map_or(0, |f| f.behavior),
        }
    }
    /// The condition that fired, if any.
    pub fn fired(&self) -> Option<Fired> {
        self.which.map(|which| Fired::new(self.fired_in, which))
    }
}

/// Which condition of which behavior fired a transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fired {
    /// The behavior holding it (composed or not).
    pub behavior: u16,
    /// Which of its conditions.
    pub which: Which,
}

/// One of a behavior's conditions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Which {
    /// Its activation condition (`when`).
    When,
    /// Its completion condition (`done`).
    Done,
    /// Its failure condition (`fail`).
    Fail,
}

impl Fired {
    /// The fired condition of `behavior`.
    pub fn new(behavior: u16, which: Which) -> Self {
        Fired { behavior, which }
    }
    /// Its text in species `sp` (none for a behavior it does not have).
    pub fn text(self, sp: &crate::species::Species) -> Option<Arc<str>> {
        self.in_species(sp).map(|(_, text)| text.clone())
    }
    /// The condition itself in species `sp`.
    pub fn node(self, sp: &crate::species::Species) -> Option<&CondNode> {
        self.in_species(sp).map(|(node, _)| node)
    }
    /// The condition and its text in species `sp`.
    fn in_species(self, sp: &crate::species::Species) -> Option<(&CondNode, &Arc<str>)> {
        let b = sp.behaviors.get(self.behavior as usize)?;
        Some(match self.which {
            Which::When => (&b.when, &b.when_text),
            Which::Done => (&b.done, &b.done_text),
            Which::Fail => (&b.fail, &b.fail_text),
        })
    }
}

/// Up to two transitions per tick (a completion followed by a resume or start is one).
pub type Transitions = [Option<Transition>; 2];

fn can_start(i: usize, mind: &Mind, tick: u64) -> bool {
    can_start_node(i, mind, tick) && !mind.stack().contains(&(i as u16))
}

/// Whether behavior `i`'s cooldown has run out.
fn can_start_node(i: usize, mind: &Mind, tick: u64) -> bool {
    mind.cooldowns.ready(i as u16, tick)
}

/// The highest-priority behavior (earliest declared among equals) other than the current one
/// whose activation condition holds, considering only levels up to `max_level`.
fn best_triggered(
    ctx: &Ctx,
    mind: &mut Mind,
    rng: &mut Rng,
    max_level: u8,
    exclude: u16,
) -> Option<u16> {
    let bs = &ctx.species.behaviors;
    let mut best: Option<(u8, u16)> = None;
    for (i, b) in bs.iter().enumerate() {
        if i as u16 == exclude
            || b.priority > max_level
            || best.is_some_and(|(p, _)| b.priority >= p)
        {
            continue;
        }
        if can_start(i, mind, ctx.tick)
            && cond(&b.when, ctx, mind, rng)
            && !done_on_entry(b, ctx, mind, rng)
        {
            best = Some((b.priority, i as u16));
        }
    }
    best.map(|(_, i)| i)
}

/// Whether behavior `b` would be done the moment it started (its `done` read as if it had just
/// been entered: no time in it yet). Such a behavior is not started: it would end on the next
/// tick and start again on the one after, an episode of one tick each time (escape heard of
/// from kin while its predator is already behind and out of sight, say). Its `min_time` does
/// not hold it either: a behavior is started for what it will do, and this one has nothing to do.
fn done_on_entry(b: &crate::species::Behavior, ctx: &Ctx, mind: &mut Mind, rng: &mut Rng) -> bool {
    let entered = mind.entered_tick;
    mind.entered_tick = ctx.tick;
    let done = cond(&b.done, ctx, mind, rng);
    mind.entered_tick = entered;
    done
}

fn enter(mind: &mut Mind, to: u16, tick: u64) {
    mind.current = to;
    mind.entered_tick = tick;
    mind.reached = false;
}

/// One step of arbitration for one agent. Returns the transitions it made.
pub fn arbitrate(ctx: &Ctx, mind: &mut Mind, rng: &mut Rng) -> Transitions {
    if ctx.species.depth > 0 {
        return tree::arbitrate(ctx, mind, rng);
    }
    let bs = &ctx.species.behaviors;
    // A lone behavior that never completes (a boid's "flock") has nothing to arbitrate:
    // nothing can interrupt it and it never ends.
    if let [only] = &bs[..] {
        if matches!(only.done, CondNode::Never) {
            mind.current = 0;
            return [None, None];
        }
    }
    let tick = ctx.tick;
    let cur = mind.current.min(bs.len().saturating_sub(1) as u16);
    mind.current = cur;
    let b = &bs[cur as usize];
    let t_in = ctx.time_in_behavior(mind);
    let mut out: Transitions = [None, None];

    // 1. Completion of the current behavior (at once after its contact: a fish that has
    // eaten or mated is done with it, whatever its minimum time).
    if (t_in >= b.min_time || mind.reached) && cond(&b.done, ctx, mind, rng) {
        if b.cooldown > 0.0 {
            let until = tick + (b.cooldown / ctx.dt).ceil() as u64;
            mind.cooldowns.start(cur, tick, until);
        }
        // Stacked behaviors whose own completion already holds are dropped.
        while let Some(top) = mind.top() {
            let tb = &bs[top as usize];
            if cond(&tb.done, ctx, mind, rng) {
                mind.pop();
            } else {
                break;
            }
        }
        let new = best_triggered(ctx, mind, rng, u8::MAX, cur);
        let top = mind.top();
        let (to, cause) = match (top, new) {
            (Some(t), Some(n)) if bs[t as usize].priority < bs[n as usize].priority => {
                mind.pop();
                (t, Cause::Resumed)
            }
            (_, Some(n)) => (n, Cause::Completed),
            (Some(t), None) => {
                mind.pop();
                (t, Cause::Resumed)
            }
            (None, None) => (ctx.species.initial, Cause::Completed),
        };
        enter(mind, to, tick);
        out[0] = Some(Transition::new(
            cur,
            to,
            cause,
            Some(Fired::new(cur, Which::Done)),
        ));
        return out;
    }

    // 2. Interrupts: strictly higher levels always; equal levels when allowed and past min_time.
    let max_level = if b.equal_may_interrupt && t_in >= b.min_time {
        b.priority
    } else {
        b.priority.saturating_sub(1)
    };
    if max_level == 0 {
        return out;
    }
    if let Some(n) = best_triggered(ctx, mind, rng, max_level, cur) {
        mind.push(cur);
        enter(mind, n, tick);
        out[0] = Some(Transition::new(
            cur,
            n,
            Cause::Interrupted,
            Some(Fired::new(n, Which::When)),
        ));
    }
    out
}
