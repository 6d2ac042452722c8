//! The parameter types of the stages above the species in the core's layers (steering,
//! decision, locomotion), one file per stage: pure data with their defaults (the papers'
//! values) and doc citations. A species file names them and a runtime species holds them, so
//! they sit below `species`, which sits below the stages that read it (`tests/layers.rs`). Each
//! stage keeps its logic (and most methods on them) and re-exports them under their old
//! paths. The stages below the species (perception, drives) keep their parameter types.
//!
//! May import: `perception` and what is below it, nothing above.

pub mod decision;
pub mod locomotion;
pub mod steering;
