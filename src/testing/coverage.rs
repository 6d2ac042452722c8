//! Coverage for designers (`shoal test --coverage`): per species, which behaviors no test ever
//! ran and which transitions (from → to, cause) the arbitration rules of seed 000 §3 allow but no
//! test ever made.

use super::world::lock;
use crate::events::Cause;
use crate::species::{load_species, Compose, CondNode, Species};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

#[derive(Debug, Default)]
struct Seen {
    roots: BTreeSet<PathBuf>,
    behaviors: BTreeSet<(String, String)>,
    transitions: BTreeSet<(String, String, String, &'static str)>,
}

/// What the tests of a run exercised (shared by every test; sets, so the result does not depend
/// on the order tests run in).
#[derive(Debug, Default)]
pub struct Coverage {
    seen: Mutex<Seen>,
}

/// A transition the rules allow: `(from, to, cause)`.
pub type Possible = (u16, u16, Cause);

/// The conjuncts of a condition (`All([a, b])` → a, b).
fn conjuncts(c: &CondNode) -> Vec<&CondNode> {
    match c {
        CondNode::All(v) => v.iter().flat_map(conjuncts).collect(),
        c => vec![c],
    }
}

/// The disjuncts of a condition (`Any([a, b])` → a, b).
fn disjuncts(c: &CondNode) -> Vec<&CondNode> {
    match c {
        CondNode::Any(v) => v.iter().flat_map(disjuncts).collect(),
        c => vec![c],
    }
}

/// Whether `a` and `b` cannot both hold (one is the negation of the other).
fn contradicts(a: &CondNode, b: &CondNode) -> bool {
    matches!(a, CondNode::Not(x) if **x == *b) || matches!(b, CondNode::Not(x) if **x == *a)
}

/// Every transition seed 000 §3's arbitration allows for a species, as far as the conditions
/// show it:
/// - interrupted: to a behavior that can trigger and whose level is higher, or equal when the
///   current one lets equal levels interrupt it — unless the new one's activation implies the
///   current one's completion (a shared term), which then completes instead;
/// - completed: from a behavior that can complete, to one that can trigger and whose activation
///   does not contradict that completion, or to the initial behavior when it can leave the stack
///   (the fallback; an initial behavior that never completes stays at the bottom of the stack
///   and resumes instead);
/// - resumed: from a behavior that can complete, to one that can be interrupted (so stacked) at
///   the same level or below (the top of the stack never outranks the current behavior).
///
/// For composed behaviors the same analysis runs inside each prioritized list (the species'
/// own, each `behaviors:`) over its members, and a sequence's or fallback's steps and each
/// `on_success` / `on_failure` add their transitions; a transition between parts is counted
/// between the members of the innermost list that holds both ([`lift`]).
pub fn possible(sp: &Species) -> Vec<Possible> {
    let bs = &sp.behaviors;
    if sp.depth == 0 {
        let all: Vec<usize> = (0..bs.len()).collect();
        return possible_in(sp, &all, sp.initial as usize);
    }
    let mut out = possible_in(
        sp,
        &sp.roots.iter().map(|&i| i as usize).collect::<Vec<_>>(),
        sp.initial_node as usize,
    );
    for (i, b) in bs.iter().enumerate() {
        let kids: Vec<usize> = b.children.iter().map(|&c| c as usize).collect();
        match b.compose {
            Compose::Leaf => {}
            Compose::Select => {
                let init = crate::species::validate::default_part(bs, i as u16).unwrap_or(0);
                out.extend(possible_in(sp, &kids, init as usize));
            }
            Compose::Sequence | Compose::Fallback => {
                let cause = if b.compose == Compose::Sequence {
                    Cause::Succeeded
                } else {
                    Cause::Failed
                };
                for w in b.children.windows(2) {
                    if bs[w[0] as usize].on_success.is_none() || cause == Cause::Failed {
                        out.push((w[0], w[1], cause));
                    }
                }
            }
        }
        if let Some(t) = b.on_success {
            out.push((i as u16, t, Cause::Succeeded));
        }
        if let Some(t) = b.on_failure {
            out.push((i as u16, t, Cause::Failed));
        }
    }
    out.sort_by_key(|&(f, t, c)| (f, t, c as u8));
    out.dedup();
    out
}

/// A transition between two parts, as the members of the innermost list holding both: from
/// `hunt/strike` to `feed` is from `hunt` to `feed`; from `eat/search` to `eat/chase` stays.
pub fn lift(sp: &Species, from: u16, to: u16) -> (u16, u16) {
    let chain = |i: u16| {
        let mut v: Vec<u16> = crate::species::validate::ancestors(&sp.behaviors, i).collect();
        v.reverse();
        v
    };
    let (a, b) = (chain(from), chain(to));
    let k = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    match (a.get(k), b.get(k)) {
        (Some(&x), Some(&y)) => (x, y),
        _ => (from, to),
    }
}

/// The analysis over `members`, one prioritized list whose default is `initial`.
fn possible_in(sp: &Species, members: &[usize], initial: usize) -> Vec<Possible> {
    let bs = &sp.behaviors;
    let triggers = |i: usize| bs[i].when != CondNode::Never;
    let level_allows = |from: usize, to: usize| {
        bs[to].priority < bs[from].priority
            || (bs[to].priority == bs[from].priority && bs[from].equal_may_interrupt)
    };
    let interrupts = |from: usize, to: usize| {
        if !triggers(to) || !level_allows(from, to) {
            return false;
        }
        // Completion is checked first; it is only held back by min_time, which also holds back
        // equal levels (not higher ones).
        let completes_first = bs[to].priority == bs[from].priority || bs[from].min_time <= 0.0;
        let shared = conjuncts(&bs[to].when)
            .iter()
            .any(|c| disjuncts(&bs[from].done).contains(c));
        !(completes_first && shared)
    };
    let stackable = |i: usize| members.iter().any(|&x| x != i && interrupts(i, x));
    // How a behavior leaves for what the list's rules choose: its completion or its failure,
    // where no `on_success` or `on_failure` names what follows (the rules then choose, a
    // failure as after a completion).
    let ends = |i: usize| {
        let b = &bs[i];
        let mut v = Vec::new();
        if b.done != CondNode::Never && b.on_success.is_none() {
            v.extend(disjuncts(&b.done));
        }
        if b.fail != CondNode::Never && b.on_failure.is_none() {
            v.extend(disjuncts(&b.fail));
        }
        v
    };
    let initial_ends = !ends(initial).is_empty();
    let mut out = Vec::new();
    for &from in members {
        let ending = ends(from);
        let completes = !ending.is_empty();
        for &to in members {
            if from == to {
                continue;
            }
            if interrupts(from, to) {
                out.push((from as u16, to as u16, Cause::Interrupted));
            }
            let compatible = !ending
                .iter()
                .all(|d| conjuncts(&bs[to].when).iter().any(|c| contradicts(c, d)));
            let starts = (triggers(to) && compatible) || (to == initial && initial_ends);
            if completes && starts {
                out.push((from as u16, to as u16, Cause::Completed));
            }
            if completes && stackable(to) && bs[to].priority >= bs[from].priority {
                out.push((from as u16, to as u16, Cause::Resumed));
            }
        }
    }
    out
}

impl Coverage {
    /// Notes a behaviors folder whose species the report covers.
    pub fn add_root(&self, root: &Path) {
        let mut s = lock(&self.seen);
        if !s.roots.contains(root) {
            s.roots.insert(root.to_path_buf());
        }
    }

