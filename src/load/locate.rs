//! Where something is written in a user's file: the line and column (1-based) of a quoted name
//! or of a key's value, so that a problem found after parsing points at its text. Not a tick
//! stage; every loader locates its diagnostics with these.

/// Line and column (1-based) of the first occurrence of `needle` at or after byte `from`.
pub fn locate(text: &str, needle: &str, from: usize) -> Option<(usize, usize, usize)> {
    let at = text.get(from..)?.find(needle)? + from;
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    Some((line, col, at))
}

/// Line, column and byte offset of the value of `key` (an identifier followed by `:` or `(`)
/// at or after byte `from`: the first character after the `:` or the `(` itself.
pub fn locate_key(text: &str, key: &str, from: usize) -> Option<(usize, usize, usize)> {
    find_key(text, key, from).map(|(_, value)| position(text, value))
}

/// Byte offsets of the first `key` at or after `from` that is a whole identifier followed by
/// `:` or `(`, and of its value.
pub(crate) fn find_key(text: &str, key: &str, from: usize) -> Option<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut start = from.min(text.len());
    while let Some(i) = text.get(start..).and_then(|t| t.find(key)) {
        let at = start + i;
        let end = at + key.len();
        start = at + 1;
        let ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
        if at > 0 && ident(bytes[at - 1]) {
            continue;
        }
        let mut j = end;
        while j < bytes.len() && bytes[j].is_ascii_whitespace() {
            j += 1;
        }
        match bytes.get(j) {
            Some(b'(') => return Some((at, j)),
            Some(b':') => {
                j += 1;
                while j < bytes.len() && bytes[j].is_ascii_whitespace() {
                    j += 1;
                }
                // An optional value written `Some(x)`: the problem is `x`, not `Some`.
                if bytes[j.min(bytes.len())..].starts_with(b"Some(") {
                    j += "Some(".len();
                    while j < bytes.len() && bytes[j].is_ascii_whitespace() {
                        j += 1;
                    }
                }
                return Some((at, j.min(text.len())));
            }
            _ => continue,
        }
    }
    None
}

/// Line and column (1-based) of byte `at`, and `at`.
fn position(text: &str, at: usize) -> (usize, usize, usize) {
    let at = (0..=at)
        .rev()
        .find(|&i| text.is_char_boundary(i))
        .unwrap_or(0);
    let line = text[..at].matches('\n').count() + 1;
    let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let col = text[line_start..at].chars().count() + 1;
    (line, col, at)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_found_as_whole_identifiers_before_a_colon() {
        let text = "(max_turn_x: 1, max_turn : 2)";
        let (l, c, _) = locate_key(text, "max_turn", 0).unwrap();
        assert_eq!((l, c), (1, 28));
    }
}
