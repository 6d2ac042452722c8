//! Part of stage 4 (decision), at load time: resolving a script's `import`s.
//!
//! Each imported file is resolved, confined, read, compiled and evaluated once per load, whatever
//! the number of paths that reach it (a diamond of imports costs one compile per file, not one
//! per path): modules are cached by canonical path. A module that imports itself, directly or
//! not, is an error naming the chain. Paths are canonicalized before they are checked against
//! the behaviors folder, so neither `..` nor a symbolic link can reach a file outside it.
//!
//! Modules are registered on the importing engine as static modules under their alias (Rhai's
//! module resolver is never used at run time), with the modules they import themselves, because
//! a module's functions run on the engine that calls them.
//!
//! A load keeps what it read ([`Sources`]: each import's resolution and each module's text), so
//! that the script can be compiled again exactly the same without the file system
//! ([`super::Script`]'s per-thread replicas): a module edited meanwhile must not give one worker
//! thread other code than the rest.

use super::calls::{self, Known};
use super::{new_engine, parse_diag, SandboxLimits};
use crate::diag::Diagnostic;
use rhai::{Engine, Module, Scope, Shared};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One `import "path" as alias;` statement of a script.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ImportStmt {
    /// The path as written.
    pub path: String,
    /// The alias (empty when missing).
    pub alias: String,
    /// Line and column of the statement, 1-based.
    pub line: usize,
    pub col: usize,
    /// Byte range of the whole statement in the text (blanked before a module is compiled).
    pub span: (usize, usize),
}

/// Finds `import "path" as name;` statements that start a line in `text`.
pub(crate) fn find_imports(text: &str) -> Vec<ImportStmt> {
    let mut out = Vec::new();
    let mut offset = 0;
    for (ln, line) in text.split_inclusive('\n').enumerate() {
        let start = offset;
        offset += line.len();
        let line = line.trim_end_matches(['\n', '\r']);
        let t = line.trim_start();
        let Some(rest) = t.strip_prefix("import") else {
            continue;
        };
        let col = line.len() - t.len() + 1;
        let rest = rest.trim_start();
        let Some(q) = rest.strip_prefix('"') else {
            continue;
        };
        let Some(end) = q.find('"') else {
            continue;
        };
        let path = q[..end].to_string();
        let after = q[end + 1..].trim_start();
        let alias = after
            .strip_prefix("as")
            .map(|a| a.trim().trim_end_matches(';').trim().to_string())
            .unwrap_or_default();
        let stmt_end = line.find(';').map_or(line.len(), |i| i + 1);
        out.push(ImportStmt {
            path,
            alias,
            line: ln + 1,
            col,
            span: (start + col - 1, start + stmt_end),
        });
    }
    out
}

/// `text` with its import statements replaced by spaces (positions stay where they were): the
/// host registers the modules, so the statements must not run.
fn blank_imports(text: &str, imports: &[ImportStmt]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for i in imports {
        for b in &mut bytes[i.span.0..i.span.1] {
            *b = b' ';
        }
    }
    // Only ASCII bytes of whole statements were replaced.
    String::from_utf8(bytes).unwrap_or_else(|_| text.to_string())
}

/// A compiled module.
#[derive(Clone)]
pub(crate) struct Loaded {
    pub module: Shared<Module>,
    /// Its public functions, with their parameter count.
    pub functions: Vec<(String, usize)>,
    /// Every module it imports, directly or not, by alias, with its file.
    pub nested: Vec<(String, PathBuf, Shared<Module>)>,
}

/// What a load of a script read from the file system: where each import resolved and the text
/// of each module, enough to compile the script again the same way ([`Loader::replay`]).
#[derive(Debug, Default)]
pub(crate) struct Sources {
    /// The script's own canonical path.
    own: PathBuf,
    /// (importing file, path as written) → (file found, canonical path).
    resolved: BTreeMap<(PathBuf, String), (PathBuf, PathBuf)>,
    /// Each module's text, by the path it was found at.
    texts: BTreeMap<PathBuf, String>,
}

