//! Documents and positions: file URIs to paths and back, LSP positions (lines and UTF-16 code
//! units) to byte offsets and back, and the texts the server reads: an open editor buffer, else
//! the file on disk. Every conversion clamps: a position past the end is the end.

use crate::load::overlay::{normalize, Texts};
use lsp_types::{Position, Range, Uri};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::Arc;

/// The largest file the server reads from disk for its index (an open buffer of any size is
/// taken as the editor sends it).
pub const MAX_DISK_TEXT: u64 = 8 << 20;

/// The path of a `file:` URI, normalized; `None` for any other scheme or a malformed one.
pub fn uri_to_path(uri: &Uri) -> Option<PathBuf> {
    let s = uri.as_str();
    let rest = s.strip_prefix("file://")?;
    // `file://host/path`: only an empty host or `localhost` is this machine.
    let path = if rest.starts_with('/') {
        rest
    } else {
        rest.strip_prefix("localhost")?
    };
    let path = path.split(['?', '#']).next().unwrap_or("");
    let bytes = percent_decode(path)?;
    Some(normalize(&bytes_to_path(bytes)))
}

#[cfg(unix)]
fn bytes_to_path(b: Vec<u8>) -> PathBuf {
    use std::os::unix::ffi::OsStringExt;
    PathBuf::from(std::ffi::OsString::from_vec(b))
}

#[cfg(not(unix))]
fn bytes_to_path(b: Vec<u8>) -> PathBuf {
    PathBuf::from(String::from_utf8_lossy(&b).into_owned())
}

fn percent_decode(s: &str) -> Option<Vec<u8>> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = s.get(i + 1..i + 3)?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    Some(out)
}

/// The `file:` URI of `path` (absolute), bytes outside the unreserved set percent-encoded.
pub fn path_to_uri(path: &Path) -> Option<Uri> {
    #[cfg(unix)]
    let bytes = {
        use std::os::unix::ffi::OsStrExt;
        path.as_os_str().as_bytes().to_vec()
    };
    #[cfg(not(unix))]
    let bytes = path.to_string_lossy().replace('\\', "/").into_bytes();
    let mut s = String::from("file://");
    if !bytes.starts_with(b"/") {
        s.push('/');
    }
    for b in bytes {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            s.push(b as char);
        } else {
            s.push_str(&format!("%{b:02X}"));
        }
    }
    Uri::from_str(&s).ok()
}

/// The byte offset of `pos` in `text`: its line's start plus its UTF-16 column, clamped to the
/// line's end (a line past the last is the end of the text).
pub fn offset(text: &str, pos: Position) -> usize {
    let mut start = 0;
    for _ in 0..pos.line {
        match text[start..].find('\n') {
            Some(i) => start += i + 1,
            None => return text.len(),
        }
    }
    let line = &text[start..];
    let line = &line[..line.find('\n').unwrap_or(line.len())];
    let mut units = 0u32;
    for (b, c) in line.char_indices() {
        if units >= pos.character {
            return start + b;
        }
        units += c.len_utf16() as u32;
    }
    start + line.len()
}

/// The LSP position of byte `at` of `text` (clamped to the text, and back to a character
/// boundary).
pub fn position(text: &str, at: usize) -> Position {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() as u32;
    let ls = before.rfind('\n').map_or(0, |i| i + 1);
    let character = before[ls..].chars().map(|c| c.len_utf16() as u32).sum();
    Position { line, character }
}

/// The LSP range of bytes `span` of `text`.
pub fn range(text: &str, span: (usize, usize)) -> Range {
    Range {
        start: position(text, span.0),
        end: position(text, span.1),
    }
}

/// Where each line of a text starts and whether it is ASCII: many offsets of one text (an
/// outline, a rename's edits) convert in O(log n) each instead of a scan from the start, which
/// made a hostile file of 50,000 functions on one line take 48 s.
pub struct LineIndex<'a> {
    text: &'a str,
    starts: Vec<usize>,
    ascii: Vec<bool>,
}

impl<'a> LineIndex<'a> {
    /// The index of `text`.
    pub fn new(text: &'a str) -> Self {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        let ascii = starts
            .iter()
            .enumerate()
            .map(|(k, &s)| {
                let e = starts.get(k + 1).copied().unwrap_or(text.len());
                text.as_bytes()[s..e].is_ascii()
            })
            .collect();
        LineIndex {
            text,
            starts,
            ascii,
        }
    }

