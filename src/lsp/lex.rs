//! A forgiving scanner for RON and Rhai text: identifiers, string literals and punctuation with
//! their byte ranges, comments skipped. The symbol index reads documents through it, so an
//! outline and navigation keep working while a file is half-typed and does not parse.

/// One token: what it is and the byte range it covers in the text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Tok {
    /// An identifier or keyword.
    Ident(usize, usize),
    /// A string literal: the byte range of its content (between the quotes).
    Str(usize, usize),
    /// Any other character outside comments, numbers and whitespace.
    Punct(char, usize),
}

/// The tokens of `text`. Never fails: an unclosed string or comment runs to the end.
pub fn tokens(text: &str) -> Vec<Tok> {
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
                while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                    i += 1;
                }
                i = (i + 2).min(b.len());
            }
            b'"' | b'`' => {
                let start = i + 1;
                i += 1;
                while i < b.len() && b[i] != c {
                    if b[i] == b'\\' {
                        i += 1;
                    }
                    i += 1;
                }
                let end = i.min(b.len());
                out.push(Tok::Str(start, end));
                i = (i + 1).min(b.len());
            }
            b'\'' => {
                // A character literal: skipped whole, so `'"'` opens no string.
                i += 1;
                if b.get(i) == Some(&b'\\') {
                    i += 1;
                }
                i += 1;
                while i < b.len() && b[i] != b'\'' && b[i] != b'\n' {
                    i += 1;
                }
                i = (i + 1).min(b.len());
            }
            _ if c.is_ascii_alphabetic() || c == b'_' => {
                let start = i;
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                out.push(Tok::Ident(start, i));
            }
            _ if c.is_ascii_digit() => {
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_' || b[i] == b'.')
                {
                    i += 1;
                }
            }
            _ if c.is_ascii_whitespace() => i += 1,
            _ if c.is_ascii() => {
                out.push(Tok::Punct(c as char, i));
                i += 1;
            }
            _ => i += 1,
        }
    }
    out
}

/// The text of an identifier or string token.
pub fn text_of<'t>(text: &'t str, t: &Tok) -> &'t str {
    match *t {
        Tok::Ident(s, e) | Tok::Str(s, e) => text.get(s..e).unwrap_or(""),
        Tok::Punct(..) => "",
    }
}

/// Whether token `t` is the punctuation `c`.
pub fn is_punct(t: Option<&Tok>, c: char) -> bool {
    matches!(t, Some(Tok::Punct(x, _)) if *x == c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_comments_and_idents() {
        let t = "a: \"x\\\"y\" // \"no\"\n/* \"no\" */ fn f('\"')";
        let toks = tokens(t);
        let words: Vec<&str> = toks.iter().map(|k| text_of(t, k)).collect();
        assert_eq!(words, ["a", "", "x\\\"y", "fn", "f", "", ""]);
        // Unclosed things never panic.
        for s in ["\"abc", "/* x", "'", "'\\", "é\"é"] {
            tokens(s);
        }
    }
}