/// Resolves the imports of one script, compiling each module once.
pub(crate) struct Loader<'a> {
    limits: &'a SandboxLimits,
    /// Canonical folders imports may come from.
    allowed: Vec<PathBuf>,
    /// The folder import paths are first resolved in.
    root: PathBuf,
    cache: BTreeMap<PathBuf, Loaded>,
    /// The files being loaded, outermost first (a cycle is a file already in it).
    stack: Vec<PathBuf>,
    /// Every imported file, in the order first met.
    pub files: Vec<PathBuf>,
    /// Whether an imported file raises to a power ([`super::exact_power`]): the engines that
    /// run its functions need it too.
    pub power: bool,
    /// Whether an imported file names the mean heading ([`super::names_heading`]).
    pub heading: bool,
    pub diags: Vec<Diagnostic>,
    /// What this load read (for a replay).
    pub sources: Sources,
    /// A load being replayed: everything is read from it, nothing from the file system.
    replay: Option<&'a Sources>,
}

impl<'a> Loader<'a> {
    /// A loader for the script `file`: imports are resolved in `root`, then beside the script,
    /// and must stay inside one of those two folders.
    pub fn new(file: &Path, root: &Path, limits: &'a SandboxLimits) -> Self {
        let dir = file.parent().unwrap_or(Path::new("."));
        let mut allowed: Vec<PathBuf> = [root, dir]
            .iter()
            .filter_map(|d| canonical_dir(d).ok())
            .collect();
        allowed.dedup();
        let own = std::fs::canonicalize(file).unwrap_or_else(|_| file.to_path_buf());
        Self::start(limits, allowed, root, own, None)
    }

    /// A loader of the script at canonical path `own` that has read nothing yet.
    fn start(
        limits: &'a SandboxLimits,
        allowed: Vec<PathBuf>,
        root: &Path,
        own: PathBuf,
        replay: Option<&'a Sources>,
    ) -> Self {
        Loader {
            limits,
            allowed,
            root: root.to_path_buf(),
            cache: BTreeMap::new(),
            stack: vec![own.clone()],
            files: Vec::new(),
            power: false,
            heading: false,
            diags: Vec::new(),
            sources: Sources {
                own,
                ..Sources::default()
            },
            replay,
        }
    }

