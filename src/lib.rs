//! shoal: a data- and script-driven engine for animal and unit behavior.
//!
//! The tick pipeline, one folder per stage (see `src/README.md`):
//! [`index`] → [`perception`] → [`drives`] → [`decision`] → [`steering`] → [`locomotion`] →
//! [`events`], driven by [`tick`].
#![warn(missing_docs)]

pub use sim::Sim;

/// What an embedding program needs, in one import: `use shoal::prelude::*;`.
pub mod prelude {
    pub use crate::diag::{Diagnostic, Diagnostics};
    pub use crate::events::{Event, MessageKind};
    pub use crate::perception::{Category, Percept};
    pub use crate::scenario::{Overrides, Run, Scenario};
    pub use crate::sim::{Sim, UnknownSpecies};
    pub use crate::species::{Species, SpeciesSet};
    pub use crate::world::{Aabb, Agent, AgentId, Shape, World};
    pub use glam::Vec3;
}

#[cfg(feature = "tools")]
pub mod bench;
pub mod command;
pub mod ctx;
pub mod decision;
pub mod diag;
pub mod drives;
pub mod events;
pub mod formation;
pub mod frame;
pub mod health;
pub mod index;
#[cfg(feature = "tools")]
pub mod live;
pub mod locomotion;
pub mod numbers;
pub mod perception;
pub mod record;
pub mod scenario;
pub mod script;
pub mod sim;
pub mod species;
pub mod squad;
pub mod steering;
pub mod terrain;
#[cfg(feature = "tools")]
pub mod testing;
pub mod tick;
#[cfg(feature = "tools")]
pub mod view;
pub mod world;
