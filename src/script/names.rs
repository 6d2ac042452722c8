//! Part of stage 4 (decision), at load time: the names a script writes as string literals where
//! the engine expects a declared name. Rhai looks these up only when they run, so a misspelt
//! blackboard key reads as `()` and a renamed behavior makes `this.behavior == "ambush"` false
//! for ever. The compiled AST is walked (so strings in comments do not count) and each use is
//! returned with its line and column; the species loader and the test runner check them against
//! what the species declares. Keys and names that are not literals are checked when they run.

use super::memory::{MemType, MemorySpec};
use crate::diag::Diagnostic;
use crate::load::did_you_mean;
use rhai::{ASTNode, Dynamic, Expr, FnCallExpr, Stmt, AST};
use std::path::Path;

/// One literal name in a script, with where it is written.
#[derive(Debug, Clone, PartialEq)]
pub struct Named {
    /// The name.
    pub name: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub col: usize,
}

/// What a script does with the agent's blackboard, written with literal keys.
#[derive(Debug, Default)]
pub struct KeyUses {
    /// Every `this["k"]`, `this.has("k")` and `this.forget("k")`.
    pub keys: Vec<Named>,
    /// Every `this["k"] = value` whose value's type shows in the text: the key and that type.
    pub writes: Vec<(Named, MemType)>,
}

fn at(name: &str, pos: rhai::Position) -> Named {
    let (line, col) = super::position_of(pos);
    Named {
        name: name.to_string(),
        line,
        col,
    }
}

/// The type of a value whose type shows in the text: a literal, `vec3(..)`, or a property of
/// `this` of a known type.
fn evident_type(e: &Expr) -> Option<MemType> {
    match e {
        Expr::BoolConstant(..) => Some(MemType::Bool),
        Expr::IntegerConstant(..) => Some(MemType::Int),
        Expr::FloatConstant(..) => Some(MemType::Float),
        Expr::StringConstant(..) | Expr::InterpolatedString(..) => Some(MemType::Str),
        Expr::FnCall(f, _) if f.name == "vec3" && f.args.len() == 3 && !f.is_qualified() => {
            Some(MemType::Vec3)
        }
        Expr::Dot(x, ..) if matches!(x.lhs, Expr::ThisPtr(_)) => match &x.rhs {
            Expr::Property(p, _) => match p.2.as_str() {
                "pos" | "vel" | "fwd" => Some(MemType::Vec3),
                "time" | "dt" | "speed" | "max_speed" | "hunger" | "libido" | "fear"
                | "fatigue" | "state" | "time_in_behavior" | "age" | "mass" => Some(MemType::Float),
                "id" | "tick" | "stack_depth" | "kind" => Some(MemType::Int),
                "behavior" | "species" | "sex" | "heard" => Some(MemType::Str),
                _ => None,
            },
            _ => None,
        },
        _ => None,
    }
}

/// The literal key of `this["k"]`.
fn this_index(e: &Expr) -> Option<Named> {
    let Expr::Index(x, ..) = e else { return None };
    match (&x.lhs, &x.rhs) {
        (Expr::ThisPtr(_), Expr::StringConstant(k, pos)) => Some(at(k, *pos)),
        _ => None,
    }
}

/// The blackboard uses of `ast` with literal keys.
pub fn key_uses(ast: &AST) -> KeyUses {
    let mut uses = KeyUses::default();
    ast.walk(&mut |path| {
        match path.last() {
            Some(ASTNode::Expr(e @ Expr::Index(..))) => uses.keys.extend(this_index(e)),
            Some(ASTNode::Expr(Expr::Dot(x, ..))) if matches!(x.lhs, Expr::ThisPtr(_)) => {
                if let Expr::MethodCall(f, _) = &x.rhs {
                    if matches!(f.name.as_str(), "has" | "forget") && f.args.len() == 1 {
                        if let Expr::StringConstant(k, pos) = &f.args[0] {
                            uses.keys.push(at(k, *pos));
                        }
                    }
                }
            }
            Some(ASTNode::Stmt(Stmt::Assignment(x))) if !x.0.is_op_assignment() => {
                if let (Some(k), Some(t)) = (this_index(&x.1.lhs), evident_type(&x.1.rhs)) {
                    uses.writes.push((k, t));
                }
            }
            _ => {}
        }
        true
    });
    uses.keys.sort_by_key(|n| (n.line, n.col));
    uses.writes.sort_by_key(|w| (w.0.line, w.0.col));
    uses
}

