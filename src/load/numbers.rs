//! Numbers read from users' files, checked once at load: finite where they must be, inside their
//! range, in order (`min ≤ max`), and sizes within what the machine can hold. Each failure is a
//! located [`Diagnostic`] that names the key and says what was expected.
//!
//! Not a tick stage: the loaders (species, scenarios, squads) run these checks so that the tick
//! loop can trust every number it reads (no `clamp` with NaN bounds, no loop whose progress
//! depends on float precision). Keys are located with [`super::locate`](mod@super::locate).

use super::diag::Diagnostic;
use super::locate::find_key;
use std::path::Path;

// Loaders that check numbers also locate keys by this path.
pub use super::locate::locate_key;

/// The most agents a scenario may create in all (groups, timed spawns and squads together).
pub const MAX_AGENTS: u64 = 10_000_000;

/// The most cells of a terrain grid (a 16 384 × 16 384 grid): each cell holds a height, its
/// attributes and a cost per walking species.
pub const MAX_CELLS: u64 = 1 << 28;

/// The most food items a scenario may place or hold.
pub const MAX_FOOD: u64 = 10_000_000;

/// The largest magnitude of a coordinate (world units): beyond this an `f32` cannot tell
/// neighbouring body lengths apart.
pub const MAX_COORD: f32 = 1.0e7;

/// Checks the numbers of one file, collecting located diagnostics.
pub struct NumberCheck<'a> {
    file: &'a Path,
    text: &'a str,
    /// Where key searches start: the section (behavior, group, primitive) being checked.
    pub from: usize,
    /// What was found wrong so far.
    pub diags: Vec<Diagnostic>,
}

impl<'a> NumberCheck<'a> {
    /// Checks for `file`, whose text is `text`.
    pub fn new(file: &'a Path, text: &'a str) -> Self {
        NumberCheck {
            file,
            text,
            from: 0,
            diags: Vec::new(),
        }
    }

    /// Moves the section to the next `key` after the current section's start, when it is
    /// written (a default value leaves the section where it was); returns the new start.
    /// Entering the same key again moves on to its next occurrence (list entries).
    pub fn enter(&mut self, key: &str) -> usize {
        let after = if self.from == 0 { 0 } else { self.from + 1 };
        if let Some((at, _)) = find_key(self.text, key, after) {
            self.from = at;
        }
        self.from
    }

    /// Line and column of `key`'s value in the current section (or anywhere, or nowhere).
    fn at(&self, key: &str) -> (usize, usize) {
        locate_key(self.text, key, self.from)
            .or_else(|| locate_key(self.text, key, 0))
            .map_or((0, 0), |(l, c, _)| (l, c))
    }

    /// Records `msg` at `key`'s value.
    pub fn error(&mut self, key: &str, msg: String) {
        let (l, c) = self.at(key);
        self.diags
            .push(Diagnostic::new(self.file, l, c, msg, Some(self.text)));
    }

    /// `v` must be a finite number.
    pub fn finite(&mut self, key: &str, v: f32) -> bool {
        self.range(key, v, f32::MIN, f32::MAX)
    }

    /// `v` must be a finite number ≥ 0.
    pub fn non_negative(&mut self, key: &str, v: f32) -> bool {
        self.range(key, v, 0.0, f32::MAX)
    }

    /// `v` must be a finite number > 0.
    pub fn positive(&mut self, key: &str, v: f32) -> bool {
        if v.is_finite() && v > 0.0 {
            return true;
        }
        self.error(key, format!("`{key}` must be a finite number > 0, not {v}"));
        false
    }

    /// `v` must be finite and lie in `[lo, hi]`.
    pub fn range(&mut self, key: &str, v: f32, lo: f32, hi: f32) -> bool {
        if v.is_finite() && v >= lo && v <= hi {
            return true;
        }
        let expected = match (lo == f32::MIN, hi == f32::MAX) {
            (true, true) => "a finite number".to_string(),
            (false, true) => format!("a finite number ≥ {lo}"),
            (true, false) => format!("a finite number ≤ {hi}"),
            (false, false) => format!("a number from {lo} to {hi}"),
        };
        self.error(key, format!("`{key}` must be {expected}, not {v}"));
        false
    }

    /// `v` must not be NaN and must be ≥ 0; infinity is allowed (e.g. "no limit").
    pub fn non_negative_or_inf(&mut self, key: &str, v: f32) -> bool {
        if v >= 0.0 {
            return true;
        }
        self.error(
            key,
            format!("`{key}` must be a number ≥ 0 (or `inf` for no limit), not {v}"),
        );
        false
    }

    /// Every component of `v` must be finite with magnitude at most [`MAX_COORD`].
    pub fn point(&mut self, key: &str, v: &[f32]) -> bool {
        if v.iter().all(|x| x.is_finite() && x.abs() <= MAX_COORD) {
            return true;
        }
        self.error(
            key,
            format!("`{key}` must have finite coordinates within ±{MAX_COORD:e}, not {v:?}"),
        );
        false
    }

    /// `lo ≤ hi`, where both were checked finite before.
    pub fn order(&mut self, lo_key: &str, lo: f32, hi_key: &str, hi: f32) -> bool {
        if lo <= hi {
            return true;
        }
        self.error(
            lo_key,
            format!("`{lo_key}` ({lo}) must not exceed `{hi_key}` ({hi})"),
        );
        false
    }

    /// A count must not exceed `max` (`what` says what is counted and why the limit).
    pub fn count(&mut self, key: &str, n: u64, max: u64, what: &str) -> bool {
        if n <= max {
            return true;
        }
        self.error(
            key,
            format!("`{key}` is {n}, above the limit of {max} {what}"),
        );
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_and_inf_are_refused_with_the_key_located() {
        let text = "Species(\n  body: (limits: (max_turn: NaN)),\n)";
        let mut n = NumberCheck::new(Path::new("a.ron"), text);
        n.enter("limits");
        assert!(!n.positive("max_turn", f32::NAN));
        assert!(!n.non_negative("cooldown", f32::INFINITY));
        assert_eq!((n.diags[0].line, n.diags[0].col), (2, 29));
        assert!(n.diags[0].message.contains("finite number > 0, not NaN"));
        assert!(n.diags[1].message.contains("≥ 0, not inf"));
    }
}
