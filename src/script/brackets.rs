//! Where a script's brackets stop matching, for syntax errors. Rhai reports where parsing failed
//! (often the closing `}` of the function, or the end of the file), not the `(` that was never
//! closed; a scan of the text outside strings and comments finds that opener. Load time only.

/// Line, column (1-based) and character of the first bracket that is never closed: the opener
/// a mismatched closer runs into, or the innermost opener still open at the end.
pub fn unclosed(text: &str) -> Option<(usize, usize, char)> {
    let mut open: Vec<(usize, usize, char)> = Vec::new();
    // How many of each kind are open: whether a closer's opener is anywhere on the stack,
    // without scanning it (a file of mismatched closers over a deep stack was quadratic).
    let mut depth = [0usize; 3];
    let kind = |b: char| match b {
        '(' | ')' => 0,
        '[' | ']' => 1,
        _ => 2,
    };
    let (mut line, mut col) = (1, 0);
    let mut chars = text.chars().peekable();
    // Inside a block comment (nesting depth), a line comment, or a string (its quote).
    let mut block = 0usize;
    let mut in_line = false;
    let mut quote: Option<char> = None;
    while let Some(c) = chars.next() {
        col += 1;
        if c == '\n' {
            line += 1;
            col = 0;
            in_line = false;
            continue;
        }
        if in_line {
            continue;
        }
        if block > 0 {
            if c == '*' && chars.peek() == Some(&'/') {
                chars.next();
                col += 1;
                block -= 1;
            } else if c == '/' && chars.peek() == Some(&'*') {
                chars.next();
                col += 1;
                block += 1;
            }
            continue;
        }
        if let Some(q) = quote {
            if c == '\\' && q != '`' {
                if chars.next().is_some() {
                    col += 1;
                }
            } else if c == q {
                quote = None;
            }
            continue;
        }
        match c {
            '/' if chars.peek() == Some(&'/') => in_line = true,
            '/' if chars.peek() == Some(&'*') => {
                chars.next();
                col += 1;
                block = 1;
            }
            '"' | '\'' | '`' => quote = Some(c),
            '(' | '[' | '{' => {
                open.push((line, col, c));
                depth[kind(c)] += 1;
            }
            ')' | ']' | '}' => {
                let want = match c {
                    ')' => '(',
                    ']' => '[',
                    _ => '{',
                };
                match open.last() {
                    Some(&(_, _, o)) if o == want => {
                        open.pop();
                        depth[kind(c)] -= 1;
                    }
                    // `#{` opens a map and closes with `}`.
                    Some(&top) if depth[kind(c)] > 0 => return Some(top),
                    _ => {}
                }
            }
            _ => {}
        }
    }
    open.last().copied()
}

/// A note for a syntax error at `line:col` of `text`: where the bracket that is never closed
/// was opened, when that is somewhere else.
pub fn note(text: &str, line: usize, col: usize) -> Option<String> {
    let (l, c, ch) = unclosed(text)?;
    if (l, c) == (line, col) {
        return None;
    }
    Some(format!(
        "; the `{ch}` at line {l}, column {c} is never closed"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_opener_a_closer_runs_into() {
        let text = "fn f() {\n    let x = g(1, 2;\n}\n";
        assert_eq!(unclosed(text), Some((2, 14, '(')));
    }

    #[test]
    fn ignores_brackets_in_strings_and_comments() {
        let text = "// a ( in a comment\nfn f() { \"(\" + `{` } /* [ */\n";
        assert_eq!(unclosed(text), None);
        assert_eq!(unclosed("fn f() {\n  if x {\n}\n"), Some((1, 8, '{')));
    }

    #[test]
    fn a_closer_with_no_opener_of_its_kind_is_skipped() {
        assert_eq!(unclosed("f(x]"), Some((1, 2, '(')));
        assert_eq!(unclosed("[f(x]"), Some((1, 3, '(')));
        assert_eq!(unclosed("f(x))"), None);
    }

    #[test]
    fn many_stray_closers_over_a_deep_stack_take_linear_time() {
        // Found by the fuzzer: each stray `)` scanned every open `[`, 10 s on 670 KB.
        let text = format!("{}{}", "[".repeat(200_000), ")".repeat(200_000));
        let t = std::time::Instant::now();
        assert_eq!(unclosed(&text), Some((1, 200_000, '[')));
        assert!(t.elapsed().as_secs_f64() < 0.5, "{:?}", t.elapsed());
    }
}
