//! Part of stage 4 (decision), at load time: every function a script calls must exist.
//!
//! Rhai resolves calls when they run, so a call to a function that exists nowhere (a typo, a
//! helper that was renamed, a module function that is private) would only fail on the tick that
//! reaches it. At load the compiled AST is walked and each call is looked up among the script's
//! own functions, the functions of the modules it imports and the functions the engine registers
//! (Rhai's packages and the shoal API); what is not found is reported with its file, line and
//! column. Functions that would make a run depend on the clock ([`DENIED`]) are not registered,
//! and a call to one of them gets a message that says why.

use crate::diag::Diagnostic;
use rhai::{Expr, Module, Shared, Stmt, AST};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Functions that read the clock or block the thread (Rhai's `BasicTimePackage` and `sleep` of
/// its core package): the engine does not register them, so results depend only on the inputs.
pub const DENIED: [&str; 3] = ["timestamp", "elapsed", "sleep"];

/// Rhai's keyword functions, handled by the evaluator rather than registered.
const KEYWORDS: [&str; 9] = [
    "print",
    "debug",
    "type_of",
    "Fn",
    "call",
    "curry",
    "is_shared",
    "is_def_var",
    "is_def_fn",
];

/// What a script can call besides its own functions and the engine's.
#[derive(Default)]
pub(crate) struct Known {
    /// The modules it imports, by alias: their public functions and parameter counts.
    pub modules: BTreeMap<String, Vec<(String, usize)>>,
    /// Every module reachable through its imports, by alias, with its file.
    pub nested: Vec<(String, PathBuf, Shared<Module>)>,
}

/// Names and parameter counts of every function the engine registers (the same for every
/// script: computed once).
pub fn registered() -> &'static BTreeSet<(String, usize)> {
    static REGISTERED: OnceLock<BTreeSet<(String, usize)>> = OnceLock::new();
    REGISTERED.get_or_init(|| {
        super::new_engine(&super::SandboxLimits::default())
            .collect_fn_metadata(
                None,
                |f| Some((f.metadata.name.to_string(), f.metadata.num_params)),
                true,
            )
            .into_iter()
            .collect()
    })
}

fn plural(n: usize, one: &str) -> String {
    if n == 1 {
        format!("1 {one}")
    } else {
        format!("{n} {one}s")
    }
}

/// Calls in `ast` (the script `file` with text `text`) to functions that exist nowhere.
pub(crate) fn check(ast: &AST, known: &Known, file: &Path, text: &str) -> Vec<Diagnostic> {
    let registered = registered();
    let own: BTreeSet<(String, usize)> = ast
        .iter_functions()
        .map(|f| (f.name.to_string(), f.params.len()))
        .collect();
    // Names bound to values (a variable may hold a function pointer and be called).
    let mut locals: BTreeSet<String> = ast
        .iter_functions()
        .flat_map(|f| f.params.iter().map(|p| p.to_string()).collect::<Vec<_>>())
        .collect();
    ast.walk(&mut |path| {
        match path.last() {
            Some(rhai::ASTNode::Expr(Expr::Variable(v, ..))) => {
                locals.insert(v.1.to_string());
            }
            Some(rhai::ASTNode::Stmt(Stmt::Var(v, ..))) => {
                locals.insert(v.0.name.to_string());
            }
            _ => {}
        }
        true
    });
    let named = |name: &str| {
        own.iter().any(|(n, _)| n == name) || registered.iter().any(|(n, _)| n == name)
    };
    let mut out = Vec::new();
    let mut report = |pos: rhai::Position, msg: String| {
        let (line, col) = super::position_of(pos);
        out.push(Diagnostic::new(file, line, col, msg, Some(text)));
    };
    ast.walk(&mut |path| {
        let call = match path.last() {
            Some(rhai::ASTNode::Expr(Expr::FnCall(x, pos)))
            | Some(rhai::ASTNode::Stmt(Stmt::FnCall(x, pos))) => Some((x, pos)),
            _ => None,
        };
        if let Some((x, pos)) = call {
            if !x.is_operator_call() {
                let name = x.name.as_str();
                let n = x.args.len();
                if x.is_qualified() {
                    let root = x.namespace.path[0].as_str();
                    let Some(fns) = known.modules.get(root) else {
                        if root != "global" && !known.nested.iter().any(|m| m.0 == root) {
                            report(
                                *pos,
                                format!("`{root}::{name}`: no module is imported as `{root}`"),
                            );
                        }
                        return true;
                    };
                    if x.namespace.path.len() == 1
                        && !fns.iter().any(|(f, p)| f == name && *p == n)
                    {
                        let hint = match fns.iter().find(|(f, _)| f == name) {
                            Some((_, p)) => format!(" (it takes {})", plural(*p, "parameter")),
                            None => " (or it is private)".to_string(),
                        };
                        report(
                            *pos,
                            format!(
                                "call to undefined function `{root}::{name}` with {}: module `{root}` defines no such function{hint}",
                                plural(n, "argument")
                            ),
                        );
                    }
                    return true;
                }
                if KEYWORDS.contains(&name)
                    || locals.contains(name)
                    || own.contains(&(name.to_string(), n))
                    || registered.contains(&(name.to_string(), n))
                {
                    return true;
                }
                if DENIED.contains(&name) {
                    report(
                        *pos,
                        format!(
                            "`{name}()` is not available to scripts: a run must not depend on the clock (use `this.time` or `this.tick`)"
                        ),
                    );
                    return true;
                }
                let hint = if let Some((_, p)) = own.iter().find(|(f, _)| f == name) {
                    format!(" (the script's `{name}` takes {})", plural(*p, "parameter"))
                } else if registered.contains(&(name.to_string(), n + 1)) {
                    format!(" (did you mean the method `this.{name}(...)`?)")
                } else if named(name) {
                    " (a function of that name exists with another number of parameters)".into()
                } else {
                    String::new()
                };
                report(
                    *pos,
                    format!(
                        "call to undefined function `{name}` with {}: it is not defined in this script, its imports or the engine{hint}",
                        plural(n, "argument")
                    ),
                );
            }
            return true;
        }
        let Some(rhai::ASTNode::Expr(Expr::MethodCall(x, pos))) = path.last() else {
            return true;
        };
        let name = x.name.as_str();
        if KEYWORDS.contains(&name) || named(name) || locals.contains(name) {
            return true;
        }
        if DENIED.contains(&name) {
            report(
                *pos,
                format!("`{name}` is not available to scripts: a run must not depend on the clock"),
            );
            return true;
        }
        report(
            *pos,
            format!("call to undefined method `{name}`: no function of that name exists in this script, its imports or the engine"),
        );
        true
    });
    // Functions are walked in the order of Rhai's table, which differs between processes:
    // report in the order of the text.
    out.sort_by_key(|d| (d.line, d.col));
    out
}
