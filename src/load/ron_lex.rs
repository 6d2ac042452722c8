//! RON's tokens: identifiers and numbers, strings, brackets, commas and colons, each with its
//! byte range. A forgiving scan (an unclosed string or bracket is still tokenised), shared by the
//! language server's cursor scan and by the settings that patch a file by key
//! ([`super::ron_patch`]). Not a tick stage.

/// A lexical token of RON, with its byte range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tok {
    /// An identifier or number.
    Word,
    /// A string (closed or not).
    Str,
    /// `(`, `[` or `{`.
    Open(u8),
    /// `)`, `]` or `}`.
    Close,
    /// `,`.
    Comma,
    /// `:` (not `::`).
    Colon,
}

/// Splits `text` into tokens (comments and whitespace dropped).
pub fn tokens(text: &str) -> Vec<(Tok, usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        match c {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                    i += 1;
                }
                i = (i + 2).min(b.len());
            }
            b'"' => {
                let start = i;
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    if b[i] == b'\\' {
                        i += 1;
                    }
                    i += 1;
                }
                i = (i + 1).min(b.len());
                out.push((Tok::Str, start, i));
            }
            b'(' | b'[' | b'{' => {
                out.push((Tok::Open(c), i, i + 1));
                i += 1;
            }
            b')' | b']' | b'}' => {
                out.push((Tok::Close, i, i + 1));
                i += 1;
            }
            b',' => {
                out.push((Tok::Comma, i, i + 1));
                i += 1;
            }
            b':' if b.get(i + 1) == Some(&b':') => i += 2,
            b':' => {
                out.push((Tok::Colon, i, i + 1));
                i += 1;
            }
            _ if is_word(c) => {
                let start = i;
                while i < b.len() && is_word(b[i]) {
                    i += 1;
                }
                out.push((Tok::Word, start, i));
            }
            _ => i += 1,
        }
    }
    out
}

/// Bytes of identifiers and numbers.
pub fn is_word(c: u8) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, b'_' | b'.' | b'-' | b'+')
}

/// Bytes of identifiers.
pub fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}
