//! Part of stage 4 (decision): the Rhai script host.
//!
//! One [`Script`] per species file, compiled once per (re)load with the imports it names compiled
//! as static modules. Scripts run sandboxed: no file, network or environment access, and limits
//! on operations per call (a `loop {}` is stopped), call depth, string, array and map sizes.
//! Calls bind the agent's typed [`AgentView`] as `this`; nothing is looked up by string in the hot
//! path, and calls happen only at the species' decision rate or on events.

mod view;

pub use view::{from_mem, register_api, to_mem, AgentView, CategoryView, ScriptSteer, SteerTerm};

use crate::diag::{Diagnostic, Diagnostics};
use rhai::{CallFnOptions, Dynamic, Engine, EvalAltResult, Module, Position, Scope, AST};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Safety limits applied to every script call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Operations per call; a call that exceeds it is stopped.
    pub max_operations: u64,
    /// Call depth.
    pub max_call_levels: usize,
    /// Longest string.
    pub max_string_size: usize,
    /// Largest array.
    pub max_array_size: usize,
    /// Largest map.
    pub max_map_size: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_operations: 200_000,
            max_call_levels: 32,
            max_string_size: 4096,
            max_array_size: 4096,
            max_map_size: 256,
        }
    }
}

/// A compiled species script with its own engine (which holds the imported modules).
pub struct Script {
    engine: Engine,
    ast: AST,
    /// The script file.
    pub file: PathBuf,
    /// Its text (for locating diagnostics).
    pub text: Arc<str>,
    /// Every file it imports, directly or not.
    pub imports: Vec<PathBuf>,
    /// Functions it defines, with their parameter count.
    pub functions: Vec<(String, usize)>,
}

impl std::fmt::Debug for Script {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Script")
            .field("file", &self.file)
            .field("functions", &self.functions)
            .finish()
    }
}

/// A failed call, located in the script.
#[derive(Debug, Clone, PartialEq)]
pub struct CallError {
    /// `file:line:col: message`.
    pub diagnostic: Diagnostic,
}

/// A fresh sandboxed engine with the shoal API registered.
pub fn new_engine(limits: &Limits) -> Engine {
    let mut e = Engine::new();
    e.set_max_operations(limits.max_operations);
    e.set_max_call_levels(limits.max_call_levels);
    e.set_max_string_size(limits.max_string_size);
    e.set_max_array_size(limits.max_array_size);
    e.set_max_map_size(limits.max_map_size);
    e.set_max_expr_depths(64, 32);
    e.set_max_modules(64);
    e.set_strict_variables(true);
    // Scripts write nothing to the terminal by themselves.
    e.on_print(|_| {});
    e.on_debug(|_, _, _| {});
    // Imports are resolved by the host (static modules); nothing loads files at run time.
    e.set_module_resolver(rhai::module_resolvers::DummyModuleResolver::new());
    register_api(&mut e);
    e
}

fn parse_diag(file: &Path, text: &str, err: &rhai::ParseError) -> Diagnostic {
    let pos = err.1;
    Diagnostic::new(
        file,
        pos.line().unwrap_or(0),
        pos.position().unwrap_or(0),
        err.0.to_string(),
        Some(text),
    )
}

/// Finds `import "path" as name;` statements at the top level of `text`, with the line and
/// column of each path.
fn find_imports(text: &str) -> Vec<(String, String, usize, usize)> {
    let mut out = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if let Some(rest) = t.strip_prefix("import") {
            let col = line.len() - t.len() + 1;
            let rest = rest.trim_start();
            if let Some(q) = rest.strip_prefix('"') {
                if let Some(end) = q.find('"') {
                    let path = q[..end].to_string();
                    let after = q[end + 1..].trim_start();
                    let alias = after
                        .strip_prefix("as")
                        .map(|a| a.trim().trim_end_matches(';').trim().to_string())
                        .unwrap_or_default();
                    out.push((path, alias, ln + 1, col));
                }
            }
        }
    }
    out
}

impl Script {
    /// Compiles the script at `file`; imports are resolved relative to `root` (the behaviors
    /// folder), then relative to the script's own folder, with the `.rhai` extension added.
    pub fn load(file: &Path, root: &Path, limits: &Limits) -> Result<Script, Diagnostics> {
        let text = std::fs::read_to_string(file)
            .map_err(|e| Diagnostic::file(file, format!("cannot read script: {e}")))?;
        Self::compile(file, &text, root, limits)
    }

