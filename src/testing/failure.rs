//! How a script test ends badly: assertion failures, skips and errors raised by the test API,
//! and any Rhai error, located at the innermost file:line of the test.

use crate::diag::Diagnostic;
use rhai::{Dynamic, EvalAltResult, Position};
use std::path::Path;

/// What kind of stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// An assertion did not hold.
    Fail,
    /// The test asked to be skipped.
    Skip,
    /// The test itself is wrong (bad name, bad argument, a limit reached...).
    Error,
}

/// The payload the test API throws.
#[derive(Debug, Clone)]
pub struct Stop {
    /// Kind.
    pub kind: Kind,
    /// What was expected and what happened.
    pub message: String,
    /// The state and last decisions of the agents concerned.
    pub context: String,
}

/// A Rhai error carrying a [`Stop`]; Rhai fills in the position of the call.
pub fn raise(kind: Kind, message: impl Into<String>, context: String) -> Box<EvalAltResult> {
    Box::new(EvalAltResult::ErrorRuntime(
        Dynamic::from(Stop {
            kind,
            message: message.into(),
            context,
        }),
        Position::NONE,
    ))
}

/// A test's error that is not an assertion: a wrong name, a bad argument, a limit.
pub fn error(message: impl Into<String>) -> Box<EvalAltResult> {
    raise(Kind::Error, message, String::new())
}

/// A stop, located.
#[derive(Debug, Clone)]
pub struct Located {
    /// Kind.
    pub kind: Kind,
    /// `file:line:col: message` with the offending line.
    pub diagnostic: Diagnostic,
    /// The state and last decisions of the agents concerned.
    pub context: String,
}

/// Limits named in messages.
#[derive(Debug, Clone, Copy)]
pub struct LimitsInfo {
    /// Operations per test.
    pub max_operations: u64,
    /// Nested calls.
    pub max_call_levels: usize,
}

/// Turns the error a test function returned into a located stop: the innermost frame names the
/// file and the line (an assertion inside a helper function points into the helper).
pub fn locate(err: &EvalAltResult, file: &Path, text: &str, limits: LimitsInfo) -> Located {
    let site = crate::script::error_site(err, file, text);
    let (kind, message, context) = match site.error {
        EvalAltResult::ErrorRuntime(d, _) if d.is::<Stop>() => {
            let s = d.clone().cast::<Stop>();
            (s.kind, s.message, s.context)
        }
        EvalAltResult::ErrorTooManyOperations(_) => (
            Kind::Error,
            format!(
                "test exceeded its limit of {} operations (an endless loop?)",
                limits.max_operations
            ),
            String::new(),
        ),
        EvalAltResult::ErrorStackOverflow(_) => (
            Kind::Error,
            format!(
                "test exceeded its limit of {} nested calls (endless recursion?)",
                limits.max_call_levels
            ),
            String::new(),
        ),
        EvalAltResult::ErrorRuntime(d, _) => (Kind::Error, format!("thrown: {d}"), String::new()),
        other => (
            Kind::Error,
            crate::script::bare_message(other),
            String::new(),
        ),
    };
    Located {
        kind,
        diagnostic: Diagnostic::new(
            site.file,
            site.pos.line().unwrap_or(0),
            site.pos.position().unwrap_or(0),
            message,
            site.text.as_deref(),
        ),
        context,
    }
}
