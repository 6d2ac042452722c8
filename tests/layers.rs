//! The core's layers, checked from the source: each module in [`LAYERS`] imports only the modules
//! below it, so the core has no import cycle and the tick reads bottom to top. Only non-test code
//! counts (a file's `#[cfg(test)]` part may reach anywhere). The species (its file format, its
//! validation and the runtime species) and the script host are layers of their own: the stages
//! that read a species sit above them, and the parameter types a species file names of those
//! stages sit below them, in `params`. What is above the core (scenarios, records, health, the
//! tools) is not ordered here.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Core modules, lowest first. `events::apply` (stage 7) stands apart from the event types: it is
/// written as a method of the tick's `Pipeline`, which calls it without importing it.
const LAYERS: &[&str] = &[
    // Whether a pass may split (a tick the governor runs on one thread).
    "par",
    "frame",
    "command",
    // The loader helpers every loader uses (`crate::diag` and `crate::numbers` are short paths
    // into it), then terrain and formations: pure data and planning, below the world because it
    // holds the terrain and the squads' board.
    "load",
    "terrain",
    "formation",
    "world",
    "events",
    "index",
    "perception",
    "drives",
    // What a species is built from and holds: the later stages' parameter types, scripts.
    "params",
    "script",
    "species",
    "ctx",
    "steering",
    "decision",
    "locomotion",
    "tick",
    "events::apply",
    // Squads run between ticks; the `Sim` owns them.
    "squad",
    "sim",
];

fn rank(node: &str) -> Option<usize> {
    LAYERS.iter().position(|l| *l == node)
}

/// The core node a source file belongs to.
fn node_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap();
    let parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if parts.len() >= 2 && parts[0] == "events" && parts[1] == "apply" {
        return "events::apply".into();
    }
    parts[0].clone()
}

/// The core node a `crate::…` path names (`crate::diag` and `crate::numbers` are short paths into
/// `load`).
fn node_of_path(path: &str) -> String {
    if path.starts_with("events::apply") {
        return "events::apply".into();
    }
    let head = path.split("::").next().unwrap_or("");
    let head = head
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .next()
        .unwrap_or("");
    match head {
        "diag" | "numbers" => "load".into(),
        _ => head.to_string(),
    }
}

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Every import of a core module by one below it, as "a imports b, which is above it (file:line)".
fn upward_imports(src: &Path, sources: &[(PathBuf, String)]) -> Vec<String> {
    // (from, to) → first place it happens.
    let mut upward: BTreeMap<(String, String), String> = BTreeMap::new();
    for (file, text) in sources {
        let from = node_of(src, file);
        let Some(r_from) = rank(&from) else { continue };
        let mut skip_next = false;
        let mut lines = text.lines().enumerate().peekable();
        while let Some((n, line)) = lines.next() {
            let line = line.trim_start();
            if std::mem::take(&mut skip_next) || line.starts_with("//") {
                continue;
            }
            if line.trim_end() == "#[cfg(test)]" {
                // An inline test module runs to the end of the file; any other test-only item
                // is the next line.
                match lines.peek() {
                    Some((_, next)) if inline_module(next) => break,
                    _ => skip_next = true,
                }
                continue;
            }
            let mut targets = Vec::new();
            for (i, _) in line.match_indices("crate::") {
                targets.push(node_of_path(&line[i + "crate::".len()..]));
            }
            for to in targets {
                let Some(r_to) = rank(&to) else { continue };
                if to != from && r_to > r_from {
                    let at = format!("{}:{}", file.strip_prefix(src).unwrap().display(), n + 1);
                    upward.entry((from.clone(), to)).or_insert(at);
                }
            }
        }
    }
    upward
        .iter()
        .map(|((a, b), at)| format!("{a} imports {b}, which is above it ({at})"))
        .collect()
}

/// Whether `line` opens an inline module (`mod x {`, `pub(super) mod x {`, ...).
fn inline_module(line: &str) -> bool {
    let mut words = line.split_whitespace();
    let first = words.next().unwrap_or("");
    let item = if first.starts_with("pub") {
        words.next().unwrap_or("")
    } else {
        first
    };
    item == "mod" && line.trim_end().ends_with('{')
}

#[test]
fn each_core_module_imports_only_the_ones_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut all = Vec::new();
    files(&src, &mut all);
    all.sort();
    let mut sources: Vec<(PathBuf, String)> = all
        .into_iter()
        .map(|f| {
            let text = std::fs::read_to_string(&f).unwrap();
            (f, text)
        })
        .collect();
    // Files that are test modules (`#[cfg(test)] mod x;` in their parent) may reach anywhere.
    let mut test_only = Vec::new();
    for (file, text) in &sources {
        let dir = file.parent().unwrap();
        let mut lines = text.lines().map(str::trim);
        while let Some(l) = lines.next() {
            if l == "#[cfg(test)]" {
                if let Some(m) = lines.next().and_then(|n| n.strip_prefix("mod ")) {
                    test_only.push(dir.join(m.trim_end_matches(';')));
                }
            }
        }
    }
    // `x.rs`, or every file of the folder `x/`.
    sources.retain(|(f, _)| {
        !test_only
            .iter()
            .any(|t| f.with_extension("") == *t || f.starts_with(t))
    });
    let report = upward_imports(&src, &sources);
    assert!(report.is_empty(), "\n{}", report.join("\n"));
}

/// The check itself bites: a core module reaching up is reported (through a short path too), a
/// reach down, a comment, a test module or a module outside the layers is not.
#[test]
fn an_import_from_above_is_found() {
    let src = Path::new("/x/src");
    let file = |p: &str, text: &str| (src.join(p), text.to_string());
    let report = upward_imports(
        src,
        &[
            file(
                "world/agent.rs",
                "use crate::frame;\n// crate::tick\nuse crate::steering::Steer;\n",
            ),
            file(
                "world/mod.rs",
                "use crate::terrain::Terrain;\nuse crate::squad::Board;\n",
            ),
            file(
                "events/apply.rs",
                "use crate::decision::Ctx;\nuse crate::sim::Sim;\n",
            ),
            file(
                "events/mod.rs",
                "use crate::world::AgentId;\n#[cfg(test)]\nuse crate::sim::Sim;\n",
            ),
            file(
                "world/rng.rs",
                "#[cfg(test)]\npub(super) mod tests {\n    use crate::sim::Sim;\n}\n",
            ),
            file("frame.rs", "let far = crate::numbers::MAX_COORD;\n"),
            file("terrain/dem.rs", "use crate::diag::Diagnostic;\n"),
            file("species/mod.rs", "use crate::tick::Pipeline;\n"),
            file("scenario/mod.rs", "use crate::sim::Sim;\n"),
        ],
    );
    assert_eq!(
        report,
        [
            "events::apply imports sim, which is above it (events/apply.rs:2)",
            "frame imports load, which is above it (frame.rs:1)",
            "species imports tick, which is above it (species/mod.rs:1)",
            "world imports squad, which is above it (world/mod.rs:2)",
            "world imports steering, which is above it (world/agent.rs:3)",
        ]
    );
}
