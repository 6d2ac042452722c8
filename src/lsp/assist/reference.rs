//! The designers' references, embedded, and the entry of one word cut out of them: the species
//! reference (`behaviors/README.md`), the scenario reference (`docs/scenarios.md`), the squads
//! reference (`docs/squads.md`) and the test reference (`behaviors/tests/README.md`). An entry
//! is the table row that names the word in its first cell (with the table's header, so it
//! renders as a table), else the bullet that starts with it, else the paragraph that names it in
//! code.

/// The species reference.
pub const SPECIES: &str = include_str!("../../../behaviors/README.md");
/// The scenario reference.
pub const SCENARIOS: &str = include_str!("../../../docs/scenarios.md");
/// The squads reference (the squad part of the script API).
pub const SQUADS: &str = include_str!("../../../docs/squads.md");
/// The script-test reference.
pub const TESTS: &str = include_str!("../../../behaviors/tests/README.md");

/// Whether `word` is written as code in `text`: inside backticks, as a whole identifier, at the
/// start of the code or after `.`, `(`, `[`, a space or `|`.
pub fn names(text: &str, word: &str) -> bool {
    if word.is_empty() {
        return false;
    }
    let b = text.as_bytes();
    text.match_indices(word).any(|(i, _)| {
        let in_code = text[..i].matches('`').count() % 2 == 1;
        let before = if i == 0 { b' ' } else { b[i - 1] };
        let after = b.get(i + word.len()).copied().unwrap_or(b' ');
        in_code
            && matches!(before, b'`' | b'.' | b'(' | b'[' | b' ' | b'|')
            && !(after.is_ascii_alphanumeric() || after == b'_')
    })
}

/// The entry for `word` in `doc`, preferring one inside the section whose heading is `section`
/// (a `##`/`###` heading, compared without backticks and case).
pub fn entry(doc: &str, word: &str, section: Option<&str>) -> Option<String> {
    let found = entries(doc, word);
    if let Some(sec) = section {
        if let Some(e) = found.iter().find(|e| same(&e.section, sec)) {
            return Some(e.text.clone());
        }
    }
    found.into_iter().next().map(|e| e.text)
}

/// The section under the heading `name` (its text up to the first code block or 30 lines).
pub fn section(doc: &str, name: &str) -> Option<String> {
    let lines: Vec<&str> = doc.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with('#') && same(l.trim_start_matches('#').trim(), name))?;
    let mut out = vec![lines[at]];
    for l in lines.iter().skip(at + 1).take(30) {
        if l.starts_with('#') || l.starts_with("```") {
            break;
        }
        out.push(l);
    }
    Some(out.join("\n").trim_end().to_string())
}

fn same(a: &str, b: &str) -> bool {
    a.trim_matches('`')
        .eq_ignore_ascii_case(b.trim_matches('`'))
}

struct Found {
    section: String,
    text: String,
    rank: u8,
}

fn entries(doc: &str, word: &str) -> Vec<Found> {
    let lines: Vec<&str> = doc.lines().collect();
    let mut out = Vec::new();
    let mut heading = "";
    let mut header: Option<(usize, usize)> = None; // the current table's header lines
    let mut in_code = false;
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i];
        if l.starts_with("```") {
            in_code = !in_code;
            i += 1;
            continue;
        }
        if in_code {
            i += 1;
            continue;
        }
        if l.starts_with('#') {
            heading = l.trim_start_matches('#').trim();
        }
        if l.starts_with('|') {
            if header.is_none() {
                header = Some((i, i + 1));
            } else if i > header.map_or(0, |h| h.1) {
                let first = l.split('|').nth(1).unwrap_or("");
                if names(first, word) {
                    let (h, s) = header.unwrap_or((i, i));
                    out.push(Found {
                        section: heading.to_string(),
                        text: format!("{}\n{}\n{l}", lines[h], lines[s]),
                        rank: 0,
                    });
                }
            }
            i += 1;
            continue;
        }
        header = None;
        if let Some(rest) = l.strip_prefix("- ") {
            let first_code = rest.split('`').nth(1).unwrap_or("");
            if rest.starts_with('`') && names(&format!("`{first_code}`"), word) {
                let mut text = l.to_string();
                let mut j = i + 1;
                while j < lines.len() && lines[j].starts_with("  ") {
                    text.push('\n');
                    text.push_str(lines[j]);
                    j += 1;
                }
                out.push(Found {
                    section: heading.to_string(),
                    text,
                    rank: 1,
                });
            }
        } else if !l.trim().is_empty() && !l.starts_with('#') {
            // A paragraph: from here to the next blank line.
            let mut j = i;
            while j < lines.len()
                && !lines[j].trim().is_empty()
                && !lines[j].starts_with('|')
                && !lines[j].starts_with("```")
                && !lines[j].starts_with('#')
            {
                j += 1;
            }
            let para = lines[i..j].join("\n");
            if names(&para, word) {
                out.push(Found {
                    section: heading.to_string(),
                    text: para,
                    rank: 2,
                });
            }
            i = j.max(i + 1);
            continue;
        }
        i += 1;
    }
    out.sort_by_key(|f| f.rank);
    out
}
