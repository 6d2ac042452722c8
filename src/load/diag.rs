//! Located diagnostics for everything a user writes: species, scripts, scenarios, terrain.
//!
//! Not a tick stage: every loader turns its failures into a [`Diagnostic`] that names the file,
//! the line and column (1-based) and what was expected, and shows the offending line.
//!
//! Every user file is read through [`read_text`] or [`read_bytes`], so that a named pipe or a
//! device in place of a file, and text that is not UTF-8, are refused the same way everywhere.

use std::fmt;
use std::path::{Path, PathBuf};

/// The most characters of a source line a diagnostic shows: a file of one 100 MB line must not
/// send 100 MB to the terminal with each error.
pub const MAX_ECHO: usize = 200;

/// The most characters of a message a diagnostic shows (messages may quote the user's text).
pub const MAX_MESSAGE: usize = 1000;

/// The most diagnostics one load reports before it stops looking.
pub const MAX_DIAGNOSTICS: usize = 20;

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
    /// The text of the offending line, when the file could be read (an excerpt around the
    /// column when the line is longer than [`MAX_ECHO`]).
    pub source_line: Option<String>,
    /// The caret's column in `source_line` when that is an excerpt, not the whole line.
    excerpt_col: Option<usize>,
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
        let full = text.and_then(|t| {
            if line == 0 {
                None
            } else {
                t.lines().nth(line - 1)
            }
        });
        // Only an excerpt is kept: a diagnostic must not hold a copy of a huge line.
        let (source_line, excerpt_col) = match full {
            Some(l) if l.len() > MAX_ECHO => {
                let (w, c) = window(l, col);
                (Some(w), Some(c))
            }
            Some(l) => (Some(l.to_string()), None),
            None => (None, None),
        };
        Diagnostic {
            file: file.as_ref().to_path_buf(),
            line,
            col,
            message: message.into(),
            source_line,
            excerpt_col,
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

/// At most `max` characters of `s`, the middle replaced by `…` when it is longer.
pub fn clip(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    let head = max / 2;
    let tail = max.saturating_sub(head + 1);
    let mut out: String = s.chars().take(head).collect();
    out.push('…');
    out.extend(s.chars().skip(n - tail));
    out
}

/// At most [`MAX_ECHO`] characters of `line` around the 1-based column `col` (0: the start),
/// with `…` where it was cut, and the column of `col` in that excerpt.
pub fn window(line: &str, col: usize) -> (String, usize) {
    // Characters past the window's end change nothing: counting them made each diagnostic on a
    // 500 KB line cost a scan of it.
    let n = line.chars().take(col.saturating_add(MAX_ECHO + 1)).count();
    if n <= MAX_ECHO {
        return (line.to_string(), col);
    }
    let at = col.saturating_sub(1).min(n);
    let start = at
        .saturating_sub(MAX_ECHO / 2)
        .min(n.saturating_sub(MAX_ECHO));
    let end = (start + MAX_ECHO).min(n);
    let mut out = String::new();
    if start > 0 {
        out.push('…');
    }
    out.extend(line.chars().skip(start).take(end - start));
    if end < n {
        out.push('…');
    }
    let caret = if col == 0 {
        0
    } else {
        at - start + 1 + usize::from(start > 0)
    };
    (out, caret)
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.message.chars().count() > MAX_MESSAGE {
            let short = Diagnostic {
                message: clip(&self.message, MAX_MESSAGE),
                source_line: None,
                ..self.clone()
            };
            write!(f, "{}", short.headline())?;
        } else {
            write!(f, "{}", self.headline())?;
        }
        if let Some(full) = &self.source_line {
            let (src, col) = match self.excerpt_col {
                Some(c) => (full.clone(), c),
                None => window(full, self.col),
            };
            let gutter = format!("{}", self.line);
            write!(f, "\n{} | {}", gutter, src)?;
            if col > 0 {
                let pad: String = src
                    .chars()
                    .take(col - 1)
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

/// Refuses anything but a regular file (a named pipe, a device or a folder would block or fail
/// the read), naming `path`; `what` says what the file was meant to be ("species file").
pub fn regular_file(path: &Path, what: &str) -> Result<(), Diagnostic> {
    let meta = std::fs::metadata(path)
        .map_err(|e| Diagnostic::file(path, format!("cannot read {what}: {e}")))?;
    if meta.is_file() {
        return Ok(());
    }
    let kind = if meta.is_dir() {
        "a folder"
    } else {
        special_kind(&meta)
    };
    Err(Diagnostic::file(
        path,
        format!("cannot read {what}: it is {kind}, not a regular file"),
    ))
}

#[cfg(unix)]
fn special_kind(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_fifo() {
        "a named pipe"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else {
        "not a plain file"
    }
}

#[cfg(not(unix))]
fn special_kind(_: &std::fs::Metadata) -> &'static str {
    "a special file"
}

/// Why `path` cannot be read as a file (`not found`, or what it is instead of a regular file),
/// or `None` when it is a regular file; for messages located where the path is written.
pub fn file_problem(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => None,
        Ok(m) if m.is_dir() => Some("is a folder, not a regular file".into()),
        Ok(m) => Some(format!("is {}, not a regular file", special_kind(&m))),
        Err(_) => Some("not found".into()),
    }
}

/// The bytes of the regular file `path` (see [`regular_file`]).
pub fn read_bytes(path: &Path, what: &str) -> Result<Vec<u8>, Diagnostic> {
    regular_file(path, what)?;
    std::fs::read(path).map_err(|e| Diagnostic::file(path, format!("cannot read {what}: {e}")))
}

/// The text of the regular file `path`; text that is not UTF-8 is refused at the line and
/// column of its first bad byte.
pub fn read_text(path: &Path, what: &str) -> Result<String, Diagnostic> {
    // An editor's unsaved buffer, when the language server checks with one.
    if let Some(text) = super::overlay::read(path) {
        return Ok(text);
    }
    let bytes = read_bytes(path, what)?;
    String::from_utf8(bytes).map_err(|e| utf8_diag(path, what, e.as_bytes(), e.utf8_error()))
}

/// Locates the first invalid byte of `bytes`.
pub fn utf8_diag(path: &Path, what: &str, bytes: &[u8], e: std::str::Utf8Error) -> Diagnostic {
    let good = &bytes[..e.valid_up_to()];
    // Valid up to here, so the prefix decodes.
    let good = std::str::from_utf8(good).unwrap_or_default();
    let line_start = good.rfind('\n').map_or(0, |i| i + 1);
    let line = good.matches('\n').count() + 1;
    let col = good[line_start..].chars().count() + 1;
    let rest = &bytes[line_start..];
    let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
    let shown = String::from_utf8_lossy(&rest[..end]);
    let mut d = Diagnostic::new(
        path,
        line,
        col,
        format!(
            "{what} is not valid UTF-8: byte 0x{:02x} here; save the file as UTF-8",
            bytes[e.valid_up_to()]
        ),
        None,
    );
    d.source_line = Some(shown.into_owned());
    d
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

    #[test]
    fn long_lines_are_cut_around_the_column() {
        let line = format!("{}X{}", "a".repeat(5000), "b".repeat(5000));
        let d = Diagnostic::new("big.ron", 1, 5001, "bad", Some(&line));
        let shown = d.to_string();
        assert!(
            shown.len() < 3 * MAX_ECHO + 100,
            "{} bytes shown",
            shown.len()
        );
        let lines: Vec<&str> = shown.lines().collect();
        let caret = lines[2].find('^').unwrap();
        assert_eq!(lines[1].chars().nth(caret).unwrap(), 'X');
    }

    #[test]
    fn long_messages_are_cut() {
        let d = Diagnostic::file("a.ron", "x".repeat(1_000_000));
        assert!(d.to_string().chars().count() < MAX_MESSAGE + 20);
    }

    #[test]
    fn bad_utf8_is_located_at_its_first_byte() {
        let dir = std::env::temp_dir().join(format!("shoal-utf8-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("bad.ron");
        std::fs::write(&p, b"Species(\n  name: \"a\xffb\",\n)").unwrap();
        let d = read_text(&p, "species file").unwrap_err();
        assert_eq!((d.line, d.col), (2, 11), "{d}");
        assert!(d.message.contains("UTF-8"), "{d}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[cfg(unix)]
    #[test]
    fn folders_are_refused_by_name() {
        let d = read_text(Path::new("/"), "scenario").unwrap_err();
        assert!(d.message.contains("a folder, not a regular file"), "{d}");
    }
}
