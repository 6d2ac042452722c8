//! Scenario expectations (`expect: [...]` in a scenario file), checked over a run.
//!
//! Not a tick stage: a layer above the scenario [`super::Run`]. A [`Tracker`] is built once from
//! the validated scenario (names resolved, problems located in the scenario file), fed the world
//! after every tick ([`Tracker::observe`]) and asked for one [`Verdict`] per expectation at the end
//! ([`Tracker::finish`]). `shoal test` runs scenario files this way. Run-health bounds
//! (`MaxFrozen`, `MaxSwitchRate`, …) are judged on the report of a [`Monitor`] the tracker owns
//! when the scenario declares any.

use super::bounds::Bound;
use super::{Expectation, Scenario};
use crate::events::Event;
use crate::health::{Health, Monitor};
use crate::load::{locate, Diagnostic, Diagnostics};
use crate::tick::Pipeline;
use crate::world::World;
use glam::Vec3;

/// The outcome of one expectation.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// What was expected, in words.
    pub expected: String,
    /// Whether it held.
    pub passed: bool,
    /// What happened, in words.
    pub observed: String,
}

/// One expectation with its names resolved and what has been seen of it so far.
#[derive(Debug, Clone)]
enum Check {
    Share {
        species: usize,
        /// The behavior and, for a composed one, every part inside it: an agent in any of them
        /// counts.
        members: Vec<u16>,
        fraction: f32,
        from: f32,
        to: f32,
        /// Best share seen in the window and when (s).
        best: Option<(f32, f32)>,
    },
    MinCatches(u64),
    MinMeals(u64),
    /// Catches by one species' agents: (species, at least, seen so far).
    SpeciesCatches(usize, u64, u64),
    /// Meals by one species' agents: (species, at least, seen so far).
    SpeciesMeals(usize, u64, u64),
    MinAlive(usize, u64),
    MaxAlive(usize, u64),
    /// Catches (or meals, when `catches` is false) by one named group's agents.
    GroupCount {
        group: String,
        at_least: u64,
        catches: bool,
        seen: u64,
    },
    /// Agents of one named group alive at the end: at least (`min`) or at most this many.
    GroupAlive {
        group: String,
        bound: u64,
        min: bool,
    },
    MinPolarization(usize, f32),
    NoScriptErrors {
        first: Vec<String>,
    },
    /// A bound on a run-health figure of a species.
    Health(usize, Bound),
}

/// Follows a run and judges the scenario's expectations.
#[derive(Debug, Clone)]
pub struct Tracker {
    checks: Vec<(String, Check)>,
    species: Vec<String>,
    duration: f32,
    last_time: f32,
    /// Follows the run's health when a check needs it.
    monitor: Option<Monitor>,
    /// The run's spawned groups, as last seen by [`Tracker::observe_run`].
    spans: Vec<super::GroupSpan>,
}

