//! Advancing a test world: `step`, `run` (seconds), `step_until` (a condition, at most so many
//! ticks). A step that fails (a script error, the tick limit) fails the test with every agent's
//! last decisions.

use super::assertions::holds;
use super::{TestCtx, WorldRef, R};
use crate::testing::failure::{raise, Kind};
use rhai::{Dynamic, Engine, FnPtr, NativeCallContext, FLOAT, INT};
use std::sync::Arc;

/// Registers `step`, `run` and `step_until`.
pub(super) fn register(e: &mut Engine, ctx: &Arc<TestCtx>) {
    e.register_fn("step", |w: &mut WorldRef| step_world(w, 1));
    e.register_fn("step", |w: &mut WorldRef, n: INT| step_world(w, n));
    e.register_fn("run", |w: &mut WorldRef, seconds: FLOAT| {
        let dt = w.get().world.dt;
        step_world(w, (seconds / dt).round() as i64)
    });
    let c = ctx.clone();
    e.register_fn(
        "step_until",
        move |nc: NativeCallContext, w: &mut WorldRef, f: FnPtr, max: INT| -> R<bool> {
            let d = Dynamic::from(w.clone());
            for k in 0..=max.max(0) {
                if holds(&nc, &c.fn_params, &f, &d)? {
                    return Ok(true);
                }
                if k < max {
                    step_world(w, 1)?;
                }
            }
            Ok(false)
        },
    );
}

pub(super) fn step_world(w: &WorldRef, n: i64) -> R<()> {
    let mut tw = w.get();
    for _ in 0..n.max(0) {
        tw.step()
            .map_err(|m| raise(Kind::Error, m, tw.all_decisions(8)))?;
    }
    Ok(())
}
