//! Arbitration for composed behaviors: a behavior may hold its own prioritized sub-behaviors
//! (`behaviors:`, a state within a state, as in hierarchical state machines), or steps run in
//! order (`sequence:`, `fallback:`) that end in success or failure.
//!
//! Seed 000 §3's rules apply unchanged inside every prioritized list (a scope): a higher level
//! interrupts, an interrupted behavior goes on the one stack, and when a behavior of a scope
//! ends, the top of the stack — if it belongs to that scope — is compared with the best new
//! candidate of the scope. A composite is never current itself: the current behavior is always
//! a leaf, and the composites above it are read from their parent links.
//!
//! What the paper does not say, added here: outcomes. A behavior's `done` ends it with success,
//! else its `fail` with failure (`fail` is not held back by `min_time`); the outcome goes to `on_success` / `on_failure` when they name a
//! sibling, else to the parent: a sequence moves to its next step on success and fails on
//! failure, a fallback tries its next step on failure and succeeds on success, a prioritized
//! list starts whatever its scope's rules choose. Outer scopes are checked first, so a composite
//! whose own `done`, `fail` or interrupt fires ends its whole subtree at once.
//!
//! A species without composites never comes here ([`super::arbitrate`] keeps the flat rules'
//! code as it was), so its runs are unchanged.

use super::{can_start_node, cond, Fired, Transition, Transitions, Which};
use crate::ctx::Ctx;
use crate::events::Cause;
use crate::species::validate::{ancestors, default_part};
use crate::species::{Behavior, Compose, CondNode};

pub use crate::species::compose::MAX_NESTING;
use crate::world::{Mind, Rng};

/// The path from the root list down to behavior `leaf`, root first (no allocation: this runs
/// every tick for every agent).
fn path(bs: &[Behavior], leaf: u16) -> ([u16; MAX_NESTING + 1], usize) {
    let mut rev = [0u16; MAX_NESTING + 1];
    let mut n = 0;
    for (slot, i) in rev.iter_mut().zip(ancestors(bs, leaf)) {
        *slot = i;
        n += 1;
    }
    rev[..n].reverse();
    (rev, n)
}

/// Whether `node` is `scope` or inside it.
pub fn within(bs: &[Behavior], node: u16, scope: u16) -> bool {
    ancestors(bs, node).any(|a| a == scope)
}

/// The tick behavior `i` was entered: a leaf's is the mind's, a composite's is kept per depth.
fn entered(bs: &[Behavior], mind: &Mind, i: u16) -> u64 {
    let b = &bs[i as usize];
    if b.compose == Compose::Leaf {
        mind.entered_tick
    } else {
        mind.scope_entered(b.level as usize)
            .unwrap_or(mind.entered_tick)
    }
}

/// Evaluates `c`, a condition of a behavior entered at tick `at`, with `TimeIn` read as time
/// in that behavior.
fn cond_of(c: &CondNode, at: u64, ctx: &Ctx, mind: &mut Mind, rng: &mut Rng) -> bool {
    let keep = mind.entered_tick;
    mind.entered_tick = at;
    let r = cond(c, ctx, mind, rng);
    mind.entered_tick = keep;
    r
}

/// The children of `scope` (`None`: the root list).
fn children<'a>(ctx: &'a Ctx, scope: Option<u16>) -> &'a [u16] {
    match scope {
        Some(s) => &ctx.species.behaviors[s as usize].children,
        None => &ctx.species.roots,
    }
}

fn can_start(bs: &[Behavior], i: u16, mind: &Mind, tick: u64) -> bool {
    can_start_node(i as usize, mind, tick) && !mind.stack().iter().any(|&s| within(bs, s, i))
}

/// The best behavior of `scope` (highest level, earliest declared among equals) other than
/// `exclude` whose activation holds and that would not be done on entry.
fn best_in(
    ctx: &Ctx,
    mind: &mut Mind,
    rng: &mut Rng,
    scope: Option<u16>,
    max_level: u8,
    exclude: Option<u16>,
) -> Option<u16> {
    let bs = &ctx.species.behaviors;
    let mut best: Option<(u8, u16)> = None;
    for &i in children(ctx, scope) {
        let b = &bs[i as usize];
        if Some(i) == exclude
            || b.priority > max_level
            || best.is_some_and(|(p, _)| b.priority >= p)
        {
            continue;
        }
        if can_start(bs, i, mind, ctx.tick)
            && cond(&b.when, ctx, mind, rng)
            && !cond_of(&b.done, ctx.tick, ctx, mind, rng)
        {
            best = Some((b.priority, i));
        }
    }
    best.map(|(_, i)| i)
}

