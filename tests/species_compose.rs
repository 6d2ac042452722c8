//! Composed behaviors, each rule in a world built for it: a probe species whose drives change
//! only when the test sets them (`native: false`).
//! - `flee` (level 1) interrupts anything, composed or not;
//! - `eat` (level 2) holds its own prioritized list — `rest` 1, `court` 2, `search` 3 — with
//!   seed 000 §3's rules inside it;
//! - `errand` (level 3) is a sequence `go` → `fetch` whose success starts `celebrate` and whose
//!   failure starts `sulk`;
//! - `forage` (level 3) is a fallback `plan_a` → `plan_b`;
//! - `idle` (level 4, initial).

mod common;

use common::{folder, load, Change, Sim};
use glam::Vec3;
use shoal::events::Cause;
use shoal::species::Species;
use shoal::world::{Aabb, AgentId};

const PROBE: &str = r#"
Species(
    name: "probe",
    drives: (native: false, hunger: Fixed(0.0)),
    initial: "idle",
    behaviors: [
        Behavior(name: "flee", priority: 1, when: Above(Drive(Fear), 0.5), done: Below(Drive(Fear), 0.5), steer: Cruise(speed: 1.0), min_time: 0.0),
        Behavior(
            name: "eat", priority: 2, min_time: 0.0,
            when: Above(Drive(Hunger), 0.5), done: Below(Drive(Hunger), 0.2),
            behaviors: [
                Behavior(name: "rest", priority: 1, when: Above(Drive(Fatigue), 0.5), done: Below(Drive(Fatigue), 0.5), steer: Stop, min_time: 0.0),
                Behavior(name: "court", priority: 2, when: Above(Drive(Libido), 0.5), done: Below(Drive(Libido), 0.5), steer: Cruise(speed: 0.4), min_time: 0.0),
                Behavior(name: "search", priority: 3, steer: Wander(), min_time: 0.0),
            ],
        ),
        Behavior(
            name: "errand", priority: 3, min_time: 0.0,
            when: Above(Attribute(Age), 5.0),
            sequence: [
                Behavior(name: "go", done: TimeIn(0.2), steer: Cruise(speed: 0.5), min_time: 0.0),
                Behavior(name: "fetch", done: TimeIn(0.2), fail: Above(Drive(Libido), 0.5), steer: Cruise(speed: 0.3), min_time: 0.0),
            ],
            on_success: "celebrate",
            on_failure: "sulk",
        ),
        Behavior(name: "celebrate", priority: 3, done: TimeIn(0.2), steer: Cruise(speed: 0.9), min_time: 0.0, equal_may_interrupt: false),
        Behavior(name: "sulk", priority: 3, done: TimeIn(0.2), steer: Stop, min_time: 0.0, equal_may_interrupt: false),
        Behavior(
            name: "forage", priority: 3, min_time: 0.0,
            when: Above(Attribute(Mass), 5.0),
            fallback: [
                Behavior(name: "plan_a", fail: TimeIn(0.1), steer: Cruise(speed: 0.5), min_time: 0.0),
                Behavior(name: "plan_b", done: TimeIn(0.1), steer: Cruise(speed: 0.5), min_time: 0.0),
            ],
        ),
        Behavior(name: "idle", priority: 4, steer: Wander(), min_time: 0.0),
    ],
)
"#;

fn probe_species(text: &str) -> (Species, tempfile::TempDir) {
    let dir = folder(&[("probe.ron", text)]);
    let sp = load(&dir.path().join("probe.ron"), dir.path());
    (sp, dir)
}

fn probe() -> (Sim, AgentId, tempfile::TempDir) {
    let (sp, dir) = probe_species(PROBE);
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let id = sim.spawn("probe", Vec3::ZERO, 0.0);
    set(&mut sim, id, [0.0; 6]);
    (sim, id, dir)
}

/// Sets hunger, libido, fear and fatigue, and the errand's and forage's triggers (age, mass
/// above 5 when the last two are above 0.5).
fn set(sim: &mut Sim, id: AgentId, d: [f32; 6]) {
    let a = sim.agent_mut(id);
    a.drives.hunger = d[0];
    a.drives.libido = d[1];
    a.drives.fear = d[2];
    a.drives.fatigue = d[3];
    a.attrs.age = d[4] * 10.0;
    a.attrs.mass = d[5] * 10.0;
}

fn last(sim: &Sim, id: AgentId) -> (String, String, Cause, Vec<String>) {
    let c: Change = sim.last_change(id);
    (c.from, c.to, c.cause, c.stack)
}

fn t(from: &str, to: &str, cause: Cause, stack: &[&str]) -> (String, String, Cause, Vec<String>) {
    (
        from.into(),
        to.into(),
        cause,
        stack.iter().map(|s| s.to_string()).collect(),
    )
}

