//! The simulation as a Bevy resource: a bare [`Sim`] or a scenario [`Run`] (which adds its timed
//! events and food respawn to every step). Only the plugin's step system advances it; other
//! systems read it, spawn and despawn agents, send messages or inject percepts between ticks.

use bevy::prelude::Resource;
use shoal::prelude::{Run, Sim};

/// The running simulation. Insert one (before or after adding [`crate::ShoalPlugin`]); the
/// plugin steps it once per run of its schedule and mirrors its agents as entities.
#[derive(Resource)]
pub struct ShoalSim {
    source: Source,
    /// Whether the step system advances the world (a pause leaves entities where they are).
    pub running: bool,
}

enum Source {
    Sim(Box<Sim>),
    Run(Box<Run>),
}

impl ShoalSim {
    /// A resource running `sim` (an empty world or one the app filled).
    pub fn new(sim: Sim) -> ShoalSim {
        ShoalSim {
            source: Source::Sim(Box::new(sim)),
            running: true,
        }
    }

    /// A resource running a scenario: its timed events and food respawn apply every step. It
    /// keeps running after the scenario's duration (a game has no end).
    pub fn from_run(run: Run) -> ShoalSim {
        ShoalSim {
            source: Source::Run(Box::new(run)),
            running: true,
        }
    }

    /// The simulation (agents, events, species, clock).
    pub fn sim(&self) -> &Sim {
        match &self.source {
            Source::Sim(s) => s,
            Source::Run(r) => &r.sim,
        }
    }

    /// The simulation, to spawn, despawn, send messages or inject percepts between ticks.
    pub fn sim_mut(&mut self) -> &mut Sim {
        match &mut self.source {
            Source::Sim(s) => s,
            Source::Run(r) => &mut r.sim,
        }
    }

    /// The scenario run, when the resource was made from one.
    pub fn run(&self) -> Option<&Run> {
        match &self.source {
            Source::Sim(_) => None,
            Source::Run(r) => Some(r),
        }
    }

    /// Advances one tick: [`Run::step`] for a scenario, [`Sim::step`] otherwise.
    pub fn step(&mut self) {
        match &mut self.source {
            Source::Sim(s) => s.step(),
            Source::Run(r) => r.step(),
        }
    }
}

impl From<Sim> for ShoalSim {
    fn from(sim: Sim) -> ShoalSim {
        ShoalSim::new(sim)
    }
}

impl From<Run> for ShoalSim {
    fn from(run: Run) -> ShoalSim {
        ShoalSim::from_run(run)
    }
}