    /// What [`position`] gives for byte `at`.
    pub fn position(&self, at: usize) -> Position {
        let mut at = at.min(self.text.len());
        while !self.text.is_char_boundary(at) {
            at -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= at) - 1;
        let ls = self.starts[line];
        let character = if self.ascii[line] {
            (at - ls) as u32
        } else {
            self.text[ls..at]
                .chars()
                .map(|c| c.len_utf16() as u32)
                .sum()
        };
        Position {
            line: line as u32,
            character,
        }
    }

    /// What [`range`] gives for bytes `span`.
    pub fn range(&self, span: (usize, usize)) -> Range {
        Range {
            start: self.position(span.0),
            end: self.position(span.1),
        }
    }
}

/// The range of a diagnostic at 1-based `line`:`col` (characters) of `text`: from there to the
/// end of the word, or the whole first line when the line is 0.
pub fn diag_range(text: &str, line: usize, col: usize) -> Range {
    if line == 0 {
        let end = text.find('\n').unwrap_or(text.len());
        return range(text, (0, end));
    }
    let mut start = 0;
    for _ in 1..line {
        match text[start..].find('\n') {
            Some(i) => start += i + 1,
            None => {
                start = text.len();
                break;
            }
        }
    }
    let row = &text[start..];
    let row = &row[..row.find('\n').unwrap_or(row.len())];
    let at = row
        .char_indices()
        .nth(col.saturating_sub(1))
        .map_or(row.len(), |(b, _)| b);
    let word = row[at..]
        .char_indices()
        .find(|(_, c)| !(c.is_alphanumeric() || *c == '_'))
        .map_or(row.len() - at, |(b, _)| b);
    // At least one character, so the editor shows a mark.
    let end = if word == 0 {
        row[at..].chars().next().map_or(at, |c| at + c.len_utf8())
    } else {
        at + word
    };
    range(text, (start + at, start + end))
}

/// The open documents: editor buffers by normalized path.
#[derive(Default)]
pub struct Documents {
    /// The buffers, shared with the analysis as its overlay.
    pub open: Texts,
}

impl Documents {
    /// The text of `path`: its buffer when open, else the file (when small enough and UTF-8).
    pub fn text(&self, path: &Path) -> Option<Arc<str>> {
        if let Some(t) = self.open.get(path) {
            return Some(t.clone());
        }
        let meta = std::fs::metadata(path).ok()?;
        if !meta.is_file() || meta.len() > MAX_DISK_TEXT {
            return None;
        }
        std::fs::read_to_string(path).ok().map(Arc::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_round_trip_in_utf16() {
        let t = "aé😀b\nxy";
        let p = Position {
            line: 0,
            character: 4,
        };
        // é is 1 unit, 😀 is 2.
        assert_eq!(&t[offset(t, p)..offset(t, p) + 1], "b");
        assert_eq!(position(t, offset(t, p)), p);
        // Past the end: clamped.
        assert_eq!(offset(t, Position::new(0, 99)), t.find('\n').unwrap());
        assert_eq!(offset(t, Position::new(9, 0)), t.len());
        assert_eq!(position(t, 999), Position::new(1, 2));
        assert_eq!(position(t, 2), Position::new(0, 1));
    }

    #[test]
    fn the_line_index_converts_like_position_at_every_byte() {
        let t = "aé😀b\nxy\n\nfn f() {}\n😀";
        let lines = LineIndex::new(t);
        for at in 0..=t.len() + 2 {
            assert_eq!(lines.position(at), position(t, at), "byte {at}");
        }
        assert_eq!(lines.range((0, 3)), range(t, (0, 3)));
    }

    #[test]
    fn uris_and_paths() {
        let p = Path::new("/tmp/a b/é.ron");
        let u = path_to_uri(p).unwrap();
        assert_eq!(u.as_str(), "file:///tmp/a%20b/%C3%A9.ron");
        assert_eq!(uri_to_path(&u).unwrap(), p);
        assert!(uri_to_path(&Uri::from_str("untitled:x").unwrap()).is_none());
        assert!(uri_to_path(&Uri::from_str("file://elsewhere/x").unwrap()).is_none());
    }

    #[test]
    fn diagnostic_ranges() {
        let t = "ab cd\nef";
        assert_eq!(
            diag_range(t, 1, 4),
            Range::new(Position::new(0, 3), Position::new(0, 5))
        );
        assert_eq!(
            diag_range(t, 0, 0),
            Range::new(Position::new(0, 0), Position::new(0, 5))
        );
        assert_eq!(diag_range(t, 7, 7).start, Position::new(1, 2));
    }
}