    /// Compiles script `text` (named `file` in diagnostics).
    pub fn compile(
        file: &Path,
        text: &str,
        root: &Path,
        limits: &Limits,
    ) -> Result<Script, Diagnostics> {
        let mut engine = new_engine(limits);
        let mut imports = Vec::new();
        let mut seen = BTreeSet::new();
        let mut diags = Vec::new();
        let mut nested = Vec::new();
        register_imports(
            &mut engine,
            file,
            text,
            root,
            limits,
            &mut imports,
            &mut seen,
            &mut diags,
            &mut nested,
            0,
        );
        if !diags.is_empty() {
            return Err(Diagnostics(diags));
        }
        let mut ast = engine
            .compile(text)
            .map_err(|e| Diagnostics::from(parse_diag(file, text, &e)))?;
        ast.set_source(file.display().to_string());
        let functions = ast
            .iter_functions()
            .map(|f| (f.name.to_string(), f.params.len()))
            .collect();
        Ok(Script {
            engine,
            ast,
            file: file.to_path_buf(),
            text: text.into(),
            imports,
            functions,
        })
    }

    /// Whether the script defines `name` taking `params` parameters.
    pub fn has_fn(&self, name: &str, params: usize) -> bool {
        self.functions
            .iter()
            .any(|(n, p)| n == name && *p == params)
    }

    /// Line and column of `fn name` in the script (for errors about a function's result).
    pub fn fn_position(&self, name: &str) -> (usize, usize) {
        let pat = format!("fn {name}");
        for (i, line) in self.text.lines().enumerate() {
            if let Some(c) = line.find(&pat) {
                let rest = &line[c + pat.len()..];
                if rest.trim_start().starts_with('(') {
                    return (i + 1, c + 1);
                }
            }
        }
        (0, 0)
    }

    /// Calls `name` with `view` bound as `this` and no arguments.
    pub fn call<T: Clone + Send + Sync + 'static>(
        &self,
        scope: &mut Scope,
        this: &mut Dynamic,
        name: &str,
    ) -> Result<T, CallError> {
        self.call_args(scope, this, name, ())
    }

    /// Calls `name` with `this` bound and `args`.
    pub fn call_args<T: Clone + Send + Sync + 'static>(
        &self,
        scope: &mut Scope,
        this: &mut Dynamic,
        name: &str,
        args: impl rhai::FuncArgs,
    ) -> Result<T, CallError> {
        let options = CallFnOptions::new()
            .eval_ast(false)
            .rewind_scope(true)
            .bind_this_ptr(this);
        self.engine
            .call_fn_with_options::<T>(options, scope, &self.ast, name, args)
            .map_err(|e| {
                let mut diagnostic = self.locate_error(&e);
                // Some errors (the operation limit) carry no position: point at the function.
                if diagnostic.line == 0 && diagnostic.file == self.file {
                    let (line, col) = self.fn_position(name);
                    diagnostic = Diagnostic::new(
                        &self.file,
                        line,
                        col,
                        diagnostic.message,
                        Some(&self.text),
                    );
                }
                CallError { diagnostic }
            })
    }

    /// Turns a runtime error into a diagnostic that names the right file at the innermost frame.
    pub fn locate_error(&self, err: &EvalAltResult) -> Diagnostic {
        let site = error_site(err, &self.file, &self.text);
        let message = match site.error {
            EvalAltResult::ErrorTooManyOperations(_) => {
                "script exceeded its operation limit (an endless loop?); the agent keeps its last valid steering".to_string()
            }
            other => bare_message(other),
        };
        let (file, pos, text) = (site.file, site.pos, site.text);
        Diagnostic::new(
            file,
            pos.line().unwrap_or(0),
            pos.position().unwrap_or(0),
            message,
            text.as_deref(),
        )
    }
}

/// Position of a rhai error, as (line, col).
pub fn position_of(p: Position) -> (usize, usize) {
    (p.line().unwrap_or(0), p.position().unwrap_or(0))
}

