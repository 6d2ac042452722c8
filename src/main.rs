//! The `shoal` command line: a thin layer over the library. Arguments are parsed here, turned
//! into a configuration once, and handed to the command's module in `cli/`.

mod cli;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// shoal: animal and unit behavior as data and scripts.
#[derive(Parser, Debug)]
#[command(name = "shoal", version, about, long_about = None)]
struct Args {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scenario headless, as fast as possible, and record it.
    Run(cli::run::RunArgs),
    /// Re-run a recorded run from its folder and check that it matches bit for bit.
    Rerun(cli::run::RerunArgs),
    /// Validate species, scripts and scenarios without running them.
    Check {
        /// Files or folders (default: behaviors/ and scenarios/).
        paths: Vec<PathBuf>,
    },
    /// Write (and optionally open) the replay viewer of a recorded run.
    View(cli::view::ViewArgs),
    /// Report where two runs of the same scenario diverge.
    Diff(cli::diff::DiffArgs),
    /// Print the run-health figures and warnings of a recorded run.
    Health(cli::health::HealthArgs),
    /// Run a scenario live with hot reload and a browser viewer.
    Watch(cli::watch::WatchArgs),
    /// Run designers' script tests.
    Test(cli::test::TestArgs),
    /// Run a benchmark workload and print a table.
    Bench(cli::bench::BenchArgs),
    /// Plan, run and collect parameter sweeps (see docs/sweeps.md).
    Sweep(cli::sweep::SweepArgs),
    /// Serve the Language Server Protocol on stdio, for editors.
    Lsp,
    /// Write Rhai definition files of the script and test APIs and JSON Schemas of the formats.
    Defs(cli::defs::DefsArgs),
}

fn main() -> ExitCode {
    // Output piped into `head` and closed early is not an error worth a backtrace.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("Broken pipe") {
            std::process::exit(141);
        }
        default_hook(info);
    }));
    let args = Args::parse();
    let command = args
        .command
        .unwrap_or(Command::Run(cli::run::RunArgs::default()));
    let result = match command {
        Command::Run(a) => cli::run::run(a),
        Command::Rerun(a) => cli::run::rerun(a),
        Command::Check { paths } => cli::check::check(&paths),
        Command::View(a) => cli::view::view(a),
        Command::Diff(a) => cli::diff::diff(a),
        Command::Health(a) => cli::health::health(a),
        Command::Watch(a) => cli::watch::watch(a),
        Command::Test(a) => cli::test::test(a),
        Command::Bench(a) => cli::bench::bench(a),
        Command::Sweep(a) => cli::sweep::sweep(a),
        Command::Lsp => cli::lsp::lsp(),
        Command::Defs(a) => cli::defs::defs(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
