//! Reading RON: the options every file of the engine is read with, and RON's errors turned into
//! located diagnostics that say, in designers' words, what was expected. Not a tick stage.

use super::diag::Diagnostic;
use super::hints::did_you_mean;
use std::path::Path;

/// RON options used for every file the engine reads: newtype variants may be written with their
/// fields directly (`AvoidStatic(m0: 2.0)` or `AvoidStatic()`), and an optional value may be
/// written bare (`hunger: Fixed(0.9)`) as well as `Some(Fixed(0.9))`.
pub fn ron_options() -> ron::Options {
    use ron::extensions::Extensions;
    ron::Options::default()
        .with_default_extension(Extensions::UNWRAP_VARIANT_NEWTYPES)
        .with_default_extension(Extensions::IMPLICIT_SOME)
}

/// What designers call the types of the file format, for messages.
fn designer_name(type_name: &str) -> &str {
    match type_name {
        "Recipe" => "steering recipe",
        "Cond" => "condition",
        "Value" => "value",
        "Category" => "category",
        "DriveKind" => "drive",
        "AttrKind" => "attribute",
        "MessageKind" => "message kind",
        "Action" => "action",
        "Contact" => "contact",
        "Draw" => "draw",
        "Target" => "target",
        "Sector" => "sector",
        "Level" => "level",
        other => other,
    }
}

/// Turns a RON error into a located diagnostic.
pub fn ron_diag(file: &Path, text: &str, e: &ron::error::SpannedError) -> Diagnostic {
    let (mut line, mut col) = (e.span.start.line, e.span.start.col);
    let list = |v: &[&str]| {
        v.iter()
            .map(|x| format!("`{x}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let msg = match &e.code {
        ron::Error::NoSuchEnumVariant {
            expected,
            found,
            outer,
        } => {
            let what = outer.as_deref().map_or("value", designer_name);
            format!(
                "unknown {what} `{found}`{}: expected one of {}",
                did_you_mean(found, expected.iter().copied()),
                list(expected)
            )
        }
        ron::Error::NoSuchStructField {
            expected,
            found,
            outer,
        } => {
            let what = outer.as_deref().unwrap_or("struct");
            format!(
                "unknown field `{found}` in {what}{}: expected one of {}",
                did_you_mean(found, expected.iter().copied()),
                list(expected)
            )
        }
        ron::Error::ExpectedIdentifier => "expected a field name (`name: value`); a struct inside `Variant(…)` or `Some(…)` \
             is written without its own parentheses: `Spawn(species: \"shark\", …)`, `Some(min: …, max: …)`"
            .to_string(),
        ron::Error::ExpectedOption => "expected an optional value: `Some(…)` or `None`".to_string(),
        ron::Error::MissingStructField { field, outer } => match outer {
            Some(o) => format!("`{o}` is missing its required field `{field}`"),
            None => format!("missing required field `{field}`"),
        },
        ron::Error::ExpectedComma => {
            // RON notices a missing comma at the next token; point just after the previous one,
            // where the comma belongs.
            if let Some((l, c)) = end_of_previous_token(text, line, col) {
                (line, col) = (l, c);
            }
            "expected a `,` here, between two fields or list entries".to_string()
        }
        other => other.to_string(),
    };
    Diagnostic::new(file, line, col, msg, Some(text))
}

/// Line and column just after the last non-blank, non-comment character before `line:col`.
fn end_of_previous_token(text: &str, line: usize, col: usize) -> Option<(usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut l = line.checked_sub(1)?;
    let mut upto = col.saturating_sub(1);
    loop {
        let full = lines.get(l)?;
        let chars: Vec<char> = full.chars().collect();
        let mut head: String = chars[..upto.min(chars.len())].iter().collect();
        if let Some(i) = head.find("//") {
            head.truncate(i);
        }
        let trimmed = head.trim_end();
        if !trimmed.is_empty() {
            return Some((l + 1, trimmed.chars().count() + 1));
        }
        l = l.checked_sub(1)?;
        upto = usize::MAX;
    }
}

/// The first word of a RON text, comments and blank lines skipped (`Scenario`, `Species`, …).
pub fn first_word(text: &str) -> &str {
    let mut rest = text;
    loop {
        rest = rest.trim_start();
        if let Some(after) = rest.strip_prefix("//") {
            rest = after.split_once('\n').map_or("", |x| x.1);
        } else if let Some(after) = rest.strip_prefix("/*") {
            rest = after.split_once("*/").map_or("", |x| x.1);
        } else {
            break;
        }
    }
    let end = rest
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    &rest[..end]
}
