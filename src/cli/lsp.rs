//! `shoal lsp`: the language server for editors, over stdio (see `docs/editors.md`).

use std::process::ExitCode;

/// Runs the server until the editor closes it: exit code 0 after `shutdown` then `exit`, 1 when
/// `exit` came without `shutdown` or the editor went away.
pub fn lsp() -> anyhow::Result<ExitCode> {
    let code = shoal::lsp::serve_stdio()?;
    Ok(ExitCode::from(u8::try_from(code).unwrap_or(1)))
}