#[allow(clippy::too_many_arguments)]
fn register_imports(
    engine: &mut Engine,
    file: &Path,
    text: &str,
    root: &Path,
    limits: &Limits,
    imports: &mut Vec<PathBuf>,
    seen: &mut BTreeSet<PathBuf>,
    diags: &mut Vec<Diagnostic>,
    nested: &mut Vec<(String, rhai::Shared<Module>)>,
    depth: usize,
) {
    for (path, alias, line, col) in find_imports(text) {
        let rel = if path.ends_with(".rhai") {
            path.clone()
        } else {
            format!("{path}.rhai")
        };
        let candidates = [
            root.join(&rel),
            file.parent().unwrap_or(Path::new(".")).join(&rel),
        ];
        let Some(found) = candidates.iter().find(|p| p.is_file()).cloned() else {
            diags.push(Diagnostic::new(
                file,
                line,
                col,
                format!(
                    "cannot find imported module \"{path}\" (looked for {})",
                    candidates[0].display()
                ),
                Some(text),
            ));
            continue;
        };
        if alias.is_empty() {
            diags.push(Diagnostic::new(
                file,
                line,
                col,
                "expected `import \"path\" as name;`",
                Some(text),
            ));
            continue;
        }
        if depth > 8 {
            diags.push(Diagnostic::new(
                file,
                line,
                col,
                "imports nested too deeply (a cycle?)",
                Some(text),
            ));
            continue;
        }
        seen.insert(found.clone());
        imports.push(found.clone());
        let sub_text = match std::fs::read_to_string(&found) {
            Ok(t) => t,
            Err(e) => {
                diags.push(Diagnostic::file(&found, format!("cannot read module: {e}")));
                continue;
            }
        };
        // Modules see the modules they import themselves; nested modules are registered on the
        // importing engine too, because a module's functions run on the engine that calls them.
        let mut sub_engine = new_engine(limits);
        if depth <= 8 {
            let before = nested.len();
            register_imports(
                &mut sub_engine,
                &found,
                &sub_text,
                root,
                limits,
                imports,
                seen,
                diags,
                nested,
                depth + 1,
            );
            for (a, m) in nested[before..].iter() {
                engine.register_static_module(a.as_str(), m.clone());
            }
        }
        let mut ast = match sub_engine.compile(&sub_text) {
            Ok(a) => a,
            Err(e) => {
                diags.push(parse_diag(&found, &sub_text, &e));
                continue;
            }
        };
        ast.set_source(found.display().to_string());
        match Module::eval_ast_as_new(Scope::new(), &ast, &sub_engine) {
            Ok(mut m) => {
                m.build_index();
                let m: rhai::Shared<Module> = m.into();
                engine.register_static_module(alias.as_str(), m.clone());
                nested.push((alias.clone(), m));
            }
            Err(e) => {
                let (l, c) = position_of(e.position());
                diags.push(Diagnostic::new(
                    &found,
                    l,
                    c,
                    e.to_string(),
                    Some(&sub_text),
                ));
            }
        }
    }
}

/// Where a runtime error happened: its innermost frame (through nested function calls and
/// modules), the file that frame is in (a module's path, or the script's own file) and that
/// file's text, and the position there.
pub struct ErrorSite<'e> {
    /// The innermost error.
    pub error: &'e EvalAltResult,
    /// The file it is in.
    pub file: PathBuf,
    /// The text of that file, when it can be read.
    pub text: Option<String>,
    /// Where in it.
    pub pos: Position,
}

/// The site of `err`, raised by a script read from `file` with text `text`.
pub fn error_site<'e>(err: &'e EvalAltResult, file: &Path, text: &str) -> ErrorSite<'e> {
    let mut source = String::new();
    let mut e = err;
    let mut pos = err.position();
    loop {
        match e {
            EvalAltResult::ErrorInFunctionCall(_, src, inner, p) => {
                if !src.is_empty() {
                    source = src.clone();
                }
                if !p.is_none() {
                    pos = *p;
                }
                e = inner;
                if !e.position().is_none() {
                    pos = e.position();
                }
            }
            EvalAltResult::ErrorInModule(_, inner, _) => e = inner,
            _ => break,
        }
    }
    let f = if source.is_empty() {
        file.to_path_buf()
    } else {
        PathBuf::from(source)
    };
    let text = if f == file {
        Some(text.to_string())
    } else {
        std::fs::read_to_string(&f).ok()
    };
    ErrorSite {
        error: e,
        file: f,
        text,
        pos,
    }
}

/// An error's message without Rhai's "(line …, position …)" suffix (the diagnostic says where).
pub fn bare_message(e: &EvalAltResult) -> String {
    let mut m = e.to_string();
    if let Some(i) = m.find(" (line ") {
        m.truncate(i);
    }
    m
}
