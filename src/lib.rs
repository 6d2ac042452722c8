//! shoal: a data- and script-driven engine for animal and unit behavior.
//!
//! The tick pipeline, one folder per stage (see `src/README.md`):
//! [`index`] → [`perception`] → [`drives`] → [`decision`] → [`steering`] → [`locomotion`] →
//! [`events`], driven by [`tick`].
#![warn(missing_docs)]

pub use sim::Sim;

/// Located diagnostics and the file reader ([`load::diag`]), under their short path.
pub use load::diag;
/// Load-time number checks and size limits ([`load::numbers`]), under their short path.
pub use load::numbers;

/// What an embedding program needs, in one import: `use shoal::prelude::*;`.
pub mod prelude {
    pub use crate::events::{Event, MessageKind};
    pub use crate::load::{Diagnostic, Diagnostics};
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
pub mod drives;
pub mod events;
pub mod formation;
pub mod frame;
pub mod health;
pub mod index;
#[cfg(feature = "tools")]
pub mod live;
pub mod load;
pub mod locomotion;
#[cfg(feature = "tools")]
pub mod lsp;
pub mod math;
pub mod par;
pub mod params;
pub mod perception;
pub mod project;
pub mod record;
pub mod scenario;
pub mod script;
pub mod sim;
pub mod species;
pub mod squad;
pub mod steering;
pub mod sweep;
pub mod terrain;
#[cfg(feature = "tools")]
pub mod testing;
pub mod tick;
#[cfg(feature = "tools")]
pub mod view;
pub mod world;
