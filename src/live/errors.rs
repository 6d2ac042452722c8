//! A live session's runtime script errors as the designer sees them: which agent, species and
//! script function, and where (`file:line:col`), for the terminal line of `shoal watch` and the
//! page's error toast. Not a tick stage: read from the events of the tick just done.

use crate::species::Species;
use serde::Serialize;

/// One runtime script error, located.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScriptFailure {
    /// The tick it happened in.
    pub tick: u64,
    /// The agent whose call failed.
    pub agent: u32,
    /// Its species.
    pub species: String,
    /// The script function the failing line is in, when it is in the species' own script.
    pub function: Option<String>,
    /// `file:line:col` of the failure (empty when the message does not start with one).
    pub at: String,
    /// The whole message: `file:line:col: what`, then the offending line.
    pub message: String,
}

impl ScriptFailure {
    /// Reads the error of `agent` of species `sp` at `tick` from its located `message`.
    pub fn new(tick: u64, agent: u32, sp: &Species, message: &str) -> ScriptFailure {
        let (at, line) = location(message);
        let function = sp.script.as_ref().and_then(|s| {
            let file = at.rsplitn(3, ':').nth(2)?;
            if std::path::Path::new(file) != s.file {
                return None;
            }
            // The function whose `fn` line is the last one at or above the failing line.
            s.functions
                .iter()
                .map(|(name, _)| (s.fn_position(name).0, name))
                .filter(|(l, _)| *l > 0 && *l <= line)
                .max_by_key(|(l, _)| *l)
                .map(|(_, name)| name.clone())
        });
        ScriptFailure {
            tick,
            agent,
            species: sp.name.clone(),
            function,
            at,
            message: message.to_string(),
        }
    }

    /// One line for the terminal: agent, species, function and the message's first line.
    pub fn headline(&self) -> String {
        let function = self
            .function
            .as_deref()
            .map_or(String::new(), |f| format!(" in `{f}()`"));
        format!(
            "agent {} ({}){function}: {}",
            self.agent,
            self.species,
            self.message.lines().next().unwrap_or("")
        )
    }
}

/// The `file:line:col` a located message starts with, and its line (0 when there is none).
fn location(message: &str) -> (String, usize) {
    let first = message.lines().next().unwrap_or("");
    // `file:line:col: what`: the first `:N:M:` after the file name (which may hold colons).
    let bytes = first.as_bytes();
    for (i, _) in first.match_indices(':') {
        let rest = &first[i + 1..];
        let digits = |s: &str| s.bytes().take_while(u8::is_ascii_digit).count();
        let n = digits(rest);
        if n == 0 || rest.as_bytes().get(n) != Some(&b':') {
            continue;
        }
        let m = digits(&rest[n + 1..]);
        if m == 0 || rest.as_bytes().get(n + 1 + m) != Some(&b':') {
            continue;
        }
        let end = i + 1 + n + 1 + m;
        let line = rest[..n].parse().unwrap_or(0);
        debug_assert!(end <= bytes.len());
        return (first[..end].to_string(), line);
    }
    (String::new(), 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_place_is_read_from_the_message() {
        assert_eq!(
            location("b/fish.rhai:12:5: boom\n12 | x"),
            ("b/fish.rhai:12:5".to_string(), 12)
        );
        assert_eq!(
            location("C:/x/f.rhai:3:9: y"),
            ("C:/x/f.rhai:3:9".to_string(), 3)
        );
        assert_eq!(location("no place here"), (String::new(), 0));
    }
}
