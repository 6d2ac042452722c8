//! The focuser of seed 000 §1: "a focuser passes on only what the current intention cares
//! about". A behavior may name the categories its steering reads (`focus: Some([Food,
//! Obstacle])`); while it is the current behavior, its steering primitives see only percepts of
//! those categories, and the summaries of the others read as nothing perceived.
//!
//! Only steering is focused. What decides *whether to switch* (every behavior's `when` and
//! `done`, interrupts, scripts' conditions, the drives) still reads everything: a predator must
//! interrupt a forager that is not looking for it. Without `focus` a behavior sees everything,
//! the engine's form before the focuser.

pub use crate::params::decision::Focus;
use crate::perception::{Category, Percept, Summary, MAX_PERCEPTS};

/// Writes into `out` the percepts of `percepts` whose category is in `focus` (in their order)
/// and returns the summaries as the focused behavior reads them: those of the categories left
/// out are [`Summary::NONE`], the others keep their counts and means, their `nearest` pointing
/// into `out`. `out` is cleared first and reused, so a warmed-up worker allocates nothing.
pub fn narrow(
    focus: Focus,
    percepts: &[Percept],
    summaries: &[Summary; Category::COUNT],
    out: &mut Vec<Percept>,
) -> [Summary; Category::COUNT] {
    out.clear();
    // Where each kept percept went (u16::MAX: left out).
    let mut moved = [u16::MAX; MAX_PERCEPTS];
    for (k, p) in percepts.iter().enumerate() {
        if focus.contains(p.category()) {
            if let Some(m) = moved.get_mut(k) {
                *m = out.len() as u16;
            }
            out.push(*p);
        }
    }
    let mut narrowed = [Summary::NONE; Category::COUNT];
    for c in Category::ALL {
        if focus.contains(c) {
            let mut s = summaries[c as usize];
            s.nearest = s
                .nearest
                .and_then(|k| moved.get(k as usize).copied())
                .filter(|&k| k != u16::MAX);
            narrowed[c as usize] = s;
        }
    }
    narrowed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::{Sense, Source};
    use glam::Vec3;

    fn p(category: Category, dist: f32) -> Percept {
        Percept::new(
            Source::Injected,
            category,
            Sense::Vision,
            Vec3::new(0.0, 0.0, dist),
            dist,
            1.0,
        )
    }

    #[test]
    fn a_focus_holds_exactly_the_categories_listed() {
        let f = Focus::of(&[Category::Food, Category::Obstacle]);
        for c in Category::ALL {
            let want = matches!(c, Category::Food | Category::Obstacle);
            assert_eq!(f.contains(c), want, "{c:?}");
        }
        assert!(Category::ALL.iter().all(|&c| Focus::ALL.contains(c)));
        assert!(Category::ALL.iter().all(|&c| !Focus::of(&[]).contains(c)));
        // A category listed twice is still in.
        let twice = Focus::of(&[Category::Kin, Category::Kin]);
        assert!(twice.contains(Category::Kin) && !twice.contains(Category::Food));
    }

    #[test]
    fn narrowing_keeps_the_focused_percepts_and_repoints_their_nearest() {
        // Percepts: other 1, food 2, obstacle 3, predator 4, food 5.
        let percepts = [
            p(Category::Other, 1.0),
            p(Category::Food, 2.0),
            p(Category::Obstacle, 3.0),
            p(Category::Predator, 4.0),
            p(Category::Food, 5.0),
        ];
        let mut summaries = [Summary::NONE; Category::COUNT];
        let near = |k: u16, d: f32, n: u32| Summary {
            count: n,
            seen: n,
            nearest: Some(k),
            nearest_dist: d,
            ..Summary::NONE
        };
        summaries[Category::Other as usize] = near(0, 1.0, 1);
        summaries[Category::Food as usize] = near(1, 2.0, 2);
        summaries[Category::Obstacle as usize] = near(2, 3.0, 1);
        summaries[Category::Predator as usize] = near(3, 4.0, 1);
        let mut out = vec![p(Category::Kin, 9.0)];
        let f = Focus::of(&[Category::Food, Category::Predator]);
        let s = narrow(f, &percepts, &summaries, &mut out);
        // Kept in order: food 2 (was 1), predator 4 (was 3), food 5 (was 4).
        let dists: Vec<f32> = out.iter().map(|p| p.dist).collect();
        assert_eq!(dists, [2.0, 4.0, 5.0]);
        assert_eq!(s[Category::Food as usize].nearest, Some(0));
        assert_eq!(s[Category::Food as usize].count, 2);
        assert_eq!(s[Category::Predator as usize].nearest, Some(1));
        assert_eq!(s[Category::Other as usize], Summary::NONE);
        assert_eq!(s[Category::Obstacle as usize], Summary::NONE);
        // Everything: the same percepts and summaries.
        let s = narrow(Focus::ALL, &percepts, &summaries, &mut out);
        assert_eq!(out, percepts);
        assert_eq!(s, summaries);
    }
}
