//! The scenario's numbers, checked at load: finite coordinates within
//! [`MAX_COORD`](crate::load::numbers::MAX_COORD), obstacle shapes, food, agent counts within
//! [`MAX_AGENTS`](crate::load::numbers::MAX_AGENTS), event times, squads' planning constants
//! (seed 004). Part of [`super::validate`].

use super::*;
use crate::load::numbers::{MAX_AGENTS, MAX_COORD, MAX_FOOD};
use crate::load::{Diagnostic, NumberCheck};
use crate::species::Draw;
use crate::world::Aabb;
use std::path::Path;

/// The scenario's numbers outside what `Scenario::load_str` checks by name: finite coordinates,
/// obstacle shapes, food, counts within [`MAX_AGENTS`], event times, squads.
pub(super) fn scenario_numbers(file: &Path, text: &str, def: &ScenarioDef) -> Vec<Diagnostic> {
    let mut n = NumberCheck::new(file, text);
    let aabb = |n: &mut NumberCheck, key: &str, b: &Aabb| {
        n.enter(key);
        n.point("min", &b.min.to_array()) & n.point("max", &b.max.to_array())
    };
    aabb(&mut n, "bounds", &def.bounds);
    n.from = 0;
    n.point("current", &def.current.to_array());
    n.from = 0;
    n.enter("obstacles");
    for o in &def.obstacles {
        match *o {
            ObstacleDef::Sphere { center, radius } => {
                n.enter("Sphere");
                n.point("center", &center.to_array());
                n.range("radius", radius, 0.0, MAX_COORD);
            }
            ObstacleDef::Box { min, max } => {
                n.enter("Box");
                if n.point("min", &min.to_array()) & n.point("max", &max.to_array())
                    && min.cmpgt(max).any()
                {
                    n.error(
                        "min",
                        format!(
                            "`Box`: `min` {:?} must not exceed `max` {:?} on any axis",
                            min.to_array(),
                            max.to_array()
                        ),
                    );
                }
            }
            ObstacleDef::Cylinder {
                base,
                radius,
                height,
            } => {
                n.enter("Cylinder");
                n.point("base", &base.to_array());
                n.range("radius", radius, 0.0, MAX_COORD);
                n.range("height", height, 0.0, MAX_COORD);
            }
        }
    }
    // Food: the respawn loop adds whole items per tick, so the rate is bounded by what the
    // world may hold.
    n.from = 0;
    n.enter("food");
    let f = &def.food;
    n.range(
        "respawn_per_second",
        f.respawn_per_second,
        0.0,
        MAX_FOOD as f32,
    );
    n.count(
        "initial",
        u64::from(f.initial),
        MAX_FOOD,
        "food items a scenario places",
    );
    n.count(
        "max",
        u64::from(f.max),
        MAX_FOOD,
        "food items a world holds",
    );
    if let Some(r) = &f.region {
        aabb(&mut n, "region", r);
    }
    // Agents: every group, timed spawn and squad together.
    let mut total: u64 = 0;
    let group = |n: &mut NumberCheck, g: &SpawnGroupDef, total: &mut u64| {
        n.enter("count");
        let count = u64::try_from(g.count).unwrap_or(0);
        *total = total.saturating_add(count);
        if !n.count(
            "count",
            count,
            MAX_AGENTS,
            "agents a scenario creates in all",
        ) {
            return;
        }
        if *total > MAX_AGENTS {
            n.error(
                "count",
                format!("the groups so far create {total} agents: a scenario creates at most {MAX_AGENTS} agents in all"),
            );
        }
        aabb(n, "region", &g.region);
        match g.heading {
            HeadingDef::Yaw(y) => {
                n.finite("Yaw", y);
            }
            HeadingDef::Toward(t) => {
                n.point("Toward", &t.to_array());
            }
            HeadingDef::Random => {}
        }
        let d = &g.drives;
        for (key, v) in [
            ("hunger", d.hunger),
            ("libido", d.libido),
            ("fear", d.fear),
            ("fatigue", d.fatigue),
        ] {
            match v {
                Some(Draw::Fixed(x)) => {
                    n.finite(key, x);
                }
                Some(Draw::Uniform(lo, hi)) if n.finite(key, lo) & n.finite(key, hi) && lo > hi => {
                    n.error(key, format!("`{key}`: `Uniform(lo, hi)` needs lo ≤ hi"));
                }
                _ => {}
            }
        }
    };
    n.from = 0;
    n.enter("groups");
    for g in &def.groups {
        group(&mut n, g, &mut total);
    }
    n.from = 0;
    n.enter("events");
    for e in &def.events {
        n.enter("at");
        n.non_negative("at", e.at);
        match &e.action {
            EventAction::Spawn(g) => group(&mut n, g, &mut total),
            EventAction::DropFood { count, region } => {
                n.enter("DropFood");
                n.count(
                    "count",
                    u64::from(*count),
                    MAX_FOOD,
                    "food items a scenario places",
                );
                aabb(&mut n, "region", region);
            }
            EventAction::SetCurrent(c) => {
                n.enter("SetCurrent");
                n.point("SetCurrent", &c.to_array());
            }
            EventAction::RemoveObstacle(_) => {}
        }
    }
    n.from = 0;
    n.enter("squads");
    for q in &def.squads {
        n.enter("count");
        total = total.saturating_add(u64::from(q.count));
        if n.count(
            "count",
            u64::from(q.count),
            MAX_AGENTS,
            "agents a scenario creates in all",
        ) && total > MAX_AGENTS
        {
            n.error(
                "count",
                format!("the groups and squads so far create {total} agents: a scenario creates at most {MAX_AGENTS} agents in all"),
            );
        }
        n.point("start", &[q.start.0, q.start.1]);
        n.point("goal", &[q.goal.0, q.goal.1]);
        check_planning(&mut n, &q.planning);
    }
    n.diags
}

/// A squad's `planning` constants (seed 004): `relax_step` and each class's `k1` in (0, 1], each
/// `k2` in [0, 1], `fm_broken` finite and ≥ 1 (one follower fitting costs 1), `search_weight` in
/// [1, 10].
fn check_planning(n: &mut NumberCheck<'_>, p: &crate::formation::PlanningParams) {
    let here = n.from;
    n.enter("planning");
    let unit = |n: &mut NumberCheck<'_>, key: &str, v: f32| {
        if !(v > 0.0 && v <= 1.0) {
            n.error(key, format!("`{key}` must be a number in (0, 1], not {v}"));
        }
    };
    unit(n, "relax_step", p.relax_step);
    n.range("fm_broken", p.fm_broken, 1.0, f32::MAX);
    n.range(
        "search_weight",
        p.search_weight,
        1.0,
        crate::formation::astar::MAX_SEARCH_WEIGHT,
    );
    let inside = n.from;
    for (class, f) in [
        ("must_keep", p.must_keep),
        ("may_change_rarely", p.may_change_rarely),
        ("shortest_first", p.shortest_first),
    ] {
        n.from = inside;
        n.enter(class);
        unit(n, "k1", f.k1);
        n.range("k2", f.k2, 0.0, 1.0);
    }
    n.from = here;
}