/// Enters behavior `node` at this tick, descending into composites to a leaf (a prioritized
/// list starts its best triggered child, else its default part; a sequence or fallback its first
/// step), and marks every composite entered on the way. Returns the leaf.
fn descend(ctx: &Ctx, mind: &mut Mind, rng: &mut Rng, mut node: u16) -> u16 {
    let bs = &ctx.species.behaviors;
    loop {
        let b = &bs[node as usize];
        match b.compose {
            Compose::Leaf => break,
            Compose::Select => {
                mark(mind, b.level, ctx.tick);
                node = best_in(ctx, mind, rng, Some(node), u8::MAX, None)
                    .or_else(|| default_part(bs, node))
                    .unwrap_or(b.children[0]);
            }
            Compose::Sequence | Compose::Fallback => {
                mark(mind, b.level, ctx.tick);
                node = b.children[0];
            }
        }
    }
    node
}

fn mark(mind: &mut Mind, depth: u8, tick: u64) {
    mind.set_scope_entered(depth as usize, tick);
}

/// Makes `leaf` current from `from`: composites above it that `from` was not inside are
/// entered now (a resumed subtree's clock restarts, as a resumed behavior's does).
fn enter_leaf(bs: &[Behavior], mind: &mut Mind, from: u16, leaf: u16, tick: u64) {
    for a in ancestors(bs, leaf).skip(1) {
        if !within(bs, from, a) {
            mark(mind, bs[a as usize].level, tick);
        }
    }
    mind.current = leaf;
    mind.entered_tick = tick;
    mind.reached = false;
}

/// Drops stacked behaviors inside `node` (it ends, and with it what was interrupted in it).
fn drop_within(bs: &[Behavior], mind: &mut Mind, node: u16) {
    let kept: Vec<u16> = mind
        .stack()
        .iter()
        .copied()
        .filter(|&s| !within(bs, s, node))
        .collect();
    while mind.pop().is_some() {}
    for s in kept {
        mind.push(s);
    }
}

/// How a behavior ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Outcome {
    Success,
    Failure,
}

/// Ends behavior `n` with `outcome` and picks what runs next. Returns the leaf entered and the
/// cause.
fn finish(ctx: &Ctx, mind: &mut Mind, rng: &mut Rng, n: u16, outcome: Outcome) -> (u16, Cause) {
    let bs = &ctx.species.behaviors;
    let tick = ctx.tick;
    let b = &bs[n as usize];
    if b.cooldown > 0.0 {
        let until = tick + (b.cooldown / ctx.dt).ceil() as u64;
        mind.cooldowns.start(n, tick, until);
    }
    if b.compose != Compose::Leaf {
        drop_within(bs, mind, n);
    }
    let cause = match outcome {
        Outcome::Success => Cause::Succeeded,
        Outcome::Failure => Cause::Failed,
    };
    let target = match outcome {
        Outcome::Success => b.on_success,
        Outcome::Failure => b.on_failure,
    };
    if let Some(t) = target {
        return (descend(ctx, mind, rng, t), cause);
    }
    let parent = b.parent;
    let next_step = || {
        let p = &bs[parent? as usize];
        let k = p.children.iter().position(|&c| c == n)?;
        p.children.get(k + 1).copied()
    };
    match (parent.map(|p| bs[p as usize].compose), outcome) {
        (Some(Compose::Sequence), Outcome::Success)
        | (Some(Compose::Fallback), Outcome::Failure) => match next_step() {
            Some(s) => (descend(ctx, mind, rng, s), cause),
            None => finish(ctx, mind, rng, parent.unwrap_or(n), outcome),
        },
        (Some(Compose::Sequence), Outcome::Failure)
        | (Some(Compose::Fallback), Outcome::Success) => {
            finish(ctx, mind, rng, parent.unwrap_or(n), outcome)
        }
        _ => complete_in_scope(ctx, mind, rng, parent, n, cause),
    }
}

