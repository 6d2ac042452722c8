//! Where a cursor stands in a RON document: the brackets open around it (each with the word
//! before it: a struct, variant or nothing), the key being written in each, the keys already
//! written there, and the half word under the cursor. A tolerant scan of the text, not a parse:
//! the document is usually broken while it is typed (unclosed brackets, half words, a missing
//! comma), and a broken part above the cursor only costs the frames it confuses.

pub use crate::load::ron_lex::{is_ident, is_word, tokens, Tok};

/// One open bracket around the cursor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Frame<'a> {
    /// `(`, `[` or `{`.
    pub open: u8,
    /// The word right before a `(` (`Behavior`, `Chase`; empty when none).
    pub name: &'a str,
    /// The key whose value is being written (`steer` in `steer: …`; empty for a map's string
    /// key); `None` where a key is expected.
    pub key: Option<&'a str>,
    /// Commas so far at this level (the position among positional values).
    pub commas: usize,
    /// Keys written at this level, before and after the cursor.
    pub keys: Vec<&'a str>,
}

/// The cursor's context.
#[derive(Debug, Clone, Default)]
pub struct Cursor<'a> {
    /// Brackets open around the cursor, outermost first.
    pub frames: Vec<Frame<'a>>,
    /// The half word before the cursor (what the user is typing).
    pub prefix: &'a str,
    /// Whether the cursor is inside a string.
    pub in_string: bool,
}

/// The context of byte `offset` of `text`.
pub fn at(text: &str, offset: usize) -> Cursor<'_> {
    let offset = floor_char(text, offset.min(text.len()));
    let toks = tokens(text);
    let b = text.as_bytes();
    let mut start = offset;
    while start > 0 && is_ident(b[start - 1]) {
        start -= 1;
    }
    let mut cur = Cursor {
        prefix: &text[start..offset],
        ..Cursor::default()
    };
    let mut pending = "";
    let mut k = 0;
    while k < toks.len() {
        let (t, s, e) = toks[k];
        if s >= start {
            break;
        }
        let closed = e - s >= 2 && b[e - 1] == b'"';
        if t == Tok::Str && (offset < e || (offset == e && !closed)) {
            // The cursor is inside this string.
            cur.in_string = true;
            cur.prefix = &text[s + 1..offset];
            break;
        }
        let next_colon = toks.get(k + 1).is_some_and(|n| n.0 == Tok::Colon);
        match t {
            Tok::Word => {
                let w = &text[s..e];
                if next_colon {
                    if let Some(f) = cur.frames.last_mut() {
                        f.key = Some(w);
                        f.keys.push(w);
                    }
                    k += 1;
                }
                pending = w;
                k += 1;
                continue;
            }
            Tok::Str => {
                if next_colon {
                    if let Some(f) = cur.frames.last_mut() {
                        f.key = Some("");
                    }
                    k += 1;
                }
            }
            Tok::Open(c) => cur.frames.push(Frame {
                open: c,
                name: if c == b'(' { pending } else { "" },
                key: None,
                commas: 0,
                keys: Vec::new(),
            }),
            Tok::Close => {
                // A close that matches no open bracket is a typo: ignore it; one that skips
                // open brackets closes them too.
                let want = match b[s] {
                    b')' => b'(',
                    b']' => b'[',
                    _ => b'{',
                };
                if let Some(at) = cur.frames.iter().rposition(|f| f.open == want) {
                    cur.frames.truncate(at);
                }
            }
            Tok::Comma => {
                if let Some(f) = cur.frames.last_mut() {
                    f.key = None;
                    f.commas += 1;
                }
            }
            Tok::Colon => {}
        }
        pending = "";
        k += 1;
    }
    // Keys written after the cursor in the innermost frame.
    if let Some(f) = cur.frames.last_mut() {
        let mut depth = 0i32;
        let after: Vec<_> = toks.iter().filter(|t| t.1 >= offset).collect();
        for (j, (t, s, e)) in after.iter().enumerate() {
            match t {
                Tok::Open(_) => depth += 1,
                Tok::Close if depth == 0 => break,
                Tok::Close => depth -= 1,
                Tok::Word if depth == 0 && after.get(j + 1).is_some_and(|n| n.0 == Tok::Colon) => {
                    f.keys.push(&text[*s..*e]);
                }
                _ => {}
            }
        }
    }
    cur
}

/// The word (identifier) around byte `offset`, with its range.
pub fn word_at(text: &str, offset: usize) -> Option<(&str, usize, usize)> {
    let b = text.as_bytes();
    let offset = floor_char(text, offset.min(text.len()));
    let mut s = offset;
    while s > 0 && is_ident(b[s - 1]) {
        s -= 1;
    }
    let mut e = offset;
    while e < b.len() && is_ident(b[e]) {
        e += 1;
    }
    (s < e).then(|| (&text[s..e], s, e))
}

/// `offset` moved back to a character boundary.
pub fn floor_char(text: &str, mut offset: usize) -> usize {
    while offset > 0 && !text.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}