/// The blackboard uses of `ast` (the script `file` with text `text`) that `spec` does not allow:
/// undeclared keys, and writes of a value of another type than the key's.
pub fn check_keys(ast: &AST, spec: &MemorySpec, file: &Path, text: &str) -> Vec<Diagnostic> {
    let uses = key_uses(ast);
    let mut out = Vec::new();
    for k in &uses.keys {
        if let Some(why) = spec.undeclared(&k.name) {
            out.push(Diagnostic::new(file, k.line, k.col, why, Some(text)));
        }
    }
    if !spec.keys.is_empty() && out.is_empty() {
        for (k, t) in &uses.writes {
            if let Some(want) = spec.type_of(&k.name).filter(|w| w != t) {
                out.push(Diagnostic::new(
                    file,
                    k.line,
                    k.col,
                    format!(
                        "memory key \"{}\" is declared {} (`{}`), but {} is written to it here",
                        k.name,
                        want.words(),
                        want.ron_name(),
                        t.words()
                    ),
                    Some(text),
                ));
            }
        }
    }
    if spec.keys.is_empty() && !out.is_empty() {
        // One suggestion for the whole block, with the types the writes show.
        let mut decl: Vec<(String, &str)> = Vec::new();
        for k in &uses.keys {
            if decl.iter().all(|(n, _)| *n != k.name) {
                let t = uses
                    .writes
                    .iter()
                    .find(|(w, _)| w.name == k.name)
                    .map_or("Float", |(_, t)| t.ron_name());
                decl.push((k.name.clone(), t));
            }
        }
        let block = decl
            .iter()
            .map(|(k, t)| format!("\"{k}\": {t}(None)"))
            .collect::<Vec<_>>()
            .join(", ");
        out.truncate(1);
        out[0].message = format!(
            "memory key \"{}\" is not declared: the species declares no memory; add `memory: {{ {block} }}` to the species file (each key with its type and a start value, or `None` for unset)",
            uses.keys[0].name
        );
    }
    out
}

/// The string literal compared with a `.behavior` property (`x.behavior == "eat"`), where the
/// object is `this` (`only_this`) or anything.
fn compared_behavior(f: &FnCallExpr, only_this: bool) -> Option<Named> {
    if !matches!(f.name.as_str(), "==" | "!=") || f.args.len() != 2 {
        return None;
    }
    let is_behavior = |e: &Expr| match e {
        Expr::Dot(x, ..) => {
            matches!(&x.rhs, Expr::Property(p, _) if p.2 == "behavior")
                && (!only_this || matches!(x.lhs, Expr::ThisPtr(_)))
        }
        _ => false,
    };
    match (&f.args[0], &f.args[1]) {
        (a, Expr::StringConstant(s, pos)) | (Expr::StringConstant(s, pos), a) if is_behavior(a) => {
            Some(at(s, *pos))
        }
        _ => None,
    }
}

/// The behavior names a species script compares `this.behavior` with.
pub fn behavior_uses(ast: &AST) -> Vec<Named> {
    let mut out = Vec::new();
    ast.walk(&mut |path| {
        // A comparison that ends a block is a statement.
        if let Some(ASTNode::Expr(Expr::FnCall(f, _)) | ASTNode::Stmt(Stmt::FnCall(f, _))) =
            path.last()
        {
            out.extend(compared_behavior(f, true));
        }
        true
    });
    out.sort_by_key(|n| (n.line, n.col));
    out
}

/// Behavior names and species names written as literals in a test file.
#[derive(Debug, Default)]
pub struct TestNames {
    /// Species named by `add_agent` / `add_squad`.
    pub species: Vec<Named>,
    /// Behavior names: compared with `.behavior`, given to `assert_behavior`, `assert_stack`,
    /// `assert_behavior_within`, `assert_transition`, `force_behavior`, or to `add_agent`'s
    /// `behavior` and `stack` options.
    pub behaviors: Vec<Named>,
}