#[test]
fn a_composed_behavior_starts_in_its_best_part_and_runs_the_flat_rules_inside() {
    let (mut sim, id, _dir) = probe();
    sim.run(3);
    assert_eq!(sim.behavior(id), "idle");
    // Hungry: `eat` interrupts idle and starts in its best part (nothing else fires: search).
    set(&mut sim, id, [0.9, 0.0, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(
        last(&sim, id),
        t("idle", "eat/search", Cause::Interrupted, &["idle"])
    );
    // Inside eat, a higher part interrupts a lower one, which goes on the stack.
    set(&mut sim, id, [0.9, 0.9, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(
        last(&sim, id),
        t(
            "eat/search",
            "eat/court",
            Cause::Interrupted,
            &["idle", "eat/search"]
        )
    );
    // ...and resumes when the higher one completes.
    set(&mut sim, id, [0.9, 0.0, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(
        last(&sim, id),
        t("eat/court", "eat/search", Cause::Resumed, &["idle"])
    );
}

#[test]
fn an_outer_level_interrupts_from_inside_and_the_part_resumes() {
    let (mut sim, id, _dir) = probe();
    set(&mut sim, id, [0.9, 0.9, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(sim.behavior(id), "eat/court");
    set(&mut sim, id, [0.9, 0.9, 0.9, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(
        last(&sim, id),
        t(
            "eat/court",
            "flee",
            Cause::Interrupted,
            &["idle", "eat/court"]
        )
    );
    set(&mut sim, id, [0.9, 0.9, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(
        last(&sim, id),
        t("flee", "eat/court", Cause::Resumed, &["idle"])
    );
}

#[test]
fn a_composed_behavior_that_completes_ends_its_parts_and_their_stack() {
    let (mut sim, id, _dir) = probe();
    set(&mut sim, id, [0.9, 0.0, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    set(&mut sim, id, [0.9, 0.9, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(sim.stack(id), ["idle", "eat/search"]);
    // Sated: eat's own `done` holds, checked before its parts': the whole of eat ends, the
    // search waiting inside it is dropped, and idle resumes.
    set(&mut sim, id, [0.1, 0.9, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    let c = sim.last_change(id);
    assert_eq!(
        (c.from.as_str(), c.to.as_str(), c.cause),
        ("eat/court", "idle", Cause::Resumed)
    );
    assert_eq!(c.condition.as_deref(), Some("hunger < 0.2"));
    assert!(sim.stack(id).is_empty(), "{:?}", sim.stack(id));
}

#[test]
fn a_sequence_runs_its_steps_in_order_and_its_success_starts_on_success() {
    let (mut sim, id, _dir) = probe();
    set(&mut sim, id, [0.0, 0.0, 0.0, 0.0, 0.9, 0.0]);
    sim.step();
    assert_eq!(sim.behavior(id), "errand/go");
    sim.run_until(20, |s| s.behavior(id) != "errand/go")
        .unwrap();
    assert_eq!(
        last(&sim, id),
        t("errand/go", "errand/fetch", Cause::Succeeded, &["idle"])
    );
    sim.run_until(20, |s| s.behavior(id) != "errand/fetch")
        .unwrap();
    assert_eq!(
        last(&sim, id),
        t("errand/fetch", "celebrate", Cause::Succeeded, &["idle"])
    );
    assert_eq!(
        sim.last_change(id).condition.as_deref(),
        Some("0.2 s in behavior")
    );
}

#[test]
fn a_failed_step_fails_the_sequence_and_starts_on_failure() {
    let (mut sim, id, _dir) = probe();
    set(&mut sim, id, [0.0, 0.0, 0.0, 0.0, 0.9, 0.0]);
    sim.step();
    sim.run_until(20, |s| s.behavior(id) != "errand/go")
        .unwrap();
    assert_eq!(sim.behavior(id), "errand/fetch");
    set(&mut sim, id, [0.0, 0.9, 0.0, 0.0, 0.9, 0.0]);
    sim.step();
    let c = sim.last_change(id);
    assert_eq!(
        (c.from.as_str(), c.to.as_str(), c.cause),
        ("errand/fetch", "sulk", Cause::Failed)
    );
    assert_eq!(c.condition.as_deref(), Some("libido > 0.5"));
}

#[test]
fn a_fallback_tries_its_next_step_on_failure_and_succeeds_with_it() {
    let (mut sim, id, _dir) = probe();
    set(&mut sim, id, [0.0, 0.0, 0.0, 0.0, 0.0, 0.9]);
    sim.step();
    assert_eq!(sim.behavior(id), "forage/plan_a");
    sim.run_until(20, |s| s.behavior(id) != "forage/plan_a")
        .unwrap();
    assert_eq!(
        last(&sim, id),
        t("forage/plan_a", "forage/plan_b", Cause::Failed, &["idle"])
    );
    // plan_b succeeds, so the fallback does; with no `on_success`, the list's rules pick what
    // is next: forage would fire again (its trigger still holds) — so clear it first.
    set(&mut sim, id, [0.0; 6]);
    sim.run_until(20, |s| s.behavior(id) != "forage/plan_b")
        .unwrap();
    let c = sim.last_change(id);
    assert_eq!(
        (c.from.as_str(), c.to.as_str(), c.cause),
        ("forage/plan_b", "idle", Cause::Resumed)
    );
}

#[test]
fn mistakes_in_a_composition_are_located_load_errors() {
    let cases: [(&str, &str, &str); 6] = [
        (
            r#"on_success: "celebrate","#,
            r#"on_success: "celebrat","#,
            "`on_success` names \"celebrat\", which is not another behavior of the same list (did you mean `celebrate`?)",
        ),
        (
            r#"Behavior(name: "go", done"#,
            r#"Behavior(name: "go", when: Always, done"#,
            "step \"errand/go\" has a `when`",
        ),
        (
            r#"name: "eat", priority: 2, min_time: 0.0,"#,
            r#"name: "eat", priority: 2, min_time: 0.0, steer: Stop,"#,
            "behavior \"eat\" is made of parts, which steer and act: move its `steer` into them",
        ),
        (
            r#"Behavior(name: "search", priority: 3, steer: Wander(), "#,
            r#"Behavior(name: "search", priority: 3, "#,
            "behavior \"eat/search\" has no `steer`",
        ),
        (
            r#"Behavior(name: "court", priority: 2,"#,
            r#"Behavior(name: "court","#,
            "behavior \"eat/court\" needs a `priority`",
        ),
        (
            r#"name: "plan_b""#,
            r#"name: "plan/b""#,
            "a name may not hold `/`",
        ),
    ];
    for (from, to, expected) in cases {
        assert!(PROBE.contains(from), "{from}");
        let text = PROBE.replacen(from, to, 1);
        let dir = folder(&[("probe.ron", &text)]);
        let err = Species::load(dir.path().join("probe.ron"))
            .unwrap_err()
            .to_string();
        assert!(err.contains(expected), "expected {expected:?} in:\n{err}");
        assert!(err.contains("probe.ron:"), "located: {err}");
    }
}

#[test]
fn a_reload_keeps_each_agent_in_its_part_where_the_names_still_match() {
    let (mut sim, id, _dir) = probe();
    set(&mut sim, id, [0.9, 0.0, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    set(&mut sim, id, [0.9, 0.9, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(sim.behavior(id), "eat/court");
    assert_eq!(sim.stack(id), ["idle", "eat/search"]);
    // A new version of the species: the same tree, a part's steering retuned and a part added.
    let edited = PROBE
        .replace("steer: Cruise(speed: 0.4)", "steer: Cruise(speed: 0.45)")
        .replace(
            r#"Behavior(name: "search", priority: 3,"#,
            r#"Behavior(name: "nibble", priority: 3, when: Above(Drive(Fatigue), 2.0), steer: Stop, min_time: 0.0),
                Behavior(name: "search", priority: 3,"#,
        );
    let (sp, _dir2) = probe_species(&edited);
    let set_ =
        shoal::species::SpeciesSet::with_library(vec![std::sync::Arc::new(sp)], |_| true).unwrap();
    let remap = sim.set_species(set_);
    assert_eq!(remap.fell_back_total(), 0);
    assert_eq!(sim.behavior(id), "eat/court");
    assert_eq!(sim.stack(id), ["idle", "eat/search"]);
    // And the rules go on inside it: court ends, search resumes.
    set(&mut sim, id, [0.9, 0.0, 0.0, 0.0, 0.0, 0.0]);
    sim.step();
    assert_eq!(
        last(&sim, id),
        t("eat/court", "eat/search", Cause::Resumed, &["idle"])
    );
    // A version where the running part is gone: the agent falls back to the initial behavior.
    let (sp, _dir3) = probe_species(&PROBE.replace(r#"name: "search""#, r#"name: "browse""#));
    let set_ =
        shoal::species::SpeciesSet::with_library(vec![std::sync::Arc::new(sp)], |_| true).unwrap();
    let remap = sim.set_species(set_);
    assert_eq!(remap.fell_back_total(), 1);
    assert_eq!(sim.behavior(id), "idle");
}

#[test]
fn a_flat_list_ends_a_behavior_on_its_failure_and_starts_what_it_names() {
    // No composed behavior: the flat rules alone would read neither `fail` nor `on_failure`.
    let (sp, _dir) = probe_species(
        r#"
Species(
    name: "probe",
    drives: (native: false),
    initial: "cruise",
    behaviors: [
        Behavior(name: "cruise", priority: 2, fail: TimeIn(0.5), on_failure: "rest", steer: Cruise(speed: 0.5), min_time: 0.0),
        Behavior(name: "rest", priority: 2, done: TimeIn(0.5), on_success: "cruise", steer: Stop, min_time: 0.0),
    ],
)
"#,
    );
    let mut sim = Sim::new(vec![sp], Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)));
    let id = sim.spawn("probe", Vec3::ZERO, 0.0);
    sim.run(5);
    assert_eq!(sim.behavior(id), "cruise");
    sim.run(10);
    assert_eq!(sim.behavior(id), "rest");
    assert_eq!(last(&sim, id), t("cruise", "rest", Cause::Failed, &[]));
    sim.run(15);
    assert_eq!(sim.behavior(id), "cruise");
    let c = sim.last_change(id);
    assert_eq!((c.from.as_str(), c.to.as_str()), ("rest", "cruise"));
}
