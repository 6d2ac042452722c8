//! `shoal test [PATHS] [--filter NAME] [--coverage]`: runs designers' script tests and scenario
//! expectations (see `behaviors/tests/README.md`); one line per test, then `N passed, N failed`.
//! Exits 1 when a test failed, 2 when a path does not exist.

use shoal::testing::{self, Options};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `shoal test`.
#[derive(clap::Args, Debug, Default)]
pub struct TestArgs {
    /// Test files (`.rhai`), scenarios (`.ron`) or folders (default: behaviors/tests and
    /// scenarios/tests). Folders are walked; `fixtures` folders only run when named.
    pub paths: Vec<PathBuf>,
    /// Run only the tests whose name (`file::test_name`) contains this.
    #[arg(long)]
    pub filter: Option<String>,
    /// List, per species, the behaviors and transitions no test exercised.
    #[arg(long)]
    pub coverage: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs `shoal test`.
pub fn test(args: TestArgs) -> anyhow::Result<ExitCode> {
    let paths = if args.paths.is_empty() {
        testing::default_paths()
    } else {
        args.paths
    };
    for p in &paths {
        if !p.exists() {
            eprintln!("{}: no such file or folder", p.display());
            return Ok(ExitCode::from(super::BAD_INPUT));
        }
    }
    let opts = Options {
        filter: args.filter,
        threads: args.threads,
        ..Options::default()
    };
    let report = testing::run(&paths, &opts);
    print!("{}", report.lines());
    if args.coverage {
        println!();
        println!("{}", report.coverage());
    }
    println!("{}", report.summary());
    Ok(if report.failed() > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}