    /// Its sandbox limits.
    pub fn limits(&self) -> &'a SandboxLimits {
        self.limits
    }

    /// Whether it replays an earlier load ([`Loader::replay`]).
    pub fn replaying(&self) -> bool {
        self.replay.is_some()
    }

    /// A loader that reads what an earlier load read ([`Loader::sources`]) and nothing else.
    pub fn replay(sources: &'a Sources, root: &Path, limits: &'a SandboxLimits) -> Self {
        Self::start(limits, Vec::new(), root, sources.own.clone(), Some(sources))
    }

    /// [`Loader::resolve`], remembered for a replay (or taken from the load replayed).
    fn resolve_kept(&mut self, from: &Path, path: &str) -> Result<(PathBuf, PathBuf), String> {
        let key = (from.to_path_buf(), path.to_string());
        if let Some(r) = self.replay {
            return r
                .resolved
                .get(&key)
                .cloned()
                .ok_or_else(|| format!("import \"{path}\" was not resolved in the load replayed"));
        }
        let found = self.resolve(from, path)?;
        self.sources.resolved.insert(key, found.clone());
        Ok(found)
    }

    /// The text of the module found at `path`, remembered for a replay (or taken from the load
    /// replayed).
    fn read_kept(&mut self, path: &Path) -> Result<String, Diagnostic> {
        if let Some(r) = self.replay {
            return r.texts.get(path).cloned().ok_or_else(|| {
                Diagnostic::file(path, "module not read in the load replayed".to_string())
            });
        }
        let text = crate::diag::read_text(path, "module")?;
        self.sources.texts.insert(path.to_path_buf(), text.clone());
        Ok(text)
    }

    /// Registers on `engine` the modules `text` (the file `file`) imports; returns what they
    /// define, for the check of the script's calls.
    pub fn register(&mut self, engine: &mut Engine, file: &Path, text: &str) -> Known {
        let mut known = Known::default();
        let mut direct: Vec<(String, PathBuf, Shared<Module>)> = Vec::new();
        let mut nested: Vec<(String, PathBuf, Shared<Module>)> = Vec::new();
        for stmt in find_imports(text) {
            let at = |msg: String| Diagnostic::new(file, stmt.line, stmt.col, msg, Some(text));
            if stmt.alias.is_empty() {
                self.diags
                    .push(at("expected `import \"path\" as name;`".into()));
                continue;
            }
            let (found, canonical) = match self.resolve_kept(file, &stmt.path) {
                Ok(p) => p,
                Err(msg) => {
                    self.diags.push(at(msg));
                    continue;
                }
            };
            if let Some(i) = self.stack.iter().position(|p| *p == canonical) {
                let chain: Vec<String> = self.stack[i..]
                    .iter()
                    .chain(std::iter::once(&canonical))
                    .map(|p| self.shown(p))
                    .collect();
                self.diags.push(at(format!(
                    "import cycle: {} (a module cannot import itself, directly or through others)",
                    chain.join(" → ")
                )));
                continue;
            }
            let Some(loaded) = self.load(&canonical, &found) else {
                continue;
            };
            known
                .modules
                .insert(stmt.alias.clone(), loaded.functions.clone());
            // Each (alias, file) once: a diamond of imports must not grow this list per path.
            for (a, p, m) in &loaded.nested {
                if !nested.iter().any(|(b, q, _)| b == a && q == p) {
                    nested.push((a.clone(), p.clone(), m.clone()));
                }
            }
            if !direct
                .iter()
                .any(|(b, q, _)| *b == stmt.alias && *q == canonical)
            {
                direct.push((stmt.alias.clone(), canonical, loaded.module.clone()));
            }
        }
        // One alias, one module, over the whole import tree: a module's functions resolve the
        // aliases they use on the engine of the script that calls them.
        let mut by_alias: BTreeMap<&str, &Path> = BTreeMap::new();
        for (a, p, m) in nested.iter().chain(direct.iter()) {
            match by_alias.get(a.as_str()) {
                Some(q) if *q != p.as_path() => {
                    let (line, col) = find_imports(text)
                        .iter()
                        .find(|s| s.alias == *a)
                        .map_or((0, 0), |s| (s.line, s.col));
                    self.diags.push(Diagnostic::new(
                        file,
                        line,
                        col,
                        format!(
                            "the name `{a}` is used for two modules ({} and {}) in this script's imports: give them different names",
                            self.shown(q),
                            self.shown(p)
                        ),
                        Some(text),
                    ));
                }
                Some(_) => {}
                None => {
                    by_alias.insert(a, p);
                    engine.register_static_module(a.as_str(), m.clone());
                }
            }
        }
        for d in direct {
            if !nested.iter().any(|(b, q, _)| *b == d.0 && *q == d.1) {
                nested.push(d);
            }
        }
        known.nested = nested;
        known
    }

    /// The module `path` imported by `from`, as found and canonical, or why not.
    fn resolve(&self, from: &Path, path: &str) -> Result<(PathBuf, PathBuf), String> {
        let rel = if path.ends_with(".rhai") {
            path.to_string()
        } else {
            format!("{path}.rhai")
        };
        let candidates = [
            self.root.join(&rel),
            from.parent().unwrap_or(Path::new(".")).join(&rel),
        ];
        // A named pipe or a folder in the way is reported by name, not as missing.
        let Some(found) = candidates
            .iter()
            .find(|p| p.is_file())
            .or_else(|| candidates.iter().find(|p| p.exists()))
        else {
            return Err(format!(
                "cannot find imported module \"{path}\" (looked for {})",
                candidates[0].display()
            ));
        };
        if let Some(problem) = crate::diag::file_problem(found) {
            return Err(format!("imported module \"{}\" {problem}", found.display()));
        }
        let canonical = std::fs::canonicalize(found)
            .map_err(|e| format!("cannot resolve imported module \"{path}\": {e}"))?;
        if !self.allowed.iter().any(|d| canonical.starts_with(d)) {
            return Err(format!(
                "imported module \"{path}\" resolves to {}, outside the behaviors folder ({}): modules must live inside it",
                canonical.display(),
                self.allowed
                    .first()
                    .map_or_else(|| self.root.display().to_string(), |d| d.display().to_string())
            ));
        }
        Ok((found.clone(), canonical))
    }

    /// Compiles and evaluates the module at canonical path `canonical` (found at `path`, the
    /// name diagnostics and recordings use), once per load.
    fn load(&mut self, canonical: &Path, path: &Path) -> Option<Loaded> {
        if let Some(l) = self.cache.get(canonical) {
            return Some(l.clone());
        }
        let text = match self.read_kept(path) {
            Ok(t) => t,
            Err(d) => {
                self.diags.push(d);
                return None;
            }
        };
        if !self.files.iter().any(|f| f == path) {
            self.files.push(path.to_path_buf());
        }
        if let Err(d) = super::check_size(path, &text, "module") {
            self.diags.push(d);
            return None;
        }
        let mut engine = new_engine(self.limits);
        self.stack.push(canonical.to_path_buf());
        let known = self.register(&mut engine, path, &text);
        self.stack.pop();
        self.power |= super::exact_power(&mut engine, &text);
        self.heading |= super::names_heading(&text);
        if self.power {
            engine.set_fast_operators(false);
        }
        let imports = find_imports(&text);
        let source = blank_imports(&text, &imports);
        let mut ast = match engine.compile(&source) {
            Ok(a) => a,
            Err(e) => {
                self.diags.push(parse_diag(path, &text, &e));
                return None;
            }
        };
        ast.set_source(path.display().to_string());
        self.diags.extend(calls::check(&ast, &known, path, &text));
        // Sorted: Rhai's table is in an order that differs between processes.
        let mut functions: Vec<(String, usize)> = ast
            .iter_functions()
            .filter(|f| f.access != rhai::FnAccess::Private)
            .map(|f| (f.name.to_string(), f.params.len()))
            .collect();
        functions.sort();
        match Module::eval_ast_as_new(Scope::new(), &ast, &engine) {
            Ok(mut m) => {
                m.build_index();
                let loaded = Loaded {
                    module: m.into(),
                    functions,
                    nested: known.nested,
                };
                self.cache.insert(canonical.to_path_buf(), loaded.clone());
                Some(loaded)
            }
            Err(e) => {
                let (l, c) = super::position_of(e.position());
                self.diags.push(Diagnostic::new(
                    path,
                    l,
                    c,
                    super::bare_message(&e),
                    Some(&text),
                ));
                None
            }
        }
    }

    /// A file as diagnostics name it: relative to the behaviors folder when inside it.
    fn shown(&self, p: &Path) -> String {
        self.allowed
            .iter()
            .find_map(|d| p.strip_prefix(d).ok())
            .unwrap_or(p)
            .display()
            .to_string()
    }
}

fn canonical_dir(d: &Path) -> std::io::Result<PathBuf> {
    let d = if d.as_os_str().is_empty() {
        Path::new(".")
    } else {
        d
    };
    std::fs::canonicalize(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn import_statements_are_found_with_their_spans() {
        let text = "// x\n  import \"common/a\" as a;\nfn f() { 1 }\n";
        let found = find_imports(text);
        assert_eq!(found.len(), 1);
        let i = &found[0];
        assert_eq!((i.path.as_str(), i.alias.as_str()), ("common/a", "a"));
        assert_eq!((i.line, i.col), (2, 3));
        assert_eq!(&text[i.span.0..i.span.1], "import \"common/a\" as a;");
        let blank = blank_imports(text, &found);
        assert_eq!(blank.len(), text.len());
        assert!(!blank.contains("import"));
        assert!(blank.contains("fn f() { 1 }"));
    }
}
