//! What each species reads of its perception, worked out from its behaviors at load time, so
//! that the perception stage does only that work (seed 000 §1: a fish perceives what its
//! behaviors use). The matches are exhaustive so that a new primitive has to say what it reads.

use crate::perception::{GroupQueries, Reads};
use crate::species::{CondNode, Recipe, RecipeNode, Species};
use crate::steering::avoid::AvoidParams;
use crate::steering::recipe::group_query;

/// What species `sp` reads: whether it keeps individual percepts, the range of the bearings it
/// reads, and the neighborhood sums of its group rules.
pub fn reads(sp: &Species) -> Reads {
    let mut groups = GroupQueries::new();
    // A query past the list's capacity is folded from the kept percepts.
    let mut unlisted = false;
    let reach = sp.senses.query_radius();
    for r in sp.behaviors.iter().map(|b| &b.steer).chain(&sp.recipes) {
        walk(r, &mut |l| {
            if let Some(q) = group_query(l, reach) {
                groups.insert(q);
                unlisted |= groups.position(&q).is_none();
            }
        });
    }
    let kinds = reads_percepts(sp);
    Reads {
        percepts: unlisted || kinds > Kinds::None,
        agent_percepts: unlisted || kinds == Kinds::All,
        bearing_range: Some(bearing_range(sp)),
        groups,
        headings: sp.script.as_ref().is_some_and(|s| s.reads_heading()),
    }
}

fn walk(r: &RecipeNode, f: &mut impl FnMut(&Recipe)) {
    match r {
        RecipeNode::Leaf(l) => f(l),
        RecipeNode::Priority(v) => v.iter().for_each(|r| walk(r, f)),
        RecipeNode::Blend(v) => v.iter().for_each(|(_, _, r)| walk(r, f)),
        // Script-built steering composes the named recipes, walked with the behaviors.
        RecipeNode::Script(_) => {}
    }
}

/// What the species reads of individual percepts: nothing, obstacles only, or everything
/// (agents and food too).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Kinds {
    None,
    Obstacles,
    All,
}

/// Whether anything of the species reads individual percepts (rather than summaries and group
/// sums), and of what: scripts, native drives (predator distances) and contacts read agents and
/// food; so do the primitives and conditions below, except those that read obstacles only.
fn reads_percepts(sp: &Species) -> Kinds {
    use crate::perception::Category;
    use crate::species::Target;
    fn cond(c: &CondNode) -> Kinds {
        match c {
            CondNode::All(v) | CondNode::Any(v) => v.iter().map(cond).max().unwrap_or(Kinds::None),
            CondNode::Not(c) => cond(c),
            CondNode::Latch { on, off, .. } => cond(on).max(cond(off)),
            CondNode::ObstacleNear => Kinds::Obstacles,
            CondNode::EscapeDone | CondNode::TrafficNear => Kinds::All,
            // The bearing or elevation of the nearest of the category.
            CondNode::InSector(c, _) | CondNode::AtLevel(c, _) => nearest(*c),
            // Summaries, the agent's own state, or scripts (which keep percepts anyway).
            CondNode::Always
            | CondNode::Never
            | CondNode::Above(..)
            | CondNode::Below(..)
            | CondNode::Sees(_)
            | CondNode::Smells(_)
            | CondNode::Perceives(_)
            | CondNode::Within(..)
            | CondNode::Heard(_)
            | CondNode::TimeIn(_)
            | CondNode::Chance(_)
            | CondNode::NearBounds(_)
            | CondNode::Script(_)
            | CondNode::Contacted
            | CondNode::AtStation(_) => Kinds::None,
        }
    }
    fn nearest(c: Category) -> Kinds {
        if c == Category::Obstacle {
            Kinds::Obstacles
        } else {
            Kinds::All
        }
    }
    fn leaf(r: &Recipe) -> Kinds {
        match r {
            Recipe::AvoidStatic(_) | Recipe::PredictCollision(_) => Kinds::Obstacles,
            Recipe::AvoidDynamic(_) => Kinds::All,
            Recipe::Chase(c) => nearest(c.target),
            Recipe::Escape(e) | Recipe::EscapeMirror(e) => nearest(e.from),
            Recipe::Pursue(p) => nearest(p.target),
            Recipe::Seek(s) | Recipe::Flee(s) | Recipe::Arrive(s) => match s.target {
                Target::Nearest(c) => nearest(c),
                Target::Centroid(_) | Target::Point(_) | Target::Home | Target::Station => {
                    Kinds::None
                }
            },
            // Group sums, summaries, bounds, the plan or nothing.
            Recipe::Priority(_)
            | Recipe::Blend(_)
            | Recipe::Script(_)
            | Recipe::Contain(_)
            | Recipe::Separation(_)
            | Recipe::Alignment(_)
            | Recipe::Cohesion(_)
            | Recipe::Zones(_)
            | Recipe::Vicsek(_)
            | Recipe::Disperse(_)
            | Recipe::Wander(_)
            | Recipe::Cruise(_)
            | Recipe::Stop
            | Recipe::FollowPlan(_)
            | Recipe::HoldStation(_) => Kinds::None,
        }
    }
    if sp.script.is_some() || sp.drives.native || sp.behaviors.iter().any(|b| b.contact.is_some()) {
        return Kinds::All;
    }
    let mut kinds = Kinds::None;
    for r in sp.behaviors.iter().map(|b| &b.steer).chain(&sp.recipes) {
        walk(r, &mut |l| kinds = kinds.max(leaf(l)));
    }
    sp.behaviors
        .iter()
        .map(|b| cond(&b.when).max(cond(&b.done)).max(cond(&b.fail)))
        .fold(kinds, Kinds::max)
}

