//! One module per command.

pub mod bench;
pub mod check;
pub mod defs;
pub mod diff;
pub mod health;
pub mod lsp;
pub mod run;
pub mod sweep;
pub mod test;
pub mod view;
pub mod watch;

use std::process::ExitCode;

/// Exit code for bad input (a file with errors).
pub const BAD_INPUT: u8 = 2;

/// Prints diagnostics to stderr and returns the bad-input exit code.
pub fn report(d: &shoal::diag::Diagnostics) -> ExitCode {
    eprintln!("{d}");
    let n = d.0.len();
    eprintln!("{n} error{}", if n == 1 { "" } else { "s" });
    ExitCode::from(BAD_INPUT)
}
