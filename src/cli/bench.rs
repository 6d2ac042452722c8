//! `shoal bench`.

use std::process::ExitCode;

/// Arguments of `shoal bench`.
#[derive(clap::Args, Debug, Default)]
pub struct BenchArgs {}

/// Runs `shoal bench`.
pub fn bench(_args: BenchArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`shoal bench` is not available in this build yet")
}
