//! Hover: reference entries, seed constants with their paper defaults, API and own functions.

use super::*;

#[test]
fn hover_shows_reference_entries() {
    let doc =
        format!("{SPECIES_HEAD}Behavior(name: \"eat\", min_ti|me: 0.5, steer: Cha|se(d0: 0.5)),\n");
    let (text, _) = at(&doc);
    let text = text.replacen('|', "", 1);
    let i = doc.find("min_ti").unwrap() + 2;
    let h = hover(FileKind::Species, &text, i).expect("hover on a key");
    assert!(h.markdown.contains("min_time: f32"), "{}", h.markdown);
    assert!(h.markdown.contains("anti-dithering"), "{}", h.markdown);
    assert_eq!(&text[h.start..h.end], "min_time");
    let i = text.find("Chase").unwrap() + 2;
    let h = hover(FileKind::Species, &text, i).expect("hover on a primitive");
    assert!(
        h.markdown.contains("| `Chase(target: Food"),
        "{}",
        h.markdown
    );
    assert!(
        h.markdown.starts_with("`Chase(target: Category"),
        "{}",
        h.markdown
    );
    // A condition, and a scenario key.
    let h = hover_at(
        FileKind::Species,
        "Species(behaviors: [Behavior(when: Esc|apeDone)])",
    )
    .unwrap();
    assert!(h.markdown.contains("seed 000 §4.4"), "{}", h.markdown);
    let h = hover_at(FileKind::Scenario, "Scenario(\n    respawn|: 1.0)");
    assert!(h.is_none());
    let h = hover_at(
        FileKind::Scenario,
        "Scenario(\n    food: (respawn_per|_second: 1.0))",
    )
    .unwrap();
    assert!(h.markdown.contains("respawn_per_second"), "{}", h.markdown);
    // Nothing to say about a number.
    assert!(hover_at(FileKind::Species, "Species(decision_interval: 4|)").is_none());
}

#[test]
fn hover_on_a_seed_constant_gives_its_paper_default() {
    let h = hover_at(
        FileKind::Species,
        "Species(\n    senses: (vision_half|_angle: 2.0),\n",
    )
    .unwrap();
    assert!(
        h.markdown
            .contains("**Seed constant** `senses.vision_half_angle` (seed 000 §1)"),
        "{}",
        h.markdown
    );
    assert!(
        h.markdown.contains("default 2.618 · paper 2.618\n"),
        "{}",
        h.markdown
    );
    let h = hover_at(
        FileKind::Species,
        "Species(behaviors: [Behavior(steer: Chase(max_tu|rn: 0.5))])",
    )
    .unwrap();
    assert!(
        h.markdown.contains("`Chase(max_turn)` (seed 000 §4.3)"),
        "{}",
        h.markdown
    );
    let h = hover_at(
        FileKind::Scenario,
        "Scenario(squads: [(species: \"a\", planning: (must_keep: (k|1: 0.1)))])",
    )
    .unwrap();
    assert!(
        h.markdown
            .contains("`squads[].planning.must_keep.k1` (seed 004)"),
        "{}",
        h.markdown
    );
    // A key of the same name elsewhere is no seed constant.
    let h = hover_at(
        FileKind::Species,
        "Species(behaviors: [Behavior(steer: Escape(max_tu|rn: 0.5))])",
    );
    assert!(h.is_none_or(|h| !h.markdown.contains("Seed constant")));
}

#[test]
fn hover_on_api_functions_and_own_functions() {
    let doc = SCRIPT.replace('|', "this.se|ek(this.kin.nearest_p|os)");
    let (text, i) = at(&doc);
    let text = text.replacen('|', "", 1);
    let h = hover(FileKind::Script, &text, i).expect("hover on seek");
    assert!(
        h.markdown.contains("Agent.seek(Vec3) -> Steer"),
        "{}",
        h.markdown
    );
    assert!(h.markdown.contains("steering toward"), "{}", h.markdown);
    let j = text.find("nearest_p").unwrap() + 3;
    let h = hover(FileKind::Script, &text, j).expect("hover on a Percepts property");
    assert!(
        h.markdown.contains("Percepts.nearest_pos: Vec3"),
        "{}",
        h.markdown
    );
    let k = text.find("tired").unwrap() + 1;
    let h = hover(FileKind::Script, &text, k).expect("hover on an own function");
    assert!(
        h.markdown.contains("fn tired()") && h.markdown.contains("How tired the fish is."),
        "{}",
        h.markdown
    );
    let h = hover_at(FileKind::Test, "fn t() { assert_beh|avior(a, \"x\"); }").unwrap();
    assert!(
        h.markdown.contains("the agent is in another behavior"),
        "{}",
        h.markdown
    );
}