    /// Notes that an agent of `species` ran `behavior` for a tick.
    pub fn behavior(&self, species: &str, behavior: &str) {
        let mut s = lock(&self.seen);
        let key = (species.to_string(), behavior.to_string());
        if !s.behaviors.contains(&key) {
            s.behaviors.insert(key);
        }
    }

    /// Notes a transition.
    pub fn transition(&self, species: &str, from: &str, to: &str, cause: Cause) {
        let mut s = lock(&self.seen);
        s.transitions.insert((
            species.to_string(),
            from.to_string(),
            to.to_string(),
            cause.name(),
        ));
        let key = (species.to_string(), to.to_string());
        if !s.behaviors.contains(&key) {
            s.behaviors.insert(key);
        }
    }

    /// The report: for every species of every behaviors folder the tests used, what was never
    /// exercised.
    pub fn report(&self) -> String {
        let s = lock(&self.seen);
        let mut out = String::new();
        for root in &s.roots {
            let _ = writeln!(out, "coverage of {}:", root.display());
            let mut files: Vec<PathBuf> = std::fs::read_dir(root)
                .map(|r| {
                    r.flatten()
                        .map(|e| e.path())
                        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
                        .collect()
                })
                .unwrap_or_default();
            files.sort();
            for f in files {
                match load_species(&f, root, &crate::scenario::script_limits()) {
                    Ok(sp) => out.push_str(&species_report(&sp, &s)),
                    Err(d) => {
                        let _ = writeln!(out, "{}: does not load: {}", f.display(), d);
                    }
                }
            }
        }
        out
    }
}

fn species_report(sp: &Species, s: &Seen) -> String {
    let mut out = String::new();
    let name = &sp.name;
    // A composed behavior ran when one of its parts did.
    let ran = |b: &str| {
        s.behaviors.iter().any(|(sn, x)| {
            sn == name && (x == b || x.strip_prefix(b).is_some_and(|r| r.starts_with('/')))
        })
    };
    let missing_b: Vec<&str> = sp
        .behaviors
        .iter()
        .map(|b| &*b.name)
        .filter(|b| !ran(b))
        .collect();
    let all = possible(sp);
    // Transitions between parts count between the members of the list holding both.
    let mut seen = s.transitions.clone();
    if sp.depth > 0 {
        for (sn, f, t, c) in &s.transitions {
            if sn != name {
                continue;
            }
            let (Some(fi), Some(ti)) = (sp.behavior_index(f), sp.behavior_index(t)) else {
                continue;
            };
            let (a, b) = lift(sp, fi, ti);
            let (a, b) = (
                sp.behavior_name(a).to_string(),
                sp.behavior_name(b).to_string(),
            );
            seen.insert((name.clone(), a.clone(), b.clone(), c));
            // A failure the list then handles starts what its rules choose, as a completion.
            if *c == "failed" {
                seen.insert((name.clone(), a, b, Cause::Completed.name()));
            }
        }
    }
    let s = Seen {
        roots: BTreeSet::new(),
        behaviors: BTreeSet::new(),
        transitions: seen,
    };
    let mut missing_t: BTreeMap<&str, Vec<String>> = BTreeMap::new();
    let mut missing = 0;
    // Observed transitions the rule set did not predict still count as exercised.
    for &(from, to, cause) in &all {
        let (f, t) = (sp.behavior_name(from), sp.behavior_name(to));
        let key = (name.clone(), f.to_string(), t.to_string(), cause.name());
        if !s.transitions.contains(&key) {
            missing += 1;
            missing_t
                .entry(f)
                .or_default()
                .push(format!("{t} ({})", cause.name()));
        }
    }
    let nb = sp.behaviors.len();
    let _ = writeln!(
        out,
        "{name}: {} of {nb} behaviors, {} of {} transitions exercised",
        nb - missing_b.len(),
        all.len() - missing,
        all.len()
    );
    if missing_b.is_empty() {
        let _ = writeln!(out, "  every behavior was exercised");
    } else {
        let _ = writeln!(out, "  behaviors never exercised: {}", missing_b.join(", "));
    }
    if !missing_t.is_empty() {
        let _ = writeln!(out, "  transitions never exercised:");
        // In declaration order of the `from` behavior.
        for b in &sp.behaviors {
            if let Some(v) = missing_t.get(&*b.name) {
                let mut line = format!("    {} → ", b.name);
                let indent = " ".repeat(line.chars().count());
                let mut width = line.chars().count();
                for (k, item) in v.iter().enumerate() {
                    let piece = if k + 1 < v.len() {
                        format!("{item}, ")
                    } else {
                        item.clone()
                    };
                    if width + piece.len() > 100 && width > indent.len() {
                        line = line.trim_end().to_string();
                        line.push('\n');
                        line.push_str(&indent);
                        width = indent.len();
                    }
                    width += piece.chars().count();
                    line.push_str(&piece);
                }
                let _ = writeln!(out, "{line}");
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::species::load_species_str;

    fn species(behaviors: &str) -> Species {
        let text = format!(
            "Species(name: \"t\", relations: (eats_items: true), initial: \"idle\", behaviors: [{behaviors}])"
        );
        load_species_str(
            Path::new("t.ron"),
            &text,
            Path::new("."),
            &crate::script::SandboxLimits::default(),
        )
        .unwrap_or_else(|d| panic!("{d}"))
    }

    const THREE: &str = r#"
        Behavior(name: "flee", priority: 1, when: Sees(Other), done: Not(Sees(Other)), steer: Stop),
        Behavior(name: "eat", priority: 2, when: Sees(Food), done: Not(Sees(Food)), steer: Stop),
        Behavior(name: "idle", priority: 3, steer: Stop),
    "#;

    #[test]
    fn the_transitions_the_rules_allow() {
        use Cause::*;
        // flee 0 (level 1), eat 1 (level 2), idle 2 (level 3, initial, never completes).
        assert_eq!(
            possible(&species(THREE)),
            vec![
                (0, 1, Completed),
                (0, 1, Resumed),
                (0, 2, Resumed),
                (1, 0, Interrupted),
                (1, 0, Completed),
                (1, 2, Resumed),
                (2, 0, Interrupted),
                (2, 1, Interrupted),
            ]
        );
    }

    #[test]
    fn a_shared_term_means_completion_not_interruption() {
        use Cause::*;
        // seek (3) and eat (1) share level 2; each one's activation is the other's completion.
        let sp = species(&format!(
            "{THREE} Behavior(name: \"seek\", priority: 2, when: All([Smells(Food), Not(Sees(Food))]), done: Any([Sees(Food), Not(Perceives(Food))]), steer: Stop)"
        ));
        let p = possible(&sp);
        assert!(!p.contains(&(1, 3, Interrupted)));
        assert!(!p.contains(&(3, 1, Interrupted)));
        assert!(p.contains(&(1, 3, Completed)));
        assert!(p.contains(&(3, 1, Completed)));
        assert!(p.contains(&(3, 0, Interrupted)));
    }

    #[test]
    fn a_behavior_leaves_for_what_the_rules_choose_unless_its_outcome_names_what_follows() {
        use Cause::*;
        // `dash` (3) never completes; it fails after a while, and no `on_failure` names what
        // follows: the list's rules choose, as after a completion.
        let dash = r#"Behavior(name: "dash", priority: 2, when: Sees(Kin), fail: TimeIn(2.0), steer: Stop)"#;
        let p = possible(&species(&format!("{THREE} {dash}")));
        assert!(p.contains(&(3, 1, Completed)), "{p:?}");
        assert!(p.contains(&(3, 0, Completed)), "{p:?}");
        // The initial behavior never completes: it waits on the stack and resumes.
        assert!(p.contains(&(3, 2, Resumed)), "{p:?}");
        // Named, the failure leads there alone.
        let named = dash.replace("steer: Stop", "on_failure: \"idle\", steer: Stop");
        let p = possible(&species(&format!("{THREE} {named}")));
        assert!(!p.contains(&(3, 1, Completed)), "{p:?}");
        assert!(!p.contains(&(3, 2, Resumed)), "{p:?}");
        assert!(p.contains(&(3, 2, Failed)), "{p:?}");
        // So does a success that names what follows.
        let named = dash.replace(
            "fail: TimeIn(2.0)",
            "done: TimeIn(2.0), on_success: \"idle\"",
        );
        let p = possible(&species(&format!("{THREE} {named}")));
        assert!(!p.contains(&(3, 1, Completed)), "{p:?}");
        assert!(!p.contains(&(3, 0, Completed)), "{p:?}");
        assert!(p.contains(&(3, 2, Succeeded)), "{p:?}");
    }

    #[test]
    fn the_report_lists_what_was_not_seen() {
        let c = Coverage::default();
        c.behavior("t", "idle");
        c.transition("t", "idle", "flee", Cause::Interrupted);
        let s = lock(&c.seen);
        assert_eq!(
            species_report(&species(THREE), &s),
            "t: 2 of 3 behaviors, 1 of 8 transitions exercised\n\
             \x20 behaviors never exercised: eat\n\
             \x20 transitions never exercised:\n\
             \x20   flee → eat (completed), eat (resumed), idle (resumed)\n\
             \x20   eat → flee (interrupted), flee (completed), idle (resumed)\n\
             \x20   idle → eat (interrupted)\n"
        );
    }
}
