//! `shoal view`.

use std::process::ExitCode;

/// Arguments of `shoal view`.
#[derive(clap::Args, Debug, Default)]
pub struct ViewArgs {}

/// Runs `shoal view`.
pub fn view(_args: ViewArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`shoal view` is not available in this build yet")
}
