//! `shoal diff`.

use std::process::ExitCode;

/// Arguments of `shoal diff`.
#[derive(clap::Args, Debug, Default)]
pub struct DiffArgs {}

/// Runs `shoal diff`.
pub fn diff(_args: DiffArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`shoal diff` is not available in this build yet")
}