/// Seed 000 §3's completion inside one prioritized list: stacked behaviors of the scope whose
/// own completion holds are dropped; the top of the stack resumes if it outranks the best new
/// candidate; else the candidate starts; else the scope's initial behavior (the species'
/// initial for the root list, a composite's default part).
fn complete_in_scope(
    ctx: &Ctx,
    mind: &mut Mind,
    rng: &mut Rng,
    scope: Option<u16>,
    n: u16,
    cause: Cause,
) -> (u16, Cause) {
    let bs = &ctx.species.behaviors;
    let in_scope = |s: u16| scope.is_none_or(|p| within(bs, s, p) && s != p);
    while let Some(top) = mind.top().filter(|&t| in_scope(t)) {
        let at = child_of(bs, scope, top);
        let e = entered(bs, mind, top);
        if cond_of(&bs[at as usize].done, e, ctx, mind, rng) {
            mind.pop();
        } else {
            break;
        }
    }
    let new = best_in(ctx, mind, rng, scope, u8::MAX, Some(n));
    let top = mind.top().filter(|&t| in_scope(t));
    let rank = |t: u16| bs[child_of(bs, scope, t) as usize].priority;
    match (top, new) {
        (Some(t), Some(c)) if rank(t) < bs[c as usize].priority => {
            mind.pop();
            (t, Cause::Resumed)
        }
        (_, Some(c)) => (descend(ctx, mind, rng, c), cause_started(cause)),
        (Some(t), None) => {
            mind.pop();
            (t, Cause::Resumed)
        }
        (None, None) => {
            let init = match scope {
                Some(p) => default_part(bs, p).unwrap_or(bs[p as usize].children[0]),
                None => ctx.species.initial_node,
            };
            (descend(ctx, mind, rng, init), cause_started(cause))
        }
    }
}

/// A success that starts something new reads as the flat rules' `completed`.
fn cause_started(cause: Cause) -> Cause {
    match cause {
        Cause::Succeeded => Cause::Completed,
        c => c,
    }
}

/// The ancestor of `node` that is a direct child of `scope` (`None`: of the root list).
fn child_of(bs: &[Behavior], scope: Option<u16>, node: u16) -> u16 {
    let mut at = node;
    while bs[at as usize].parent != scope {
        match bs[at as usize].parent {
            Some(p) => at = p,
            None => break,
        }
    }
    at
}

/// One step of arbitration for an agent of a species with composed behaviors, or whose flat
/// list names failures or what follows a behavior ([`crate::species::Species::depth`]).
pub fn arbitrate(ctx: &Ctx, mind: &mut Mind, rng: &mut Rng) -> Transitions {
    let bs = &ctx.species.behaviors;
    let tick = ctx.tick;
    if mind.scope_depth() < ctx.species.depth as usize {
        mind.track_scopes(ctx.species.depth as usize, mind.entered_tick);
    }
    let cur = mind.current.min(bs.len().saturating_sub(1) as u16);
    let cur = if bs[cur as usize].compose == Compose::Leaf {
        cur
    } else {
        ctx.species.initial
    };
    mind.current = cur;
    let (path, len) = path(bs, cur);
    let mut out: Transitions = [None, None];

    // 1. Outcomes, outermost first: a composite that ends takes its subtree with it.
    for &n in &path[..len] {
        let b = &bs[n as usize];
        let at = entered(bs, mind, n);
        let t_in = tick.saturating_sub(at) as f32 * ctx.dt;
        let reached = b.compose == Compose::Leaf && mind.reached;
        // Success first: a strike whose catch made its prey vanish succeeded, though it no
        // longer perceives prey.
        let outcome = if !matches!(b.done, CondNode::Never)
            && (t_in >= b.min_time || reached)
            && cond_of(&b.done, at, ctx, mind, rng)
        {
            Some((Outcome::Success, Fired::new(n, Which::Done)))
        } else if !matches!(b.fail, CondNode::Never) && cond_of(&b.fail, at, ctx, mind, rng) {
            Some((Outcome::Failure, Fired::new(n, Which::Fail)))
        } else {
            None
        };
        if let Some((outcome, fired)) = outcome {
            let (to, cause) = finish(ctx, mind, rng, n, outcome);
            enter_leaf(bs, mind, cur, to, tick);
            out[0] = Some(Transition::new(cur, to, cause, Some(fired)));
            return out;
        }
    }

    // 2. Interrupts, outermost first, inside prioritized lists only (steps run in order).
    for &n in &path[..len] {
        let b = &bs[n as usize];
        let scope = b.parent;
        if scope.is_some_and(|p| bs[p as usize].compose != Compose::Select) {
            continue;
        }
        let at = entered(bs, mind, n);
        let t_in = tick.saturating_sub(at) as f32 * ctx.dt;
        let max_level = if b.equal_may_interrupt && t_in >= b.min_time {
            b.priority
        } else {
            b.priority.saturating_sub(1)
        };
        if max_level == 0 {
            continue;
        }
        if let Some(m) = best_in(ctx, mind, rng, scope, max_level, Some(n)) {
            mind.push(cur);
            let to = descend(ctx, mind, rng, m);
            enter_leaf(bs, mind, cur, to, tick);
            out[0] = Some(Transition::new(
                cur,
                to,
                Cause::Interrupted,
                Some(Fired::new(m, Which::When)),
            ));
            return out;
        }
    }
    out
}
