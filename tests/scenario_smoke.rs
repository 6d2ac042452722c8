//! Loads the small test scenario and runs it end to end.

use shoal::scenario::{Overrides, Run, Scenario};
use std::path::Path;

#[test]
fn tiny_scenario_runs_and_things_happen() {
    let sc = Scenario::load(Path::new("scenarios/tiny.ron")).unwrap_or_else(|e| panic!("{e}"));
    let mut run = Run::new(sc, Overrides::default());
    let mut transitions = 0;
    let mut errors = Vec::new();
    while !run.finished() {
        run.step();
        for e in &run.pipeline.events {
            match e {
                shoal::events::Event::Transition { .. } => transitions += 1,
                shoal::events::Event::ScriptError { message, .. } => errors.push(message.clone()),
                _ => {}
            }
        }
    }
    assert!(errors.is_empty(), "{errors:?}");
    assert!(transitions > 10, "only {transitions} transitions");
    let s = &run.pipeline.stats;
    eprintln!(
        "meals {} catches {} matings {} transitions {}",
        s.meals, s.catches, s.matings, s.transitions
    );
    for (i, sp) in run.scenario.species.species.iter().enumerate() {
        for (b, n) in sp.behaviors.iter().zip(&s.behavior_ticks[i]) {
            eprintln!("{} {} {}", sp.name, b.name, n);
        }
    }
    for a in &run.world.agents {
        assert!(a.pos.is_finite() && run.world.bounds.contains(a.pos));
    }
}
