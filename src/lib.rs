//! shoal: a data- and script-driven engine for animal and unit behavior.
#![warn(missing_docs)]

pub mod diag;
pub mod view;
