//! Assertions of script tests, whose failures say what was expected, what happened and what
//! the agent (or every agent) last decided: `assert`, `assert_eq`, `assert_near`, behaviors,
//! stacks and transitions, conditions that must become true within so many ticks or stay true
//! for them, `fail` and `skip`.

use super::args::{num, strings};
use super::step::step_world;
use super::{AgentRef, TestCtx, WorldRef, R};
use crate::events::{Cause, Event};
use crate::testing::failure::{error, raise, Kind};
use crate::testing::world::lock;
use glam::Vec3;
use rhai::{Array, Dynamic, Engine, FnPtr, ImmutableString, NativeCallContext, INT};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Registers the assertions, `fail` and `skip`.
pub(super) fn register(e: &mut Engine, ctx: &Arc<TestCtx>) {
    let c = ctx.clone();
    e.register_fn("assert", move |ok: bool| -> R<()> {
        if ok {
            Ok(())
        } else {
            Err(raise(Kind::Fail, "assertion failed", last_context(&c)))
        }
    });
    let c = ctx.clone();
    e.register_fn("assert", move |ok: bool, msg: &str| -> R<()> {
        if ok {
            Ok(())
        } else {
            Err(raise(Kind::Fail, msg, last_context(&c)))
        }
    });
    let c = ctx.clone();
    e.register_fn("assert_eq", move |a: Dynamic, b: Dynamic| -> R<()> {
        if same(&a, &b) {
            Ok(())
        } else {
            Err(raise(
                Kind::Fail,
                format!("expected {}, got {}", show(&b), show(&a)),
                last_context(&c),
            ))
        }
    });
    let c = ctx.clone();
    e.register_fn(
        "assert_eq",
        move |a: Dynamic, b: Dynamic, msg: &str| -> R<()> {
            if same(&a, &b) {
                Ok(())
            } else {
                Err(raise(
                    Kind::Fail,
                    format!("{msg}: expected {}, got {}", show(&b), show(&a)),
                    last_context(&c),
                ))
            }
        },
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_near",
        move |a: Dynamic, b: Dynamic, tol: Dynamic| -> R<()> {
            let (ok, off) = near(&a, &b, &tol)?;
            if ok {
                Ok(())
            } else {
                Err(raise(
                    Kind::Fail,
                    format!(
                        "expected {} ± {}, got {} (off by {off})",
                        show(&b),
                        show(&tol),
                        show(&a)
                    ),
                    last_context(&c),
                ))
            }
        },
    );
    e.register_fn("assert_behavior", |a: AgentRef, name: &str| -> R<()> {
        a.world.get().check_behavior(a.id, name).map_err(error)?;
        let now = a.behavior()?;
        if now == name {
            return Ok(());
        }
        Err(raise(
            Kind::Fail,
            format!("expected {} in `{name}`, but it is in `{now}`", a.label()),
            a.decisions(),
        ))
    });
    e.register_fn("assert_stack", |a: AgentRef, names: Array| -> R<()> {
        let want = strings(&names, "stack")?;
        for n in &want {
            a.world.get().check_behavior(a.id, n).map_err(error)?;
        }
        let now = a.stack()?;
        if now == want {
            return Ok(());
        }
        Err(raise(
            Kind::Fail,
            format!(
                "expected the stack of {} to be [{}] (bottom first), but it is [{}]",
                a.label(),
                want.join(", "),
                now.join(", ")
            ),
            a.decisions(),
        ))
    });
    e.register_fn(
        "assert_behavior_within",
        |a: AgentRef, name: &str, ticks: INT| -> R<()> {
            a.world.get().check_behavior(a.id, name).map_err(error)?;
            for k in 0..=ticks.max(0) {
                if a.behavior()? == name {
                    return Ok(());
                }
                if k < ticks {
                    step_world(&a.world, 1)?;
                }
            }
            let now = a.behavior()?;
            Err(raise(
                Kind::Fail,
                format!(
                    "expected {} in `{name}` within {}, but it is in `{now}`",
                    a.label(),
                    ticks_text(&a.world, ticks.max(0) as u64)
                ),
                a.decisions(),
            ))
        },
    );
    let transition = |a: AgentRef, from: &str, to: &str, cause: Option<&str>| -> R<()> {
        {
            let tw = a.world.get();
            tw.check_behavior(a.id, from).map_err(error)?;
            tw.check_behavior(a.id, to).map_err(error)?;
        }
        let causes = Cause::ALL;
        if let Some(c) = cause {
            if !causes.iter().any(|x| x.name() == c) {
                return Err(error(format!(
                    "unknown cause \"{c}\": expected one of {}",
                    causes.map(|x| x.name()).join(", ")
                )));
            }
        }
        let id = a.id;
        let found = {
            let tw = a.world.get();
            tw.log.iter().any(|l| match &l.event {
                Event::Transition {
                    agent,
                    species,
                    from: f,
                    to: t,
                    cause: c,
                    ..
                } if *agent == id => {
                    let sp = &tw.species[*species as usize];
                    sp.behavior_name(*f) == from
                        && sp.behavior_name(*t) == to
                        && cause.is_none_or(|x| x == c.name())
                }
                _ => false,
            })
        };
        if found {
            return Ok(());
        }
        Err(raise(
            Kind::Fail,
            format!(
                "expected {} to have gone from `{from}` to `{to}`{}, but it never did",
                a.label(),
                cause.map_or(String::new(), |c| format!(" ({c})"))
            ),
            a.decisions(),
        ))
    };
    e.register_fn(
        "assert_transition",
        move |a: AgentRef, from: &str, to: &str| transition(a, from, to, None),
    );
    e.register_fn(
        "assert_transition",
        move |a: AgentRef, from: &str, to: &str, cause: &str| transition(a, from, to, Some(cause)),
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_within",
        move |nc: NativeCallContext, w: WorldRef, ticks: INT, f: FnPtr| {
            assert_within(&nc, &c.fn_params, Subject::World(w), ticks, f)
        },
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_within",
        move |nc: NativeCallContext, a: AgentRef, ticks: INT, f: FnPtr| {
            assert_within(&nc, &c.fn_params, Subject::Agent(a), ticks, f)
        },
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_always",
        move |nc: NativeCallContext, w: WorldRef, ticks: INT, f: FnPtr| {
            assert_always(&nc, &c.fn_params, Subject::World(w), ticks, f)
        },
    );
    let c = ctx.clone();
    e.register_fn(
        "assert_always",
        move |nc: NativeCallContext, a: AgentRef, ticks: INT, f: FnPtr| {
            assert_always(&nc, &c.fn_params, Subject::Agent(a), ticks, f)
        },
    );
    let c = ctx.clone();
    e.register_fn("fail", move |msg: &str| -> R<()> {
        Err(raise(Kind::Fail, msg, last_context(&c)))
    });
    e.register_fn("skip", |msg: &str| -> R<()> {
        Err(raise(Kind::Skip, msg, String::new()))
    });
}

