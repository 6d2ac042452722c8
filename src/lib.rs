//! shoal: a data- and script-driven engine for animal and unit behavior.
//!
//! The tick pipeline, one folder per stage (see `src/README.md`):
//! [`index`] → [`perception`] → [`drives`] → [`decision`] → [`steering`] → [`locomotion`] →
//! [`events`], driven by [`tick`].
#![warn(missing_docs)]

pub mod bench;
pub mod decision;
pub mod diag;
pub mod drives;
pub mod events;
pub mod formation;
pub mod frame;
pub mod health;
pub mod index;
pub mod live;
pub mod locomotion;
pub mod numbers;
pub mod perception;
pub mod record;
pub mod scenario;
pub mod script;
pub mod species;
pub mod squad;
pub mod steering;
pub mod terrain;
pub mod testing;
pub mod tick;
pub mod view;
pub mod world;
