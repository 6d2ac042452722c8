//! Scenarios: RON files naming the world, its species, its agents and timed events, loaded and
//! validated once ([`validate`]), and a [`Run`] that drives the tick pipeline through them
//! ([`run`]). A scenario may be loaded with settings that override any of its or its species'
//! keys ([`settings`]). This layer reads files; the core below it does not.

mod bounds;
pub mod def;
pub mod expect;
mod numbers;
mod reload;
pub mod run;
pub mod settings;
pub mod validate;

pub use def::*;
pub use reload::ScenarioReload;
pub use run::{GroupSpan, Overrides, Run, PLACE_TRIES};
pub use settings::Setting;

use crate::species::SpeciesSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A scenario read and validated, with its species loaded.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Name (file stem unless given).
    pub name: String,
    /// The scenario file.
    pub file: PathBuf,
    /// Its text.
    pub text: String,
    /// The definition.
    pub def: ScenarioDef,
    /// The behaviors folder species were loaded from.
    pub behaviors_dir: PathBuf,
    /// The species, in the order the scenario lists them.
    pub species: Arc<SpeciesSet>,
    /// The terrain and each walking species' cost grid, when the scenario has terrain.
    pub ground: Option<Arc<crate::squad::Ground>>,
    /// The squads, checked and planned.
    pub squads: Vec<crate::squad::SquadSetup>,
    /// The settings it was loaded with ([`Scenario::load_with`]); empty for a plain load.
    pub settings: Vec<Setting>,
    /// The texts those settings patched, by normalized path, read in place of the files
    /// (a run's copies of its inputs are these texts).
    pub patched: crate::load::overlay::Texts,
}

pub use crate::load::overlay::normalize;

/// Script limits used for every load.
pub fn script_limits() -> crate::script::SandboxLimits {
    crate::script::SandboxLimits::default()
}

impl Scenario {
    /// Every file the scenario was built from: itself, species, scripts and imports.
    pub fn files(&self) -> Vec<PathBuf> {
        let mut v = vec![self.file.clone()];
        for s in &self.species.species {
            v.extend(s.files());
        }
        v
    }
}
