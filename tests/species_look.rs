//! A species file's `look` section: read into the species' definition with its defaults filled
//! in as `world.json` carries it, and every bad value a located error.

use shoal::species::Species;

fn species(look: &str) -> Result<Species, String> {
    let text = format!(
        "Species(\n    name: \"minnow\",\n    {look}\n    initial: \"wander\",\n    behaviors: [Behavior(name: \"wander\", priority: 1, steer: Wander())],\n)\n"
    );
    Species::parse("minnow.ron", &text).map_err(|e| e.to_string())
}

#[test]
fn a_look_reaches_the_species_def_with_its_defaults() {
    let s = species("look: (shape: Shark, behavior_colors: {\"wander\": \"#00ff00\"}),").unwrap();
    let look = s.def.look.resolve(&s.def.color, &s.def.body);
    assert_eq!(look.shape, "shark");
    assert_eq!(look.length, s.def.body.size.z);
    assert_eq!(look.color, s.def.color);
    let s = species("look: (shape: Custom([(0.5, 0.0), (-0.5, 0.2), (-0.5, -0.2)]), length: 2.0),")
        .unwrap();
    let look = s.def.look.resolve(&s.def.color, &s.def.body);
    assert_eq!(
        (look.shape, look.outline.len(), look.length),
        ("custom", 3, 2.0)
    );
    assert_eq!(
        species("")
            .unwrap()
            .def
            .look
            .resolve("#000000", &s.def.body)
            .shape,
        "fish"
    );
}

#[test]
fn bad_looks_are_located_errors() {
    let e = species("look: (color: \"red\"),").unwrap_err();
    assert!(
        e.contains("minnow.ron:3:") && e.contains("\"#rrggbb\""),
        "{e}"
    );
    let e = species("look: (length: 0.0),").unwrap_err();
    assert!(e.contains("minnow.ron:3:") && e.contains("`length`"), "{e}");
    let e = species("look: (behavior_colors: {\"wandr\": \"#ff0000\"}),").unwrap_err();
    assert!(
        e.contains("undefined behavior \"wandr\"") && e.contains("wander"),
        "{e}"
    );
    let e = species("look: (shape: Custom([(0.0, 0.0), (1.0, 0.0)])),").unwrap_err();
    assert!(e.contains("3 to 64"), "{e}");
    let e = species("look: (shape: Squid),").unwrap_err();
    assert!(e.contains("minnow.ron:3:"), "{e}");
}
