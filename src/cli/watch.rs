//! `shoal watch`.

use std::process::ExitCode;

/// Arguments of `shoal watch`.
#[derive(clap::Args, Debug, Default)]
pub struct WatchArgs {}

/// Runs `shoal watch`.
pub fn watch(_args: WatchArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`shoal watch` is not available in this build yet")
}