/// Calls a condition with `this` bound to `subject`, passing the subject too when the function
/// takes a parameter.
pub(super) fn holds(
    ctx: &NativeCallContext,
    params: &BTreeMap<String, usize>,
    f: &FnPtr,
    subject: &Dynamic,
) -> R<bool> {
    let n = params.get(f.fn_name()).copied().unwrap_or(0);
    let mut this = subject.clone();
    let args: Vec<Dynamic> = (0..n).map(|_| subject.clone()).collect();
    let r = f.call_raw(ctx, Some(&mut this), args)?;
    r.as_bool()
        .map_err(|t| error(format!("the condition must return true or false, not {t}")))
}

/// What a condition is about: a whole world or one agent.
#[derive(Clone)]
enum Subject {
    World(WorldRef),
    Agent(AgentRef),
}

impl Subject {
    fn world(&self) -> &WorldRef {
        match self {
            Subject::World(w) => w,
            Subject::Agent(a) => &a.world,
        }
    }
    fn dynamic(&self) -> Dynamic {
        match self {
            Subject::World(w) => Dynamic::from(w.clone()),
            Subject::Agent(a) => Dynamic::from(a.clone()),
        }
    }
    fn context(&self) -> String {
        match self {
            Subject::World(w) => w.get().all_decisions(8),
            Subject::Agent(a) => a.decisions(),
        }
    }
}

