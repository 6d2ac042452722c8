//! Scenario expectations (`expect: [...]` in a scenario file), checked over a run.
//!
//! Not a tick stage: a layer above the scenario [`super::Run`]. A [`Tracker`] is built once from
//! the validated scenario (names resolved, problems located in the scenario file), fed the world
//! after every tick ([`Tracker::observe`]) and asked for one [`Verdict`] per expectation at the end
//! ([`Tracker::finish`]). `shoal test` runs scenario files this way.

use super::{Expectation, Scenario};
use crate::diag::{Diagnostic, Diagnostics};
use crate::events::Event;
use crate::species::validate::locate;
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
        behavior: u16,
        fraction: f32,
        from: f32,
        to: f32,
        /// Best share seen in the window and when (s).
        best: Option<(f32, f32)>,
    },
    MinCatches(u64),
    MinMeals(u64),
    MinAlive(usize, u64),
    MaxAlive(usize, u64),
    MinPolarization(usize, f32),
    NoScriptErrors {
        first: Vec<String>,
    },
}

/// Follows a run and judges the scenario's expectations.
#[derive(Debug, Clone)]
pub struct Tracker {
    checks: Vec<(String, Check)>,
    species: Vec<String>,
    duration: f32,
    last_time: f32,
}

fn counted(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

fn pct(x: f32) -> String {
    format!("{:.0}%", x * 100.0)
}

impl Tracker {
    /// Resolves the expectations of `scenario`; unknown species or behavior names and fractions
    /// outside [0, 1] are located errors in the scenario file.
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
                        "unknown species \"{name}\" in `expect`: the scenario loads {}",
                        names.join(", ")
                    ),
                );
            }
            i
        };
        let mut checks = Vec::new();
        for e in &scenario.def.expect {
            let variant = match e {
                Expectation::BehaviorShare { .. } => "BehaviorShare",
                Expectation::MinCatches(_) => "MinCatches",
                Expectation::MinMeals(_) => "MinMeals",
                Expectation::MinAlive(..) => "MinAlive",
                Expectation::MaxAlive(..) => "MaxAlive",
                Expectation::MinPolarization(..) => "MinPolarization",
                Expectation::NoScriptErrors => "NoScriptErrors",
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
                    if !(*within >= 0.0 && *after >= 0.0) {
                        error(
                            "within",
                            cursor,
                            "`after` and `within` must be ≥ 0 seconds".to_string(),
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
                            behavior: b,
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
            };
            checks.push(check);
            cursor += 1;
        }
        if !diags.is_empty() {
            return Err(Diagnostics(diags));
        }
        Ok(Tracker {
            checks,
            species: names,
            duration: scenario.def.duration,
            last_time: 0.0,
        })
    }

    /// Whether the scenario declares any expectation.
    pub fn is_empty(&self) -> bool {
        self.checks.is_empty()
    }

    /// Looks at the world after a tick (and once before the first, for windows starting at 0)
    /// and at the events of that tick.
    pub fn observe(&mut self, world: &World, pipeline: &Pipeline) {
        let t = world.time() as f32;
        let half = world.dt * 0.5;
        self.last_time = t;
        for (_, c) in &mut self.checks {
            match c {
                Check::Share {
                    species,
                    behavior,
                    from,
                    to,
                    best,
                    ..
                } if t >= *from - half && t <= *to + half => {
                    let (mut n, mut k) = (0usize, 0usize);
                    for a in &world.agents {
                        if a.species.0 as usize == *species {
                            n += 1;
                            if a.mind.current == *behavior {
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
                    Check::MinAlive(s, n) => {
                        let a = alive(*s);
                        (a >= *n, format!("{a} alive"))
                    }
                    Check::MaxAlive(s, n) => {
                        let a = alive(*s);
                        (a <= *n, format!("{a} alive"))
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
