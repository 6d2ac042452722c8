//! `shoal run` and `shoal rerun`.

use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `shoal run`.
#[derive(clap::Args, Debug, Default)]
pub struct RunArgs {
    /// Scenario file (default: scenarios/reef.ron).
    pub scenario: Option<PathBuf>,
    /// Seed (default: the scenario's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Duration in seconds (default: the scenario's).
    #[arg(long)]
    pub duration: Option<f32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Output folder (default: runs/<scenario>-<seed>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Record every this many ticks (default: the scenario's).
    #[arg(long)]
    pub interval: Option<u32>,
}

/// Arguments of `shoal rerun`.
#[derive(clap::Args, Debug, Default)]
pub struct RerunArgs {
    /// A run folder written by `shoal run`.
    pub dir: PathBuf,
    /// Worker threads.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs `shoal run`.
pub fn run(_args: RunArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`shoal run` is not available in this build yet")
}

/// Runs `shoal rerun`.
pub fn rerun(_args: RerunArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`shoal rerun` is not available in this build yet")
}
