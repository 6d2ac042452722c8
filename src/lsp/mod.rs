//! `shoal lsp`: a Language Server Protocol server over stdio for a project's species, scenario,
//! script and test files. [`server`] speaks the protocol and dispatches; [`docs`] holds the open
//! buffers and converts positions; [`diagnostics`] runs the project's checks
//! ([`crate::project`], the one `shoal check` runs) as you type; [`index`] (over the scanner in
//! [`lex`]) knows what each file defines and uses, read by [`symbols`] (outline, completion's
//! names), [`navigate`] (definition, references) and [`rename`]; [`assist`] knows the formats'
//! vocabulary (completion and hover). All read the engine's loaders and never run a scenario.

pub mod assist;
pub mod diagnostics;
pub mod docs;
pub mod index;
pub mod lex;
pub mod navigate;
pub mod rename;
pub mod server;
pub mod symbols;

pub use server::serve_stdio;