fn ticks_text(w: &WorldRef, ticks: u64) -> String {
    let dt = w.get().world.dt as f64;
    format!("{ticks} ticks ({:.2} s)", ticks as f64 * dt)
}

fn assert_within(
    ctx: &NativeCallContext,
    params: &BTreeMap<String, usize>,
    s: Subject,
    ticks: INT,
    f: FnPtr,
) -> R<()> {
    let d = s.dynamic();
    let start = s.world().get().world.tick;
    for k in 0..=ticks.max(0) {
        if holds(ctx, params, &f, &d)? {
            return Ok(());
        }
        if k < ticks {
            step_world(s.world(), 1)?;
        }
    }
    let now = s.world().get().world.tick;
    Err(raise(
        Kind::Fail,
        format!(
            "expected the condition to become true within {}, but it was still false at tick {now} (started at tick {start})",
            ticks_text(s.world(), ticks.max(0) as u64)
        ),
        s.context(),
    ))
}

fn assert_always(
    ctx: &NativeCallContext,
    params: &BTreeMap<String, usize>,
    s: Subject,
    ticks: INT,
    f: FnPtr,
) -> R<()> {
    let d = s.dynamic();
    for k in 0..=ticks.max(0) {
        if !holds(ctx, params, &f, &d)? {
            let now = s.world().get().world.tick;
            return Err(raise(
                Kind::Fail,
                format!(
                    "expected the condition to stay true for {}, but it was false at tick {now} (after {k} ticks)",
                    ticks_text(s.world(), ticks.max(0) as u64)
                ),
                s.context(),
            ));
        }
        if k < ticks {
            step_world(s.world(), 1)?;
        }
    }
    Ok(())
}

fn last_context(ctx: &TestCtx) -> String {
    lock(&ctx.worlds)
        .last()
        .map(|w| w.get().all_decisions(8))
        .unwrap_or_default()
}

fn show(d: &Dynamic) -> String {
    if let Some(s) = d.clone().try_cast::<ImmutableString>() {
        format!("\"{s}\"")
    } else if let Some(v) = d.clone().try_cast::<Vec3>() {
        format!("vec3({}, {}, {})", v.x, v.y, v.z)
    } else if let Some(a) = d.clone().try_cast::<Array>() {
        format!("[{}]", a.iter().map(show).collect::<Vec<_>>().join(", "))
    } else if let Some(a) = d.clone().try_cast::<AgentRef>() {
        a.label()
    } else {
        d.to_string()
    }
}

fn same(a: &Dynamic, b: &Dynamic) -> bool {
    let n = |d: &Dynamic| {
        d.as_float()
            .ok()
            .map(|f| f as f64)
            .or_else(|| d.as_int().ok().map(|i| i as f64))
    };
    if let (Some(x), Some(y)) = (n(a), n(b)) {
        return x == y;
    }
    if let (Some(x), Some(y)) = (a.clone().try_cast::<Array>(), b.clone().try_cast::<Array>()) {
        return x.len() == y.len() && x.iter().zip(&y).all(|(p, q)| same(p, q));
    }
    if let (Some(x), Some(y)) = (
        a.clone().try_cast::<AgentRef>(),
        b.clone().try_cast::<AgentRef>(),
    ) {
        return x.id == y.id && Arc::ptr_eq(&x.world.0, &y.world.0);
    }
    a.type_id() == b.type_id() && show(a) == show(b)
}

fn near(a: &Dynamic, b: &Dynamic, tol: &Dynamic) -> R<(bool, f32)> {
    let tol = num(tol, "tolerance")?;
    let off = match (a.clone().try_cast::<Vec3>(), b.clone().try_cast::<Vec3>()) {
        (Some(x), Some(y)) => x.distance(y),
        _ => (num(a, "value")? - num(b, "expected")?).abs(),
    };
    Ok((off <= tol, off))
}
