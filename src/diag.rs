//! Located diagnostics for everything a user writes: species, scripts, scenarios, terrain.
//!
//! Not a tick stage: every loader turns its failures into a [`Diagnostic`] that names the file,
//! the line and column (1-based) and what was expected, and shows the offending line.

use std::fmt;
use std::path::{Path, PathBuf};

/// One located problem in a user's file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// The file the problem is in.
    pub file: PathBuf,
    /// 1-based line; 0 when the problem has no position (e.g. a missing file).
    pub line: usize,
    /// 1-based column; 0 when unknown.
    pub col: usize,
    /// What went wrong and what was expected.
    pub message: String,
    /// The text of the offending line, when the file could be read.
    pub source_line: Option<String>,
}

impl Diagnostic {
    /// A diagnostic at `line:col` of `file`; the offending line is taken from `text` when given.
    pub fn new(
        file: impl AsRef<Path>,
        line: usize,
        col: usize,
        message: impl Into<String>,
        text: Option<&str>,
    ) -> Self {
        let source_line = text.and_then(|t| {
            if line == 0 {
                None
            } else {
                t.lines().nth(line - 1).map(|l| l.to_string())
            }
        });
        Diagnostic {
            file: file.as_ref().to_path_buf(),
            line,
            col,
            message: message.into(),
            source_line,
        }
    }

    /// A diagnostic about a whole file (no position), e.g. one that cannot be read.
    pub fn file(file: impl AsRef<Path>, message: impl Into<String>) -> Self {
        Self::new(file, 0, 0, message, None)
    }

    /// `file:line:col: message` on one line, without the source excerpt.
    pub fn headline(&self) -> String {
        if self.line == 0 {
            format!("{}: {}", self.file.display(), self.message)
        } else {
            format!(
                "{}:{}:{}: {}",
                self.file.display(),
                self.line,
                self.col,
                self.message
            )
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.headline())?;
        if let Some(src) = &self.source_line {
            let gutter = format!("{}", self.line);
            write!(f, "\n{} | {}", gutter, src)?;
            if self.col > 0 {
                let pad: String = src
                    .chars()
                    .take(self.col - 1)
                    .map(|c| if c == '\t' { '\t' } else { ' ' })
                    .collect();
                write!(f, "\n{} | {}^", " ".repeat(gutter.len()), pad)?;
            }
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostic {}

/// Several diagnostics from one load; loading reports all it can find, not just the first.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}

impl From<Diagnostic> for Diagnostics {
    fn from(d: Diagnostic) -> Self {
        Diagnostics(vec![d])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_shows_location_line_and_caret() {
        let d = Diagnostic::new("a.ron", 2, 5, "expected `)`", Some("x\nabc def\n"));
        assert_eq!(
            d.to_string(),
            "a.ron:2:5: expected `)`\n2 | abc def\n  |     ^"
        );
    }

    #[test]
    fn whole_file_diagnostic_has_no_position() {
        let d = Diagnostic::file("missing.ron", "cannot read file: not found");
        assert_eq!(d.to_string(), "missing.ron: cannot read file: not found");
    }
}
