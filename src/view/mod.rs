//! Replay viewer: turns a recorded run folder into one self-contained HTML page.
//!
//! Not a tick stage: it reads what the recorder wrote (`manifest.json`, `world.json`,
//! `trajectories.csv`, `food.csv`, `events.jsonl`, `health.json`; format in `docs/viewer.md`) and
//! embeds it as a compact columnar payload next to a hand-written WebGL page. The same page, without
//! a payload and with `window.SHOAL_LIVE = true`, is the live view that `shoal watch` serves
//! ([`live_html`]).

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::diag::Diagnostic;

mod csv;
mod events;
mod explain;
mod health;

pub(crate) use health::to_meta as health_meta;
mod manifest;
mod payload;
mod world;

/// The page template; `/*@CSS@*/`, `/*@BOOT@*/`, `<!--@DATA@-->` and `/*@JS@*/` are filled in.
const TEMPLATE: &str = include_str!("viewer.html");
/// The page's script: the parts of one function scope, in order (each file's header says what it
/// holds). Joined at compile time so the page stays one self-contained file.
const SCRIPT: &str = concat!(
    include_str!("js/util.js"),
    include_str!("js/render.js"),
    include_str!("js/shapes.js"),
    include_str!("js/scene.js"),
    include_str!("js/pick.js"),
    include_str!("js/legend.js"),
    include_str!("js/probe.js"),
    include_str!("js/panel.js"),
    include_str!("js/annotate.js"),
    include_str!("js/health.js"),
    include_str!("js/replay.js"),
    include_str!("js/live.js"),
    include_str!("js/graph.js"),
    include_str!("js/main.js"),
);
/// The page's style sheet.
const STYLE: &str = include_str!("viewer.css");

/// Default bound on the encoded frame data of one page (bytes).
pub const DEFAULT_MAX_PAYLOAD_BYTES: usize = 150_000_000;

/// Why a run folder could not be turned into a page.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// A file of the run folder could not be read, or the page could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying failure.
        #[source]
        source: std::io::Error,
    },
    /// A file of the run folder does not follow the run-folder format; names file, line and column.
    #[error("{0}")]
    Format(#[from] Diagnostic),
}

impl ViewError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> ViewError {
        ViewError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// The file the error is about.
    pub fn file(&self) -> &Path {
        match self {
            ViewError::Io { path, .. } => path,
            ViewError::Format(d) => &d.file,
        }
    }

    /// The 1-based line of the problem, when it has one.
    pub fn line(&self) -> Option<usize> {
        match self {
            ViewError::Format(d) if d.line > 0 => Some(d.line),
            _ => None,
        }
    }
}

/// Settings for building a replay page.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ViewOptions {
    /// Bound on the encoded frame data (bytes); above it frames are subsampled with a stride.
    pub max_payload_bytes: usize,
}

impl Default for ViewOptions {
    fn default() -> Self {
        ViewOptions {
            max_payload_bytes: DEFAULT_MAX_PAYLOAD_BYTES,
        }
    }
}

pub(crate) fn read_text(path: &Path) -> Result<String, ViewError> {
    fs::read_to_string(path).map_err(|e| ViewError::io(path, e))
}

/// The replay page for the run folder `run_dir`, with default options.
pub fn build_html(run_dir: &Path) -> Result<String, ViewError> {
    build_html_with(run_dir, &ViewOptions::default())
}

/// The replay page for the run folder `run_dir`.
pub fn build_html_with(run_dir: &Path, options: &ViewOptions) -> Result<String, ViewError> {
    let p = payload::build(run_dir, options.max_payload_bytes)?;
    let meta = escape_script_text(&p.meta.to_string());
    let mut data = String::with_capacity(
        meta.len() + p.columns.iter().map(|c| c.base64.len() + 96).sum::<usize>(),
    );
    data.push_str("<script type=\"application/json\" id=\"shoal-meta\">");
    data.push_str(&meta);
    data.push_str("</script>\n");
    for c in &p.columns {
        data.push_str("<script type=\"application/octet-stream\" class=\"shoal-col\" data-name=\"");
        data.push_str(c.name);
        data.push_str("\" data-kind=\"");
        data.push_str(c.kind);
        data.push_str("\">");
        data.push_str(&c.base64);
        data.push_str("</script>\n");
    }
    // What explains the selected agent (frames, decisions, contacts).
    data.push_str("<script type=\"application/json\" id=\"shoal-explain\">");
    data.push_str(&escape_script_text(&explain::build(run_dir).to_string()));
    data.push_str("</script>\n");
    Ok(page("window.SHOAL_LIVE = false;", &data))
}

/// The live page `shoal watch` serves: no embedded run, `window.SHOAL_LIVE = true`; it reads the
/// `/stream` event source and talks to `/control` and `/agent/<id>` (see `docs/viewer.md`).
pub fn live_html() -> String {
    page("window.SHOAL_LIVE = true;", "")
}

/// Builds the replay page for `run_dir` and writes it to `run_dir/view.html` atomically (a
/// temporary file renamed into place). Returns the page's path.
pub fn write_html(run_dir: &Path) -> Result<PathBuf, ViewError> {
    let html = build_html(run_dir)?;
    let target = run_dir.join("view.html");
    let tmp = run_dir.join(format!(".view.html.{}.tmp", std::process::id()));
    let write = || -> std::io::Result<()> {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(html.as_bytes())?;
        f.sync_all()?;
        Ok(())
    };
    if let Err(e) = write() {
        let _ = fs::remove_file(&tmp);
        return Err(ViewError::io(&tmp, e));
    }
    fs::rename(&tmp, &target).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        ViewError::io(&target, e)
    })?;
    Ok(target)
}

fn page(boot: &str, data: &str) -> String {
    let mut out = String::with_capacity(TEMPLATE.len() + SCRIPT.len() + STYLE.len() + data.len());
    let mut rest = TEMPLATE;
    for (marker, fill) in [
        ("/*@CSS@*/", STYLE),
        ("/*@BOOT@*/", boot),
        ("<!--@DATA@-->", data),
        ("/*@JS@*/", SCRIPT),
    ] {
        let at = rest
            .find(marker)
            .unwrap_or_else(|| panic!("viewer.html lacks the {marker} marker"));
        out.push_str(&rest[..at]);
        out.push_str(fill);
        rest = &rest[at + marker.len()..];
    }
    out.push_str(rest);
    out
}

/// JSON text made safe inside a `<script>` element: `<` only occurs inside JSON strings, where
/// `\u003c` means the same.
fn escape_script_text(json: &str) -> String {
    json.replace('<', "\\u003c")
}

#[cfg(test)]
mod tests;
