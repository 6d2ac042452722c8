//! Rename of a behavior or a script function across species, scripts and test files: the
//! references [`super::navigate`] finds, rewritten in one workspace edit. The new name is
//! checked first (a behavior name holds no `/` or quote; a function name is an identifier).

use super::index::{Index, Span};
use super::navigate::{references, target_at, Target};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Why a rename is refused.
pub type Refusal = String;

/// The name under byte `at` of `file` that can be renamed, and its span.
pub fn prepare(
    index: &Index,
    file: &Path,
    text: &str,
    at: usize,
) -> Result<(Target, Span), Refusal> {
    match target_at(index, file, text, at) {
        Some((t @ (Target::Behavior { .. } | Target::Function { .. }), span)) => Ok((t, span)),
        Some(_) => Err("only behaviors and script functions can be renamed".into()),
        None => Err("no behavior or script function here".into()),
    }
}

/// Rhai's reserved words, which no function may be named.
const RESERVED: &[&str] = &[
    "fn",
    "let",
    "const",
    "if",
    "else",
    "while",
    "loop",
    "for",
    "in",
    "do",
    "until",
    "break",
    "continue",
    "return",
    "throw",
    "try",
    "catch",
    "switch",
    "import",
    "export",
    "as",
    "private",
    "true",
    "false",
    "this",
    "global",
    "Fn",
    "call",
    "curry",
    "type_of",
    "print",
    "debug",
    "eval",
    // Reserved by Rhai for later use: a function so named does not parse.
    "var",
    "static",
    "is",
    "goto",
    "exit",
    "match",
    "case",
    "public",
    "protected",
    "new",
    "use",
    "with",
    "module",
    "package",
    "super",
    "thread",
    "spawn",
    "go",
    "await",
    "async",
    "sync",
    "yield",
    "default",
    "void",
    "null",
    "nil",
    "shared",
];

/// Whether `new` may name what `target` is.
pub fn check_name(target: &Target, new: &str) -> Result<(), Refusal> {
    match target {
        Target::Behavior { .. } => {
            if new.is_empty() || new.contains(['/', '"', '\\']) || new.chars().any(char::is_control)
            {
                return Err(format!(
                    "\"{new}\" cannot name a behavior: use a non-empty name without `/`, quotes or backslashes"
                ));
            }
        }
        Target::Function { .. } => {
            let ident = new
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && new.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !ident || RESERVED.contains(&new) {
                return Err(format!(
                    "\"{new}\" cannot name a script function: use letters, digits and `_`, not starting with a digit, and no reserved word"
                ));
            }
        }
        Target::File(_) => return Err("files are not renamed here".into()),
    }
    Ok(())
}

/// The edits renaming the name at byte `at` of `file` to `new`: spans by file.
pub fn rename(
    index: &Index,
    file: &Path,
    text: &str,
    at: usize,
    new: &str,
) -> Result<BTreeMap<PathBuf, Vec<Span>>, Refusal> {
    let (target, _) = prepare(index, file, text, at)?;
    check_name(&target, new)?;
    // A name already taken would merge two behaviors or two functions into one.
    let taken = match &target {
        Target::Behavior { species, path } => {
            let sibling = match path.rsplit_once('/') {
                Some((parent, _)) => format!("{parent}/{new}"),
                None => new.to_string(),
            };
            let other = Target::Behavior {
                species: species.clone(),
                path: sibling,
            };
            super::navigate::definition(index, &other).is_some()
        }
        Target::Function { script, .. } => {
            index.get(script).and_then(|f| f.function(new)).is_some()
        }
        Target::File(_) => false,
    };
    if taken {
        return Err(format!(
            "\"{new}\" is already defined there: pick another name"
        ));
    }
    let mut out: BTreeMap<PathBuf, Vec<Span>> = BTreeMap::new();
    for (f, span) in references(index, &target, true) {
        out.entry(f).or_default().push(span);
    }
    Ok(out)
}