/// The strings of an array literal (folded to a constant or not).
fn strings_of(e: &Expr) -> Vec<Named> {
    match e {
        Expr::StringConstant(s, pos) => vec![at(s, *pos)],
        Expr::Array(items, _) => items.iter().flat_map(strings_of).collect(),
        Expr::DynamicConstant(d, pos) => constant_strings(d)
            .into_iter()
            .map(|s| at(&s, *pos))
            .collect(),
        _ => Vec::new(),
    }
}

fn constant_strings(d: &Dynamic) -> Vec<String> {
    if let Some(s) = d.clone().try_cast::<rhai::ImmutableString>() {
        return vec![s.to_string()];
    }
    if let Some(a) = d.clone().try_cast::<rhai::Array>() {
        return a.iter().flat_map(constant_strings).collect();
    }
    Vec::new()
}

/// The `behavior` and `stack` entries of an options map (folded to a constant or not).
fn option_names(e: &Expr) -> Vec<Named> {
    match e {
        Expr::Map(m, _) => {
            m.0.iter()
                .filter(|(k, _)| k.name == "behavior" || k.name == "stack")
                .flat_map(|(_, v)| strings_of(v))
                .collect()
        }
        Expr::DynamicConstant(d, pos) => match d.clone().try_cast::<rhai::Map>() {
            Some(m) => ["behavior", "stack"]
                .iter()
                .filter_map(|k| m.get(*k))
                .flat_map(constant_strings)
                .map(|s| at(&s, *pos))
                .collect(),
            None => Vec::new(),
        },
        _ => Vec::new(),
    }
}

/// The literal species and behavior names of a test file.
pub fn test_names(ast: &AST) -> TestNames {
    let mut out = TestNames::default();
    ast.walk(&mut |path| {
        // A method call's arguments leave out its object; a function call's start with it.
        let (f, skip) = match path.last() {
            Some(ASTNode::Expr(Expr::FnCall(f, _))) | Some(ASTNode::Stmt(Stmt::FnCall(f, _))) => {
                (f, 1)
            }
            Some(ASTNode::Expr(Expr::MethodCall(f, _))) => (f, 0),
            _ => return true,
        };
        if skip == 1 {
            out.behaviors.extend(compared_behavior(f, false));
        }
        let arg = |i: usize| f.args.get(i + skip);
        match f.name.as_str() {
            "add_agent" | "add_squad" => {
                if let Some(Expr::StringConstant(s, pos)) = arg(0) {
                    out.species.push(at(s, *pos));
                }
                if f.name == "add_agent" {
                    if let Some(opts) = arg(2) {
                        out.behaviors.extend(option_names(opts));
                    }
                }
            }
            "assert_behavior" | "assert_stack" | "assert_behavior_within" => out
                .behaviors
                .extend(arg(0).map(strings_of).unwrap_or_default()),
            // `assert_transition(a, "from", "to", "cause")`: both ends are behaviors.
            "assert_transition" => {
                for i in [0, 1] {
                    out.behaviors
                        .extend(arg(i).map(strings_of).unwrap_or_default());
                }
            }
            "force_behavior" => out
                .behaviors
                .extend(arg(0).map(strings_of).unwrap_or_default()),
            _ => {}
        }
        true
    });
    // Functions are walked in no particular order: report in the order of the text.
    out.species.sort_by_key(|n| (n.line, n.col));
    out.behaviors.sort_by_key(|n| (n.line, n.col));
    out
}

/// Whether `name` is one of `names`, or the path of a behavior that holds some of them
/// (`eat` when `eat/chase` is one).
pub fn is_behavior(name: &str, names: &[&str]) -> bool {
    names.iter().any(|n| {
        *n == name
            || n.strip_prefix(name)
                .is_some_and(|rest| rest.starts_with('/'))
    })
}

/// The error for `name`, which is not a behavior of `owner` (its behaviors `names`).
pub fn unknown_behavior(name: &str, owner: &str, names: &[&str]) -> String {
    format!(
        "\"{name}\" is not a behavior of {owner}{}: it has {}",
        did_you_mean(name, names.iter().copied()),
        names
            .iter()
            .map(|n| format!("\"{n}\""))
            .collect::<Vec<_>>()
            .join(", ")
    )
}
