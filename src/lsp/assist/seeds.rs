//! Seed constants under the cursor: a key that overrides a constant of the source documents
//! (`species::seeds::seed_constants()`, the reference's "Seed constants") is shown with the
//! engine's default, the paper's value and the seed section it comes from.

use super::reference;
use crate::species::seeds::seed_constants;

/// The seed constant written as `key` (`senses.sectors.front`, `Chase(max_turn)`), described.
pub fn describe(key: &str) -> Option<String> {
    let c = seed_constants().into_iter().find(|c| c.key == key)?;
    let paper = c
        .paper
        .map_or("— (named without a number)".to_string(), number);
    let mut md = format!(
        "**Seed constant** `{}` (seed {})\n\ndefault {} · paper {paper}",
        c.key,
        c.seed,
        number(c.default)
    );
    if let Some(row) = reference::entry(reference::SPECIES, c.key, Some("Seed constants"))
        .filter(|e| e.contains(c.key))
    {
        md.push_str("\n\n");
        md.push_str(&row);
    }
    Some(md)
}

/// A number as the reference writes it: at most four decimals.
fn number(x: f32) -> String {
    let s = format!("{x:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
