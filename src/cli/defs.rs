//! `shoal defs`: definition files for tools without the language server: Rhai definitions of
//! the script and test APIs (`script.d.rhai`, `test.d.rhai`) and JSON Schemas of the species
//! and scenario formats (`species.schema.json`, `scenario.schema.json`).

use anyhow::Context;
use shoal::lsp::assist::api::{definitions, Api};
use shoal::lsp::assist::json_schema;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `shoal defs`.
#[derive(clap::Args, Debug)]
pub struct DefsArgs {
    /// Folder to write into (created if missing).
    #[arg(long, default_value = "defs")]
    pub out: PathBuf,
}

/// Writes the definition files and lists them.
pub fn defs(a: DefsArgs) -> anyhow::Result<ExitCode> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let files = [
        ("script.d.rhai", definitions(Api::Script)),
        ("test.d.rhai", definitions(Api::Test)),
        (
            "species.schema.json",
            serde_json::to_string_pretty(&json_schema::species())?,
        ),
        (
            "scenario.schema.json",
            serde_json::to_string_pretty(&json_schema::scenario())?,
        ),
    ];
    for (name, text) in files {
        let path = a.out.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
        println!("{}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}