/// Distance within which a species' behaviors read the bearing and elevation of agent percepts
/// other than the nearest of their category: its dynamic-avoidance range (`TrafficNear`,
/// `AvoidDynamic`), 0 when it has neither. Obstacles and the nearest percept of each category
/// always get theirs. The matches are exhaustive so that a new primitive has to say what it
/// reads.
pub fn bearing_range(sp: &Species) -> f32 {
    fn of(p: &AvoidParams) -> f32 {
        p.range.unwrap_or(f32::INFINITY)
    }
    fn cond(c: &CondNode, sp: &Species) -> f32 {
        match c {
            CondNode::TrafficNear => of(&sp.avoid),
            CondNode::All(v) | CondNode::Any(v) => {
                v.iter().map(|c| cond(c, sp)).fold(0.0, f32::max)
            }
            CondNode::Not(c) => cond(c, sp),
            CondNode::Latch { on, off, .. } => cond(on, sp).max(cond(off, sp)),
            // Nearest percepts, obstacles or no percepts at all.
            CondNode::Always
            | CondNode::Never
            | CondNode::Above(..)
            | CondNode::Below(..)
            | CondNode::Sees(_)
            | CondNode::Smells(_)
            | CondNode::Perceives(_)
            | CondNode::Within(..)
            | CondNode::InSector(..)
            | CondNode::AtLevel(..)
            | CondNode::EscapeDone
            | CondNode::ObstacleNear
            | CondNode::Heard(_)
            | CondNode::TimeIn(_)
            | CondNode::Chance(_)
            | CondNode::NearBounds(_)
            | CondNode::Script(_)
            | CondNode::Contacted
            | CondNode::AtStation(_) => 0.0,
        }
    }
    fn leaf(r: &Recipe) -> f32 {
        match r {
            Recipe::AvoidDynamic(p) => of(p),
            // Nearest percepts, obstacles, neighbors' offsets and velocities, or nothing.
            Recipe::Priority(_)
            | Recipe::Blend(_)
            | Recipe::Script(_)
            | Recipe::AvoidStatic(_)
            | Recipe::PredictCollision(_)
            | Recipe::Contain(_)
            | Recipe::Chase(_)
            | Recipe::Escape(_)
            | Recipe::EscapeMirror(_)
            | Recipe::Pursue(_)
            | Recipe::Seek(_)
            | Recipe::Flee(_)
            | Recipe::Arrive(_)
            | Recipe::Separation(_)
            | Recipe::Alignment(_)
            | Recipe::Cohesion(_)
            | Recipe::Zones(_)
            | Recipe::Vicsek(_)
            | Recipe::Disperse(_)
            | Recipe::Wander(_)
            | Recipe::Cruise(_)
            | Recipe::Stop
            | Recipe::FollowPlan(_)
            | Recipe::HoldStation(_) => 0.0,
        }
    }
    fn recipe(r: &RecipeNode) -> f32 {
        match r {
            RecipeNode::Leaf(l) => leaf(l),
            RecipeNode::Priority(v) => v.iter().map(recipe).fold(0.0, f32::max),
            RecipeNode::Blend(v) => v.iter().map(|(_, _, r)| recipe(r)).fold(0.0, f32::max),
            // Script-built steering composes the named recipes, walked below.
            RecipeNode::Script(_) => 0.0,
        }
    }
    let behaviors = sp.behaviors.iter().map(|b| {
        cond(&b.when, sp)
            .max(cond(&b.done, sp))
            .max(cond(&b.fail, sp))
            .max(recipe(&b.steer))
    });
    let named = sp.recipes.iter().map(recipe);
    behaviors.chain(named).fold(0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::GroupQuery;
    use crate::scenario::normalize;
    use crate::species::load_species_str;
    use std::path::Path;

    fn species(text: &str) -> Result<Species, String> {
        let root = normalize(Path::new("."));
        load_species_str(Path::new("fish.ron"), text, &root, &Default::default())
            .map_err(|e| e.to_string())
    }

    fn flock(rules: &str, senses: &str) -> String {
        format!(
            r#"Species(
    name: "fish",
    script: None,
    drives: (native: false),
    senses: ({senses}),
    initial: "flock",
    behaviors: [Behavior(name: "flock", priority: 1, steer: Blend([{rules}]))],
)"#
        )
    }

    #[test]
    fn group_rules_beyond_the_folded_queries_still_find_their_neighbors() {
        // Nine separation radii: one more than the sums perception folds. The ninth falls back
        // to the kept percepts, so the species must keep them.
        let rules: Vec<String> = (1..=9)
            .map(|r| format!("(w: 1.0, steer: Separation(k: 1.0, radius: {r}.0))"))
            .collect();
        let sp = species(&flock(&rules.join(", "), "")).unwrap();
        let r = reads(&sp);
        for radius in 1..=9 {
            let q = GroupQuery::Separation {
                radius: radius as f32,
            };
            assert!(
                r.groups.position(&q).is_some() || r.percepts,
                "separation within {radius} m reads neither sums nor percepts"
            );
        }
    }

    #[test]
    fn sector_conditions_resolve_to_masks_and_keep_the_nearest_percepts() {
        use crate::perception::Category;
        let text = |when: &str, done: &str| {
            format!(
                r#"Species(
    name: "fish",
    script: None,
    drives: (native: false),
    initial: "rest",
    behaviors: [
        Behavior(name: "rest", priority: 2, steer: Stop),
        Behavior(name: "bolt", priority: 1, when: {when}, done: {done}, steer: Stop),
    ],
)"#
            )
        };
        let sp = species(&text(
            "InSector(Kin, [Rear, LeftFront])",
            "AtLevel(Kin, [Above, Below])",
        ))
        .unwrap();
        // LeftFront is bit 1 (2), Rear bit 5 (32): 34. Above is bit 0 (1), Below bit 2 (4): 5.
        assert_eq!(sp.behaviors[1].when, CondNode::InSector(Category::Kin, 34));
        assert_eq!(sp.behaviors[1].done, CondNode::AtLevel(Category::Kin, 5));
        let every = species(&text(
            "InSector(Kin, [Front, LeftFront, RightFront, LeftRear, RightRear, Rear])",
            "AtLevel(Kin, [Above, Level, Below])",
        ))
        .unwrap();
        assert_eq!(
            every.behaviors[1].when,
            CondNode::InSector(Category::Kin, 63)
        );
        assert_eq!(every.behaviors[1].done, CondNode::AtLevel(Category::Kin, 7));
        // They read the bearing of the nearest kin: the species keeps agent percepts.
        let r = reads(&sp);
        assert!(r.percepts && r.agent_percepts);
        assert_eq!(r.bearing_range, Some(0.0));
        // Strength reads the nearest distance of the summary: no percepts kept.
        let sp = species(&text("Above(Strength(Kin), 0.5)", "Never")).unwrap();
        assert!(!reads(&sp).percepts);
    }

    #[test]
    fn a_step_failing_on_a_percept_keeps_what_its_failure_reads() {
        // A sequence's steps end on `fail` too: what it reads counts as what `done` reads.
        let text = |fail: &str| {
            format!(
                r#"Species(
    name: "fish",
    script: None,
    drives: (native: false),
    avoid: (range: Some(2.5)),
    initial: "rest",
    behaviors: [
        Behavior(name: "rest", priority: 2, steer: Stop),
        Behavior(
            name: "patrol",
            priority: 1,
            when: TimeIn(5.0),
            sequence: [
                Behavior(name: "out", done: TimeIn(1.0), fail: {fail}, steer: Stop),
                Behavior(name: "back", done: TimeIn(1.0), steer: Stop),
            ],
        ),
    ],
)"#
            )
        };
        let plain = reads(&species(&text("TimeIn(3.0)")).unwrap());
        assert!(!plain.percepts);
        assert_eq!(plain.bearing_range, Some(0.0));
        let sector = reads(&species(&text("InSector(Kin, [Front])")).unwrap());
        assert!(sector.percepts && sector.agent_percepts);
        let traffic = reads(&species(&text("Not(TrafficNear)")).unwrap());
        assert!(traffic.agent_percepts);
        assert_eq!(traffic.bearing_range, Some(2.5));
    }

    #[test]
    fn mean_headings_are_read_only_by_a_script_that_names_them() {
        // The shipped reef fish's script reads no mean heading: its summaries keep none.
        let root = normalize(Path::new("behaviors"));
        let file = root.join("reef_fish.ron");
        let text = std::fs::read_to_string(&file).unwrap();
        let limits = Default::default();
        let reef = load_species_str(&file, &text, &root, &limits).unwrap();
        assert!(reef.script.is_some() && !reads(&reef).headings);
        // A script naming it, or a module it imports that does, reads it.
        let dir = tempfile::tempdir().unwrap();
        let heading = "fn h(c) { c.mean_heading.x }";
        std::fs::write(dir.path().join("m.rhai"), heading).unwrap();
        let scripts = [
            (heading, true),
            ("import \"m\" as m;\nfn h(c) { m::h(c) }", true),
            ("fn h(c) { c.mean_velocity.x }", false),
        ];
        for (script, named) in scripts {
            std::fs::write(dir.path().join("s.rhai"), script).unwrap();
            let file = dir.path().join("fish.ron");
            let text = flock("(w: 1.0, steer: Cohesion(k: 1.0))", "")
                .replace("script: None", "script: Some(\"s.rhai\")");
            let sp = load_species_str(&file, &text, dir.path(), &limits).unwrap();
            assert_eq!(reads(&sp).headings, named, "{script}");
        }
    }

    #[test]
    fn too_few_percept_slots_are_refused() {
        let rule = "(w: 1.0, steer: Separation(k: 1.0, radius: 1.0))";
        for n in [1, 5] {
            let e = species(&flock(rule, &format!("max_percepts: {n}")))
                .err()
                .unwrap_or_else(|| panic!("max_percepts {n} accepted"));
            assert!(e.contains("max_percepts"), "{e}");
        }
        assert!(species(&flock(rule, "max_percepts: 6")).is_ok());
    }

    #[test]
    fn a_kin_neighborhood_bound_outside_its_range_is_refused() {
        let rule = "(w: 1.0, steer: Separation(k: 1.0, radius: 1.0))";
        for n in ["Some(0)", "Some(4097)"] {
            let e = species(&flock(rule, &format!("neighbors: {n}")))
                .err()
                .unwrap_or_else(|| panic!("neighbors {n} accepted"));
            assert!(e.contains("`neighbors` must be between 1 and 4096"), "{e}");
        }
        assert!(species(&flock(rule, "neighbors: Some(7)")).is_ok());
    }
}
