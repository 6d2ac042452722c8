//! `shoal test`.

use std::process::ExitCode;

/// Arguments of `shoal test`.
#[derive(clap::Args, Debug, Default)]
pub struct TestArgs {}

/// Runs `shoal test`.
pub fn test(_args: TestArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`shoal test` is not available in this build yet")
}
