//! "Did you mean" hints: the known name closest to a misspelt one, for the messages of every
//! loader (RON variants and fields, behavior names, species names). Not a tick stage.

/// Edit distance between two short names (for "did you mean" hints).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diag + usize::from(!ca.eq_ignore_ascii_case(&cb)))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diag = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// ` (did you mean `x`?)` when one of `known` is close to `found`, else nothing.
pub fn did_you_mean<'a>(found: &str, known: impl IntoIterator<Item = &'a str>) -> String {
    let best = known
        .into_iter()
        .map(|k| (edit_distance(found, k), k))
        .min_by_key(|(d, _)| *d);
    match best {
        Some((d, k)) if d > 0 && d <= 2.max(found.chars().count() / 3) => {
            format!(" (did you mean `{k}`?)")
        }
        _ => String::new(),
    }
}
