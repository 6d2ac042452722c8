//! Runs `scenarios/showcase.ron` (every shipped species together for 60 s) and checks that every
//! behavior of every species is visible in it.

use shoal::events::Event;
use shoal::scenario::{Overrides, Run, Scenario};
use std::path::Path;

#[test]
fn every_behavior_of_every_shipped_species_shows_up_in_a_minute() {
    let sc = Scenario::load(Path::new("scenarios/showcase.ron")).unwrap_or_else(|e| panic!("{e}"));
    let mut run = Run::new(sc, Overrides::default());
    let mut errors = Vec::new();
    while !run.finished() {
        run.step();
        for e in &run.pipeline.events {
            if let Event::ScriptError { message, .. } = e {
                errors.push(message.clone());
            }
        }
    }
    assert!(errors.is_empty(), "{errors:?}");
    let s = &run.pipeline.stats;
    let mut report = String::new();
    let mut missing = Vec::new();
    for (i, sp) in run.scenario.species.species.iter().enumerate() {
        for (b, n) in sp.behaviors.iter().zip(&s.behavior_ticks[i]) {
            report.push_str(&format!("{} {} {}\n", sp.name, b.name, n));
            if *n == 0 {
                missing.push(format!("{}.{}", sp.name, b.name));
            }
        }
    }
    eprintln!(
        "{report}meals {} catches {} matings {} transitions {}",
        s.meals, s.catches, s.matings, s.transitions
    );
    assert!(missing.is_empty(), "never active: {missing:?}\n{report}");
    assert!(s.meals > 0 && s.catches > 0 && s.matings > 0, "{s:?}");
    for a in &run.world.agents {
        assert!(a.pos.is_finite() && run.world.bounds.contains(a.pos));
    }
}
