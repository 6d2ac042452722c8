//! `shoal lsp`: the language server for editors, over stdio (see `docs/editors.md`).

use std::process::ExitCode;

/// Runs the server until the editor closes it.
pub fn lsp() -> anyhow::Result<ExitCode> {
    shoal::lsp::serve_stdio()?;
    Ok(ExitCode::SUCCESS)
}
