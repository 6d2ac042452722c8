//! The Rhai API of script tests: a world builder (`world()`, `spawn`, `add_food`, `add_rock`,
//! `step`, `step_until`), agent handles that read and set everything a behavior depends on,
//! percept injection (`perceive`), the event log, and assertions whose failures say what was
//! expected, what happened and what the agent last decided.
//!
//! A separate engine from the species scripts' (built per test, with the same safety limits
//! except a larger operation budget, since a whole test is one call). Angles are in degrees.
//!
//! One file per concept: reading arguments (`args.rs`), building a world (`setup.rs`),
//! stepping it (`step.rs`), reading it (`queries.rs`), agent handles (`agents.rs`), the event
//! log (`events.rs`), percept injection (`percepts.rs`) and assertions (`assertions.rs`).

mod agents;
mod args;
mod assertions;
mod events;
mod percepts;
mod queries;
mod setup;
mod step;

use super::coverage::Coverage;
use super::failure::error;
use super::world::{lock, Library, TestWorld};
use crate::world::AgentId;
use glam::Vec3;
use rhai::{Engine, EvalAltResult};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

type R<T> = Result<T, Box<EvalAltResult>>;

/// Default world bounds of a test: 100 × 30 × 100 around the origin, floor at 0.
pub const DEFAULT_BOUNDS: (Vec3, Vec3) =
    (Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 30.0, 50.0));

/// What one running test shares with the functions it calls.
pub struct TestCtx {
    /// Species of its behaviors folder.
    pub library: Arc<Library>,
    /// Coverage of the whole run.
    pub coverage: Arc<Coverage>,
    /// Most ticks one world may run.
    pub max_ticks: u64,
    /// Worlds the test built, in order.
    pub worlds: Mutex<Vec<WorldRef>>,
    /// What the test printed.
    pub output: Mutex<String>,
    /// Parameter counts of the file's functions (anonymous ones included).
    pub fn_params: BTreeMap<String, usize>,
}

/// A world handle in a test script.
#[derive(Clone)]
pub struct WorldRef(pub Arc<Mutex<TestWorld>>);

/// An agent handle: reads the live state of one agent of a world.
#[derive(Clone)]
pub struct AgentRef {
    /// Its world.
    pub world: WorldRef,
    /// Its id.
    pub id: AgentId,
}

impl WorldRef {
    fn get(&self) -> std::sync::MutexGuard<'_, TestWorld> {
        lock(&self.0)
    }
}

impl AgentRef {
    /// Runs `f` on the live agent, or fails saying why it is gone.
    fn with<T>(&self, f: impl FnOnce(&TestWorld, usize) -> T) -> R<T> {
        let tw = self.world.get();
        let i = tw.index(self.id).map_err(error)?;
        Ok(f(&tw, i))
    }
    fn with_mut<T>(&self, f: impl FnOnce(&mut TestWorld, usize) -> T) -> R<T> {
        let mut tw = self.world.get();
        let i = tw.index(self.id).map_err(error)?;
        Ok(f(&mut tw, i))
    }
    fn label(&self) -> String {
        self.world.get().label(self.id)
    }
    fn behavior(&self) -> R<String> {
        self.with(|tw, i| {
            let a = &tw.sim.world.agents[i];
            tw.species[a.species.0 as usize]
                .behavior_name(a.mind.current)
                .to_string()
        })
    }
    fn stack(&self) -> R<Vec<String>> {
        self.with(|tw, i| {
            let a = &tw.sim.world.agents[i];
            let sp = &tw.species[a.species.0 as usize];
            a.mind
                .stack()
                .iter()
                .map(|b| sp.behavior_name(*b).to_string())
                .collect()
        })
    }
    fn decisions(&self) -> String {
        self.world.get().decisions(self.id, 8)
    }
}

/// Registers the test API on `e` for the test described by `ctx`.
pub fn register(e: &mut Engine, ctx: Arc<TestCtx>) {
    e.register_type_with_name::<WorldRef>("World")
        .register_type_with_name::<AgentRef>("Agent");
    setup::register(e, &ctx);
    step::register(e, &ctx);
    queries::register(e);
    agents::register(e);
    events::register(e);
    percepts::register(e);
    assertions::register(e, &ctx);
    let c = ctx;
    e.on_print(move |s| {
        let mut o = lock(&c.output);
        if o.len() < 64 * 1024 {
            o.push_str(s);
            o.push('\n');
        }
    });
}
