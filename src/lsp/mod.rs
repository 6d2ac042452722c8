//! `shoal lsp`: a Language Server Protocol server over stdio for a project's species, scenario,
//! script and test files. [`server`] speaks the protocol and keeps the open documents;
//! [`assist`] knows the formats' vocabulary (completion and hover). Both read the engine's
//! loaders and never run a scenario.

pub mod assist;
pub mod server;

pub use server::serve_stdio;