fn counted(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

fn pct(x: f32) -> String {
    format!("{:.0}%", x * 100.0)
}

impl Tracker {
    /// Resolves the expectations of `scenario`; unknown species or behavior names, fractions
    /// and polarizations outside [0, 1] and times that are not finite and ≥ 0 are located errors
    /// in the scenario file.
    pub fn new(scenario: &Scenario) -> Result<Tracker, Diagnostics> {
        let text = &scenario.text;
        let file = &scenario.file;
        let start = locate(text, "expect", 0).map_or(0, |x| x.2);
        let mut diags = Vec::new();
        let mut cursor = start;
        let mut error = |needle: &str, cursor: usize, msg: String| {
            let (l, c, _) = locate(text, needle, cursor)
                .or_else(|| locate(text, needle, 0))
                .unwrap_or((0, 0, 0));
            diags.push(Diagnostic::new(file, l, c, msg, Some(text)));
        };
        let set = &scenario.species;
        let names: Vec<String> = set.species.iter().map(|s| s.name.clone()).collect();
        let species_of = |name: &str, cursor: usize, error: &mut dyn FnMut(&str, usize, String)| {
            let i = set.index_of(name);
            if i.is_none() {
                error(
                    &format!("\"{name}\""),
                    cursor,
                    format!(
                        "unknown species \"{name}\" in `expect`{}: the scenario loads {}",
                        crate::load::did_you_mean(name, names.iter().map(String::as_str)),
                        names.join(", ")
                    ),
                );
            }
            i
        };
        // Group names: the groups at t = 0 and those timed events spawn.
        let mut groups: Vec<&str> = Vec::new();
        let timed = scenario.def.events.iter().filter_map(|e| match &e.action {
            super::EventAction::Spawn(g) => Some(g),
            _ => None,
        });
        for g in scenario.def.groups.iter().chain(timed) {
            if !groups.contains(&g.group_name()) {
                groups.push(g.group_name());
            }
        }
        let group_of = |name: &str, cursor: usize, error: &mut dyn FnMut(&str, usize, String)| {
            let known = groups.contains(&name);
            if !known {
                let listed = if groups.is_empty() {
                    "the scenario has no groups".to_string()
                } else {
                    format!("the scenario's groups are {}", groups.join(", "))
                };
                error(
                    &format!("\"{name}\""),
                    cursor,
                    format!(
                        "unknown group \"{name}\" in `expect`{}: {listed} (a group is named by \
                         its `name:`, else by its species)",
                        crate::load::did_you_mean(name, groups.iter().copied()),
                    ),
                );
            }
            known
        };
        let mut checks = Vec::new();
        for e in &scenario.def.expect {
            let variant = match e {
                Expectation::BehaviorShare { .. } => "BehaviorShare",
                Expectation::MinCatches(_) => "MinCatches",
                Expectation::MinMeals(_) => "MinMeals",
                Expectation::SpeciesCatches(..) => "SpeciesCatches",
                Expectation::SpeciesMeals(..) => "SpeciesMeals",
                Expectation::GroupCatches(..) => "GroupCatches",
                Expectation::GroupMeals(..) => "GroupMeals",
                Expectation::GroupMinAlive(..) => "GroupMinAlive",
                Expectation::GroupMaxAlive(..) => "GroupMaxAlive",
                Expectation::MinAlive(..) => "MinAlive",
                Expectation::MaxAlive(..) => "MaxAlive",
                Expectation::MinPolarization(..) => "MinPolarization",
                Expectation::NoScriptErrors => "NoScriptErrors",
                Expectation::MaxFrozen(..) => "MaxFrozen",
                Expectation::MaxSwitchRate(..) => "MaxSwitchRate",
                Expectation::MaxPitchLimitShare(..) => "MaxPitchLimitShare",
                Expectation::MaxShortEpisodes(..) => "MaxShortEpisodes",
                Expectation::MaxTurningWaste(..) => "MaxTurningWaste",
                Expectation::MaxInterpenetration(..) => "MaxInterpenetration",
                Expectation::MaxObstaclePenetration(..) => "MaxObstaclePenetration",
            };
            cursor = locate(text, variant, cursor).map_or(cursor, |x| x.2);
            let check = match e {
                Expectation::BehaviorShare {
                    species,
                    behavior,
                    fraction,
                    after,
                    within,
                } => {
                    if !(0.0..=1.0).contains(fraction) {
                        error(
                            "fraction",
                            cursor,
                            format!("`fraction` must be between 0 and 1, not {fraction}"),
                        );
                    }
                    // Finite too: `after + within` bounds the window, and an infinite one never
                    // closes.
                    let seconds = |x: f32| x.is_finite() && x >= 0.0;
                    if !(seconds(*within) && seconds(*after)) {
                        error(
                            "within",
                            cursor,
                            format!(
                                "`after` and `within` must be finite numbers of seconds ≥ 0, \
                                 not {after} and {within}"
                            ),
                        );
                    }
                    let s = species_of(species, cursor, &mut error);
                    let b = s.and_then(|s| {
                        let sp = &set.species[s];
                        let b = sp.behavior_index(behavior);
                        if b.is_none() {
                            let known: Vec<&str> =
                                sp.behaviors.iter().map(|b| &*b.name).collect();
                            error(
                                &format!("\"{behavior}\""),
                                cursor,
                                format!(
                                    "species \"{species}\" has no behavior \"{behavior}\": expected one of {}",
                                    known.join(", ")
                                ),
                            );
                        }
                        b
                    });
                    let (Some(s), Some(b)) = (s, b) else {
                        continue;
                    };
                    (
                        format!(
                            "at least {} of {species} in `{behavior}` at some moment between {after} s and {} s",
                            pct(*fraction),
                            after + within
                        ),
                        Check::Share {
                            species: s,
                            members: (0..set.species[s].behaviors.len() as u16)
                                .filter(|&i| {
                                    crate::species::validate::ancestors(
                                        &set.species[s].behaviors,
                                        i,
                                    )
                                    .any(|a| a == b)
                                })
                                .collect(),
                            fraction: *fraction,
                            from: *after,
                            to: after + within,
                            best: None,
                        },
                    )
                }
                Expectation::MinCatches(n) => (
                    format!("at least {}", counted(*n, "catch", "catches")),
                    Check::MinCatches(*n),
                ),
                Expectation::MinMeals(n) => (
                    format!("at least {}", counted(*n, "meal", "meals")),
                    Check::MinMeals(*n),
                ),
                Expectation::SpeciesCatches(sp, n) => {
                    let Some(s) = species_of(sp, cursor, &mut error) else {
                        continue;
                    };
                    (
                        format!("{sp}: at least {}", counted(*n, "catch", "catches")),
                        Check::SpeciesCatches(s, *n, 0),
                    )
                }
                Expectation::SpeciesMeals(sp, n) => {
                    let Some(s) = species_of(sp, cursor, &mut error) else {
                        continue;
                    };
                    (
                        format!("{sp}: at least {}", counted(*n, "meal", "meals")),
                        Check::SpeciesMeals(s, *n, 0),
                    )
                }
                Expectation::GroupCatches(g, n) | Expectation::GroupMeals(g, n) => {
                    if !group_of(g, cursor, &mut error) {
                        continue;
                    }
                    let catches = matches!(e, Expectation::GroupCatches(..));
                    let what = if catches {
                        counted(*n, "catch", "catches")
                    } else {
                        counted(*n, "meal", "meals")
                    };
                    (
                        format!("group {g}: at least {what}"),
                        Check::GroupCount {
                            group: g.clone(),
                            at_least: *n,
                            catches,
                            seen: 0,
                        },
                    )
                }
                Expectation::GroupMinAlive(g, n) | Expectation::GroupMaxAlive(g, n) => {
                    if !group_of(g, cursor, &mut error) {
                        continue;
                    }
                    let min = matches!(e, Expectation::GroupMinAlive(..));
                    let most = if min { "least" } else { "most" };
                    (
                        format!("at {most} {n} of group {g} alive at the end"),
                        Check::GroupAlive {
                            group: g.clone(),
                            bound: *n,
                            min,
                        },
                    )
                }
                Expectation::MinAlive(sp, n) => {
                    let Some(s) = species_of(sp, cursor, &mut error) else {
                        continue;
                    };
                    (
                        format!("at least {n} {sp} alive at the end"),
                        Check::MinAlive(s, *n),
                    )
                }
                Expectation::MaxAlive(sp, n) => {
                    let Some(s) = species_of(sp, cursor, &mut error) else {
                        continue;
                    };
                    (
                        format!("at most {n} {sp} alive at the end"),
                        Check::MaxAlive(s, *n),
                    )
                }
                Expectation::MinPolarization(sp, p) => {
                    // Polarization is |mean heading|: a NaN bound would fail every run, one
                    // above 1 could never be met.
                    if !(0.0..=1.0).contains(p) {
                        error(
                            variant,
                            cursor,
                            format!(
                                "`MinPolarization` expects a polarization between 0 and 1, not {p}"
                            ),
                        );
                    }
                    let Some(s) = species_of(sp, cursor, &mut error) else {
                        continue;
                    };
                    (
                        format!("polarization of {sp} at least {p} at the end"),
                        Check::MinPolarization(s, *p),
                    )
                }
                Expectation::NoScriptErrors => (
                    "no script errors".to_string(),
                    Check::NoScriptErrors { first: Vec::new() },
                ),
                Expectation::MaxFrozen(sp, n) | Expectation::MaxObstaclePenetration(sp, n) => {
                    let bound = match e {
                        Expectation::MaxFrozen(..) => Bound::Frozen(*n),
                        _ => Bound::ObstaclePenetration(*n),
                    };
                    let Some(s) = species_of(sp, cursor, &mut error) else {
                        continue;
                    };
                    (bound.expected(sp), Check::Health(s, bound))
                }
                Expectation::MaxSwitchRate(sp, x)
                | Expectation::MaxPitchLimitShare(sp, x)
                | Expectation::MaxShortEpisodes(sp, x)
                | Expectation::MaxTurningWaste(sp, x)
                | Expectation::MaxInterpenetration(sp, x) => {
                    let (bound, ok, what) = match e {
                        Expectation::MaxSwitchRate(..) => (
                            Bound::SwitchRate(*x),
                            x.is_finite() && *x >= 0.0,
                            "a rate ≥ 0 (switches per agent per second)",
                        ),
                        Expectation::MaxTurningWaste(..) => (
                            Bound::TurningWaste(*x),
                            x.is_finite() && *x >= 1.0,
                            "a ratio ≥ 1 (turning can never be less than the heading change)",
                        ),
                        Expectation::MaxPitchLimitShare(..) => (
                            Bound::PitchLimitShare(*x),
                            (0.0..=1.0).contains(x),
                            "a fraction between 0 and 1",
                        ),
                        Expectation::MaxShortEpisodes(..) => (
                            Bound::ShortEpisodes(*x),
                            (0.0..=1.0).contains(x),
                            "a fraction between 0 and 1",
                        ),
                        _ => (
                            Bound::Interpenetration(*x),
                            (0.0..=1.0).contains(x),
                            "a fraction between 0 and 1",
                        ),
                    };
                    if !ok {
                        error(
                            variant,
                            cursor,
                            format!("`{variant}` expects {what}, not {x}"),
                        );
                    }
                    let Some(s) = species_of(sp, cursor, &mut error) else {
                        continue;
                    };
                    (bound.expected(sp), Check::Health(s, bound))
                }
            };
            checks.push(check);
            cursor += 1;
        }
        if !diags.is_empty() {
            return Err(Diagnostics(diags));
        }
        let monitor = checks
            .iter()
            .any(|(_, c)| matches!(c, Check::Health(..)))
            .then(|| Monitor::new(set, scenario.def.dt));
        Ok(Tracker {
            checks,
            species: names,
            duration: scenario.def.duration,
            last_time: 0.0,
            monitor,
            spans: Vec::new(),
        })
    }

    /// Whether the scenario declares any expectation.
    pub fn is_empty(&self) -> bool {
        self.checks.is_empty()
    }

    /// [`Tracker::observe`] for a scenario [`Run`](super::Run), which also follows the groups
    /// it has spawned (group expectations need it: `observe` alone sees no group).
    pub fn observe_run(&mut self, run: &super::Run) {
        if self.spans.len() != run.group_spans.len() {
            self.spans.clone_from(&run.group_spans);
        }
        self.observe(&run.sim.world, &run.sim.pipeline);
    }

    /// Whether agent `id` belongs to the group named `group`.
    fn in_group(&self, group: &str, id: u32) -> bool {
        self.spans
            .iter()
            .any(|s| s.name == group && s.ids.contains(&id))
    }

    /// Looks at the world after a tick (and once before the first, for windows starting at 0)
    /// and at the events of that tick.
    pub fn observe(&mut self, world: &World, pipeline: &Pipeline) {
        let t = world.time() as f32;
        let half = world.dt * 0.5;
        self.last_time = t;
        if let Some(m) = self.monitor.as_mut() {
            m.observe(world, pipeline);
        }
        // Catches and meals by group (the eater is alive after its tick: only prey is removed).
        let mut by_group = Vec::new();
        for (i, (_, c)) in self.checks.iter().enumerate() {
            if let Check::GroupCount { group, catches, .. } = c {
                let n = pipeline
                    .events
                    .iter()
                    .filter(|e| match e {
                        Event::Catch { agent, .. } => *catches && self.in_group(group, agent.0),
                        Event::Meal { agent, .. } => !*catches && self.in_group(group, agent.0),
                        _ => false,
                    })
                    .count() as u64;
                by_group.push((i, n));
            }
        }
        for (i, n) in by_group {
            if let Check::GroupCount { seen, .. } = &mut self.checks[i].1 {
                *seen += n;
            }
        }
        for (_, c) in &mut self.checks {
            match c {
                Check::Share {
                    species,
                    members,
                    from,
                    to,
                    best,
                    ..
                } if t >= *from - half && t <= *to + half => {
                    let (mut n, mut k) = (0usize, 0usize);
                    for a in &world.agents {
                        if a.species.0 as usize == *species {
                            n += 1;
                            if members.contains(&a.mind.current) {
                                k += 1;
                            }
                        }
                    }
                    if n > 0 {
                        let share = k as f32 / n as f32;
                        if best.is_none_or(|(b, _)| share > b) {
                            *best = Some((share, t));
                        }
                    }
                }
                Check::SpeciesCatches(species, _, seen) => {
                    count_by_species(world, pipeline, *species, seen, true)
                }
                Check::SpeciesMeals(species, _, seen) => {
                    count_by_species(world, pipeline, *species, seen, false)
                }
                Check::NoScriptErrors { first } => {
                    for e in &pipeline.events {
                        if let Event::ScriptError { message, .. } = e {
                            if first.len() < 3 {
                                first.push(message.clone());
                            }
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// One verdict per expectation, in the order the scenario lists them.
    pub fn finish(&self, world: &World, pipeline: &Pipeline) -> Vec<Verdict> {
        let alive = |s: usize| {
            world
                .agents
                .iter()
                .filter(|a| a.species.0 as usize == s)
                .count() as u64
        };
        let stats = &pipeline.stats;
        let report: Option<Health> = self.monitor.as_ref().map(Monitor::report);
        self.checks
            .iter()
            .map(|(expected, c)| {
                let (passed, observed) = match c {
                    Check::Share {
                        species,
                        fraction,
                        from,
                        best,
                        ..
                    } => match best {
                        Some((b, t)) => (
                            *b >= *fraction,
                            format!("highest share {} (at {t:.2} s)", pct(*b)),
                        ),
                        None if self.last_time + 1e-6 < *from => (
                            false,
                            format!(
                                "the run ended at {:.2} s, before the window (duration {} s)",
                                self.last_time, self.duration
                            ),
                        ),
                        None => (
                            false,
                            format!("no {} alive during the window", self.species[*species]),
                        ),
                    },
                    Check::MinCatches(n) => (
                        stats.catches >= *n,
                        counted(stats.catches, "catch", "catches"),
                    ),
                    Check::MinMeals(n) => {
                        (stats.meals >= *n, counted(stats.meals, "meal", "meals"))
                    }
                    Check::SpeciesCatches(_, n, seen) => {
                        (*seen >= *n, counted(*seen, "catch", "catches"))
                    }
                    Check::SpeciesMeals(_, n, seen) => {
                        (*seen >= *n, counted(*seen, "meal", "meals"))
                    }
                    Check::MinAlive(s, n) => {
                        let a = alive(*s);
                        (a >= *n, format!("{a} alive"))
                    }
                    Check::MaxAlive(s, n) => {
                        let a = alive(*s);
                        (a <= *n, format!("{a} alive"))
                    }
                    Check::GroupCount {
                        at_least,
                        catches,
                        seen,
                        ..
                    } => (
                        *seen >= *at_least,
                        if *catches {
                            counted(*seen, "catch", "catches")
                        } else {
                            counted(*seen, "meal", "meals")
                        },
                    ),
                    Check::GroupAlive { group, bound, min } => {
                        let a = world
                            .agents
                            .iter()
                            .filter(|a| self.in_group(group, a.id.0))
                            .count() as u64;
                        let passed = if *min { a >= *bound } else { a <= *bound };
                        (passed, format!("{a} alive"))
                    }
                    Check::MinPolarization(s, p) => {
                        let (sum, n) = world
                            .agents
                            .iter()
                            .filter(|a| a.species.0 as usize == *s)
                            .fold((Vec3::ZERO, 0usize), |(v, n), a| (v + a.forward(), n + 1));
                        if n == 0 {
                            (false, format!("no {} alive", self.species[*s]))
                        } else {
                            let pol = sum.length() / n as f32;
                            (pol >= *p, format!("polarization {pol:.3}"))
                        }
                    }
                    Check::NoScriptErrors { first } => match first.first() {
                        None if stats.script_errors == 0 => (true, "none".to_string()),
                        None => (
                            false,
                            format!("{} failed script calls", stats.script_errors),
                        ),
                        Some(m) => (
                            false,
                            format!("{} failed script calls, first: {m}", stats.script_errors),
                        ),
                    },
                    Check::Health(s, bound) => {
                        match report.as_ref().and_then(|h| h.species.get(*s)) {
                            Some(figures) => bound.judge(figures),
                            None => (false, "no health figures".to_string()),
                        }
                    }
                };
                Verdict {
                    expected: expected.clone(),
                    passed,
                    observed,
                }
            })
            .collect()
    }
}

/// Adds to `seen` this tick's catches (or meals) by agents of `species`.
fn count_by_species(
    world: &World,
    pipeline: &Pipeline,
    species: usize,
    seen: &mut u64,
    catches: bool,
) {
    for e in &pipeline.events {
        // The eater is alive after its tick (only the prey is removed).
        let by = match e {
            Event::Catch { agent, .. } if catches => *agent,
            Event::Meal { agent, .. } if !catches => *agent,
            _ => continue,
        };
        if world
            .agent(by)
            .is_some_and(|a| a.species.0 as usize == species)
        {
            *seen += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{Overrides, Run};
    use std::path::Path;

    /// A scenario of a dozen hungry reef fish among food, with these expectations.
    fn scenario(expect: &str) -> Result<Scenario, Diagnostics> {
        let text = format!(
            r#"Scenario(
    seed: 5,
    duration: 3.0,
    bounds: (min: (-15.0, 0.0, -15.0), max: (15.0, 12.0, 15.0)),
    species: ["reef_fish"],
    food: (initial: 30),
    groups: [(species: "reef_fish", count: 12, region: (min: (-10.0, 2.0, -10.0), max: (10.0, 10.0, 10.0)),
              drives: (hunger: Some(Fixed(0.9))))],
    expect: [
{expect}
    ],
)"#
        );
        Scenario::load_str(Path::new("scenarios/health.ron"), &text)
    }

    fn verdicts(expect: &str) -> Vec<Verdict> {
        run_verdicts(scenario(expect).unwrap_or_else(|d| panic!("{d}")))
    }

    #[test]
    fn species_meals_count_only_that_species_eating() {
        let v = verdicts(
            "MinMeals(1), SpeciesMeals(\"reef_fish\", 1), SpeciesMeals(\"reef_fish\", 100000)",
        );
        assert!(v[0].passed, "{v:?}");
        // One species eats here, so its count is the run's.
        assert_eq!(v[1].observed, v[0].observed, "{v:?}");
        assert!(
            v[1].passed && v[1].expected.starts_with("reef_fish: at least 1 meal"),
            "{v:?}"
        );
        assert!(!v[2].passed, "{v:?}");
        let err = scenario("SpeciesCatches(\"tuna\", 1)")
            .and_then(|s| Tracker::new(&s))
            .unwrap_err();
        assert!(
            err.to_string().contains("unknown species \"tuna\""),
            "{err}"
        );
    }

    #[test]
    fn health_bounds_say_the_figure_and_the_bound() {
        let v = verdicts(
            r#"        MaxSwitchRate("reef_fish", 0.0001),
        MaxTurningWaste("reef_fish", 1000.0),
        MaxFrozen("reef_fish", 12),
        MaxPitchLimitShare("reef_fish", 1.0),
        MaxShortEpisodes("reef_fish", 1.0),
        MaxInterpenetration("reef_fish", 1.0),
        MaxObstaclePenetration("reef_fish", 1000000),"#,
        );
        assert_eq!(v.len(), 7);
        // Hungry fish among food switch at least once in 3 s: far above 0.0001 per second.
        assert!(!v[0].passed, "{v:?}");
        assert_eq!(
            v[0].expected,
            "at most 0.0001 behavior switches per reef_fish per second"
        );
        assert!(
            v[0].observed
                .contains("switches per agent per second (bound 0.0001)"),
            "{}",
            v[0].observed
        );
        for x in &v[1..] {
            assert!(x.passed, "{x:?}");
            assert!(x.observed.contains("bound"), "{x:?}");
        }
    }

    #[test]
    fn health_bounds_name_known_species_and_take_sensible_values() {
        let sc = scenario(
            r#"        MaxSwitchRate("reef_fsh", 0.5),
        MaxShortEpisodes("reef_fish", 1.5),
        MaxTurningWaste("reef_fish", 0.5),"#,
        );
        // Loading the scenario resolves its expectations, so `check` reports them.
        let d = sc.unwrap_err().to_string();
        assert!(
            d.contains("health.ron:10:23: unknown species \"reef_fsh\" in `expect`"),
            "{d}"
        );
        assert!(
            d.contains("`MaxShortEpisodes` expects a fraction between 0 and 1, not 1.5"),
            "{d}"
        );
        assert!(d.contains("`MaxTurningWaste` expects a ratio ≥ 1"), "{d}");
    }

    /// Two named groups of six reef fish, only the `hungry` one hungry, among food.
    fn grouped(expect: &str) -> Result<Scenario, Diagnostics> {
        let text = format!(
            r#"Scenario(
    seed: 5,
    duration: 3.0,
    bounds: (min: (-15.0, 0.0, -15.0), max: (15.0, 12.0, 15.0)),
    species: ["reef_fish"],
    food: (initial: 30),
    groups: [
        (species: "reef_fish", name: "hungry", count: 6, region: (min: (-10.0, 2.0, -10.0), max: (10.0, 10.0, 10.0)),
         drives: (hunger: Fixed(0.9))),
        (species: "reef_fish", name: "sated", count: 6, region: (min: (-10.0, 2.0, -10.0), max: (10.0, 10.0, 10.0))),
    ],
    expect: [
{expect}
    ],
)"#
        );
        Scenario::load_str(Path::new("scenarios/groups.ron"), &text)
    }

    /// Runs `sc` to its end and judges its expectations.
    fn run_verdicts(sc: Scenario) -> Vec<Verdict> {
        let mut tracker = Tracker::new(&sc).unwrap_or_else(|d| panic!("{d}"));
        let mut run = Run::new(sc, Overrides::default());
        tracker.observe_run(&run);
        while !run.finished() {
            run.step();
            tracker.observe_run(&run);
        }
        tracker.finish(&run.sim.world, &run.sim.pipeline)
    }

    #[test]
    fn group_expectations_count_only_that_groups_agents() {
        let sc = grouped(
            r#"        MinMeals(1), GroupMeals("hungry", 1), GroupMeals("sated", 0),
        GroupMeals("hungry", 100000), GroupCatches("hungry", 0), GroupCatches("hungry", 1),
        GroupMinAlive("sated", 6), GroupMinAlive("sated", 7), GroupMaxAlive("hungry", 6),
        GroupMaxAlive("hungry", 5),"#,
        )
        .unwrap_or_else(|d| panic!("{d}"));
        let v = run_verdicts(sc);
        let passed: Vec<bool> = v.iter().map(|v| v.passed).collect();
        assert_eq!(
            passed,
            [true, true, true, false, true, false, true, false, true, false],
            "{v:?}"
        );
        assert_eq!(v[1].expected, "group hungry: at least 1 meal");
        assert_eq!(v[6].expected, "at least 6 of group sated alive at the end");
        assert_eq!(v[9].expected, "at most 5 of group hungry alive at the end");
        assert_eq!(v[9].observed, "6 alive");
        // The two groups' meals are the run's.
        let meals = |x: &Verdict| -> u64 { x.observed.split(' ').next().unwrap().parse().unwrap() };
        assert_eq!(meals(&v[1]) + meals(&v[2]), meals(&v[0]), "{v:?}");
    }

    #[test]
    fn an_unnamed_group_is_named_by_its_species_and_unknown_groups_are_located() {
        let sc = scenario("GroupMinAlive(\"reef_fish\", 12), GroupMinAlive(\"reef_fish\", 13)")
            .unwrap_or_else(|d| panic!("{d}"));
        let v = run_verdicts(sc);
        assert!(v[0].passed && !v[1].passed, "{v:?}");
        let d = grouped("        GroupCatches(\"hungyr\", 3),")
            .unwrap_err()
            .to_string();
        assert!(
            d.contains(
                "groups.ron:13:22: unknown group \"hungyr\" in `expect` (did you mean `hungry`?): \
                 the scenario's groups are hungry, sated"
            ),
            "{d}"
        );
        let d = scenario("SpeciesMeals(\"reef_fsh\", 1)")
            .unwrap_err()
            .to_string();
        assert!(d.contains("(did you mean `reef_fish`?)"), "{d}");
    }
}
