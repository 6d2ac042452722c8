//! Hostile input: files that used to pass `check` and then hang, panic or abort the run, or that
//! made `check` itself hang or flood the terminal. Each is refused at load with a located
//! diagnostic, or handled, within a time limit.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A copy of the shipped behaviors, scenarios and assets to edit.
fn world() -> tempfile::TempDir {
    fn copy(from: &Path, to: &Path) {
        std::fs::create_dir_all(to).unwrap();
        for e in std::fs::read_dir(from).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                copy(&p, &to.join(e.file_name()));
            } else {
                std::fs::copy(&p, to.join(e.file_name())).unwrap();
            }
        }
    }
    let t = tempfile::tempdir().unwrap();
    for d in ["behaviors", "scenarios", "assets"] {
        copy(Path::new(d), &t.path().join(d));
    }
    t
}

/// Runs `shoal ARGS` in `dir`; a run past 60 s counts as a hang.
fn shoal(dir: &Path, args: &[&str]) -> (i32, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().ok();
            panic!("`shoal {}` hung", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code().unwrap_or(-1), text)
}

/// Writes `text` as `rel` under `dir`.
fn write(dir: &Path, rel: &str, text: &str) -> PathBuf {
    let p = dir.join(rel);
    std::fs::write(&p, text).unwrap();
    p
}

/// `rel` with `from` replaced by `to` (which must occur).
fn edit(dir: &Path, rel: &str, from: &str, to: &str) {
    let p = dir.join(rel);
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains(from), "{rel} has no `{from}`");
    std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
}

/// `file:line:col` of the first occurrence of `needle`'s end in `rel` (1-based), as a
/// diagnostic would print it.
fn at(dir: &Path, rel: &str, needle: &str) -> String {
    let text = std::fs::read_to_string(dir.join(rel)).unwrap();
    let i = text.find(needle).unwrap() + needle.len();
    let line = text[..i].matches('\n').count() + 1;
    let col = text[..i].rsplit('\n').next().unwrap().chars().count() + 1;
    format!("{rel}:{line}:{col}")
}

/// Refused: a non-zero exit that is not a panic (101) or an abort.
fn refused(code: i32, out: &str) {
    assert!(code != 0 && code != 101 && code > 0, "exit {code}:\n{out}");
    assert!(!out.contains("panicked"), "{out}");
}

#[test]
fn infinite_food_respawn_is_refused_at_its_key() {
    let w = world();
    let d = w.path();
    for rate in ["inf", "4e8", "-1.0", "NaN"] {
        edit(
            d,
            "scenarios/tiny.ron",
            "respawn_per_second: 0.5",
            &format!("respawn_per_second: {rate}"),
        );
        let (code, out) = shoal(d, &["check", "scenarios/tiny.ron"]);
        refused(code, &out);
        let here = at(d, "scenarios/tiny.ron", "respawn_per_second: ");
        assert!(
            out.contains(&format!("{here}: `respawn_per_second` must be")),
            "{out}"
        );
        edit(
            d,
            "scenarios/tiny.ron",
            &format!("respawn_per_second: {rate}"),
            "respawn_per_second: 0.5",
        );
    }
}

#[test]
fn the_respawn_loop_ends_whatever_the_rate() {
    use shoal::scenario::{Overrides, Run, Scenario};
    let w = world();
    let mut s = Scenario::load(&w.path().join("scenarios/tiny.ron")).unwrap();
    // Past validation, as an embedding program could set it.
    s.def.food.respawn_per_second = f32::INFINITY;
    let max = s.def.food.max as usize;
    let mut run = Run::new(
        s,
        Overrides {
            duration: Some(0.2),
            ..Default::default()
        },
    );
    for _ in 0..3 {
        run.step();
    }
    assert!(run.world.food.len() <= max);
}

const PROBE: &str = r#"Species(
    name: "probe",
    body: (
        limits: (
            max_turn: NaN,
            max_speed: 2.0,
            min_speed: 3.0,
            max_accel: -1.0,
        ),
        locomotion: RigidBody(
            max_yaw_torque: inf,
        ),
        size: (0.2, 0.3, -1.0),
    ),
    senses: (vision_radius: NaN),
    initial: "swim",
    behaviors: [
        (
            name: "swim",
            priority: 1,
            steer: Cruise(speed: 0.5),
            cooldown: inf,
            min_time: -1.0,
            response: Some(NaN),
        ),
    ],
)
"#;

#[test]
fn nan_and_inf_in_a_species_are_refused_at_their_keys() {
    let w = world();
    let d = w.path();
    write(d, "behaviors/probe.ron", PROBE);
    let (code, out) = shoal(d, &["check", "behaviors/probe.ron"]);
    refused(code, &out);
    let f = "behaviors/probe.ron";
    for (needle, msg) in [
        (
            "max_turn: ",
            "`max_turn` must be a finite number > 0, not NaN",
        ),
        (
            "min_speed: ",
            "`min_speed` (3) must not exceed `max_speed` (2)",
        ),
        (
            "max_accel: ",
            "`max_accel` must be a finite number > 0, not -1",
        ),
        (
            "max_yaw_torque: ",
            "`max_yaw_torque` must be a finite number ≥ 0, not inf",
        ),
        ("size: ", "`size` must be three finite numbers > 0"),
        (
            "vision_radius: ",
            "`vision_radius` must be a finite number ≥ 0, not NaN",
        ),
        (
            "cooldown: ",
            "`cooldown` must be a finite number ≥ 0, not inf",
        ),
        (
            "min_time: ",
            "`min_time` must be a finite number ≥ 0, not -1",
        ),
        (
            "response: Some(",
            "`response` must be a finite number ≥ 0, not NaN",
        ),
    ] {
        let here = at(d, f, needle);
        assert!(
            out.contains(&format!("{here}: {msg}")),
            "{here}: {msg}\n{out}"
        );
    }
}

#[test]
fn a_huge_squad_spacing_is_refused_without_a_panic() {
    let w = world();
    let d = w.path();
    edit(
        d,
        "scenarios/squad_march.ron",
        "spacing: 4.0",
        "spacing: 1e10",
    );
    let (code, out) = shoal(d, &["check", "scenarios/squad_march.ron"]);
    refused(code, &out);
    let here = at(d, "scenarios/squad_march.ron", "spacing: ");
    assert!(out.contains(&format!("{here}: `spacing` must be")), "{out}");
}

#[test]
fn counts_beyond_the_agent_limit_are_refused_with_the_limit() {
    let w = world();
    let d = w.path();
    for count in ["2147483648", "9223372036854775807"] {
        edit(
            d,
            "scenarios/tiny.ron",
            "count: 40",
            &format!("count: {count}"),
        );
        let (code, out) = shoal(d, &["check", "scenarios/tiny.ron"]);
        refused(code, &out);
        let here = at(d, "scenarios/tiny.ron", "count: ");
        assert!(
            out.contains(&format!(
                "{here}: `count` is {count}, above the limit of 10000000"
            )),
            "{out}"
        );
        edit(
            d,
            "scenarios/tiny.ron",
            &format!("count: {count}"),
            "count: 40",
        );
    }
    edit(
        d,
        "scenarios/squad_march.ron",
        "count: 5",
        "count: 2147483648",
    );
    let (code, out) = shoal(d, &["check", "scenarios/squad_march.ron"]);
    refused(code, &out);
    assert!(out.contains("above the limit of 10000000"), "{out}");
}

#[test]
fn terrain_sizes_beyond_the_cell_limit_are_refused() {
    let w = world();
    let d = w.path();
    for (key, n) in [("ncols", "4294967297"), ("nrows", "18446744073709551615")] {
        let text = format!(
            "ncols 4\nnrows 4\nxllcorner 0\nyllcorner 0\ncellsize 1\n{}",
            "0 0 0 0\n".repeat(4)
        )
        .replace(&format!("{key} 4"), &format!("{key} {n}"));
        write(d, "big.asc", &text);
        let (code, out) = shoal(d, &["check", "big.asc"]);
        refused(code, &out);
        assert!(out.contains(&at(d, "big.asc", &format!("{key} "))), "{out}");
        assert!(out.contains("268435456"), "{out}");
    }
    // Each side within the limit, the product not.
    write(
        d,
        "wide.asc",
        "ncols 100000\nnrows 100000\nxllcorner 0\nyllcorner 0\ncellsize 1\n0\n",
    );
    let (code, out) = shoal(d, &["check", "wide.asc"]);
    refused(code, &out);
    assert!(out.contains("at most 268435456"), "{out}");
}

#[test]
fn bad_obstacle_shapes_are_refused_at_their_keys() {
    let w = world();
    let d = w.path();
    let f = "scenarios/tiny.ron";
    let rock = "obstacles: [Sphere(center: (0.0, 5.0, 0.0), radius: 2.5)]";
    for (shape, needle, msg) in [
        (
            "Box(min: (5.0, 5.0, 5.0), max: (1.0, 6.0, 6.0))",
            "Box(min: ",
            "`Box`: `min` [5.0, 5.0, 5.0] must not exceed `max`",
        ),
        (
            "Sphere(center: (0.0, 5.0, 0.0), radius: -2.5)",
            "radius: ",
            "`radius` must be a number from 0 to",
        ),
        (
            "Sphere(center: (NaN, 5.0, 0.0), radius: 2.5)",
            "center: ",
            "`center` must have finite coordinates",
        ),
    ] {
        edit(d, f, rock, &format!("obstacles: [{shape}]"));
        let (code, out) = shoal(d, &["check", f]);
        refused(code, &out);
        let here = at(d, f, needle);
        assert!(
            out.contains(&format!("{here}: {msg}")),
            "{here}: {msg}\n{out}"
        );
        edit(d, f, &format!("obstacles: [{shape}]"), rock);
    }
}

#[test]
fn check_reads_scripts_terrain_and_features() {
    let w = world();
    let (code, out) = shoal(
        w.path(),
        &[
            "check",
            "behaviors/reef_fish.rhai",
            "assets/terrain/valley.asc",
            "assets/terrain/valley_features.ron",
        ],
    );
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("3 other files, no errors"), "{out}");
    // A broken feature file is checked as one, not as a species.
    let d = w.path();
    write(
        d,
        "bad_features.ron",
        "Features(items: [Road(points: [(0.0, 0.0)], width: 4.0)])",
    );
    let (code, out) = shoal(d, &["check", "bad_features.ron"]);
    refused(code, &out);
    assert!(out.contains("a line needs at least two points"), "{out}");
    assert!(!out.contains("Species"), "{out}");
}

#[test]
fn invalid_utf8_is_located_at_its_first_bad_byte() {
    let w = world();
    let d = w.path();
    std::fs::write(
        d.join("behaviors/bad.ron"),
        b"Species(\n    name: \"b\xe9d\",\n)\n",
    )
    .unwrap();
    let (code, out) = shoal(d, &["check", "behaviors/bad.ron"]);
    refused(code, &out);
    assert!(out.contains("behaviors/bad.ron:2:13: "), "{out}");
    assert!(out.contains("not valid UTF-8"), "{out}");
}

#[cfg(unix)]
#[test]
fn named_pipes_are_refused_by_name_not_waited_on() {
    let w = world();
    let d = w.path();
    let fifo = |rel: &str| {
        let p = d.join(rel);
        std::fs::remove_file(&p).ok();
        let ok = Command::new("mkfifo").arg(&p).status().unwrap().success();
        assert!(ok, "mkfifo");
    };
    fifo("behaviors/pipe.ron");
    let (code, out) = shoal(d, &["check", "behaviors/pipe.ron"]);
    refused(code, &out);
    assert!(
        out.contains("behaviors/pipe.ron: cannot read file: it is a named pipe"),
        "{out}"
    );
    // A species' script, a scenario and a terrain file.
    fifo("behaviors/reef_fish.rhai");
    let (code, out) = shoal(d, &["check", "behaviors/reef_fish.ron"]);
    refused(code, &out);
    assert!(out.contains("reef_fish.rhai\" is a named pipe"), "{out}");
    fifo("scenarios/pipe.ron");
    let (code, out) = shoal(d, &["run", "scenarios/pipe.ron"]);
    refused(code, &out);
    assert!(
        out.contains("scenarios/pipe.ron: cannot read scenario: it is a named pipe"),
        "{out}"
    );
    fifo("assets/terrain/valley.asc");
    let (code, out) = shoal(d, &["check", "scenarios/squad_march.ron"]);
    refused(code, &out);
    assert!(out.contains("valley.asc\" is a named pipe"), "{out}");
}

#[test]
fn run_folder_errors_name_the_path() {
    let w = world();
    let d = w.path();
    write(d, "blocker", "a file where the run folder should go");
    let (code, out) = shoal(
        d,
        &[
            "run",
            "scenarios/tiny.ron",
            "--duration",
            "0.1",
            "--out",
            "blocker/run",
        ],
    );
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("blocker/run"), "{out}");
}

#[test]
fn a_huge_line_is_not_echoed_whole() {
    let w = world();
    let d = w.path();
    let line = format!("Species(name: \"x\", {}oops)", "  ".repeat(1_000_000));
    write(d, "behaviors/wide.ron", &line);
    let (code, out) = shoal(d, &["check", "behaviors/wide.ron"]);
    refused(code, &out);
    assert!(out.len() < 4_000, "{} bytes of output", out.len());
    assert!(out.contains('…'), "{out}");
}

#[test]
fn bad_squad_planning_constants_are_refused_at_their_keys() {
    let w = world();
    let d = w.path();
    let rel = "scenarios/squad_march.ron";
    let cases = [
        (
            "relax_step: 0.0",
            "relax_step: ",
            "`relax_step` must be a number in (0, 1], not 0",
        ),
        (
            "relax_step: 1.5",
            "relax_step: ",
            "`relax_step` must be a number in (0, 1], not 1.5",
        ),
        (
            "relax_step: NaN",
            "relax_step: ",
            "`relax_step` must be a number in (0, 1], not NaN",
        ),
        (
            "fm_broken: 0.5",
            "fm_broken: ",
            "`fm_broken` must be a finite number ≥ 1, not 0.5",
        ),
        (
            "fm_broken: inf",
            "fm_broken: ",
            "`fm_broken` must be a finite number ≥ 1, not inf",
        ),
        (
            "may_change_rarely: (k1: 0.1, k2: 1.5)",
            "k2: ",
            "`k2` must be a number from 0 to 1, not 1.5",
        ),
        (
            "shortest_first: (k1: 0.0, k2: 0.1)",
            "k1: ",
            "`k1` must be a number in (0, 1], not 0",
        ),
        (
            "search_weight: 0.5",
            "search_weight: ",
            "`search_weight` must be a number from 1 to 10, not 0.5",
        ),
    ];
    for (value, key, msg) in cases {
        let planning = format!("spacing: 4.0,\n            planning: ({value}),");
        edit(d, rel, "spacing: 4.0,", &planning);
        let (code, out) = shoal(d, &["check", rel]);
        refused(code, &out);
        let here = at(d, rel, key);
        assert!(
            out.contains(&format!("{here}: {msg}")),
            "{value}: {here}: {msg}\n{out}"
        );
        edit(d, rel, &planning, "spacing: 4.0,");
    }
    // The defaults written out are accepted.
    let planning = "spacing: 4.0,\n            planning: (relax_step: 0.1, fm_broken: 2.0, keep_share: true, must_keep: (k1: 0.05, k2: 0.95), search_weight: 1.5),";
    edit(d, rel, "spacing: 4.0,", planning);
    let (code, out) = shoal(d, &["check", rel]);
    assert_eq!(code, 0, "{out}");
}

#[test]
fn bad_squad_leaders_are_refused_at_their_key() {
    let w = world();
    let d = w.path();
    let rel = "scenarios/squad_march.ron";
    let cases = [
        (
            "leader: Slot(5),",
            "leader slot 5 is out of range: the squad has 5 members (slots 0 to 4)",
        ),
        (
            "leader: Role(\"scout\"),",
            "leader role \"scout\" needs `roles: [...]`, one per member",
        ),
        (
            "leader: Role(\"scout\"), roles: [\"a\", \"b\", \"c\", \"d\", \"e\"],",
            "no member has the role \"scout\"; the roles are a, b, c, d, e",
        ),
    ];
    for (value, msg) in cases {
        let with = format!("spacing: 4.0,\n            {value}");
        edit(d, rel, "spacing: 4.0,", &with);
        let (code, out) = shoal(d, &["check", rel]);
        refused(code, &out);
        let here = at(d, rel, "leader: ");
        assert!(
            out.contains(&format!("{here}: {msg}")),
            "{here}: {msg}\n{out}"
        );
        edit(d, rel, &with, "spacing: 4.0,");
    }
    let with = "spacing: 4.0,\n            roles: [\"a\", \"b\"],";
    edit(d, rel, "spacing: 4.0,", with);
    let (code, out) = shoal(d, &["check", rel]);
    refused(code, &out);
    let here = at(d, rel, "roles: ");
    assert!(
        out.contains(&format!(
            "{here}: `roles` names 2 members but the squad has 5: give one role per member"
        )),
        "{out}"
    );
}

#[test]
fn a_pgm_terrain_needs_its_cell_size_and_height_scale() {
    let w = world();
    let d = w.path();
    let rel = "scenarios/squad_march.ron";
    let mut bytes = b"P5\n128 128\n255\n".to_vec();
    bytes.extend(std::iter::repeat_n(10u8, 128 * 128));
    std::fs::write(d.join("assets/terrain/flat.pgm"), &bytes).unwrap();
    edit(
        d,
        rel,
        "dem: \"../assets/terrain/valley.asc\",\n        features: Some(\"../assets/terrain/valley_features.ron\"),",
        "dem: \"../assets/terrain/flat.pgm\",",
    );
    let (code, out) = shoal(d, &["check", rel]);
    refused(code, &out);
    let here = at(d, rel, "dem: ");
    assert!(
        out.contains(&format!("{here}: terrain file"))
            && out.contains(
                "a PGM height map needs `cell_size` (metres per pixel) and `height_scale`"
            ),
        "{out}"
    );
    let pgm = "dem: \"../assets/terrain/flat.pgm\",";
    for (value, key, msg) in [
        (
            "cell_size: -4.0, height_scale: 0.1",
            "cell_size: ",
            "`cell_size` must be a finite number > 0, not -4",
        ),
        (
            "cell_size: 4.0, height_scale: NaN",
            "height_scale: ",
            "`height_scale` must be a finite number > 0, not NaN",
        ),
    ] {
        let with = format!("{pgm} {value},");
        edit(d, rel, pgm, &with);
        let (code, out) = shoal(d, &["check", rel]);
        refused(code, &out);
        let here = at(d, rel, key);
        assert!(
            out.contains(&format!("{here}: {msg}")),
            "{here}: {msg}\n{out}"
        );
        edit(d, rel, &with, pgm);
    }
    // 128 pixels of 4 m: the 512 m square of the scenario, flat at 10 × 0.1 = 1 m.
    edit(
        d,
        rel,
        pgm,
        &format!("{pgm} cell_size: 4.0, height_scale: 0.1,"),
    );
    let (code, out) = shoal(d, &["check", rel]);
    assert_eq!(code, 0, "{out}");
    // An ESRI grid gives its own cell size.
    let asc = "dem: \"../assets/terrain/valley.asc\", cell_size: 2.0,";
    edit(
        d,
        rel,
        "dem: \"../assets/terrain/flat.pgm\", cell_size: 4.0, height_scale: 0.1,",
        asc,
    );
    let (code, out) = shoal(d, &["check", rel]);
    refused(code, &out);
    let here = at(d, rel, "cell_size: ");
    assert!(
        out.contains(&format!("{here}: `cell_size` is for a PGM height map")),
        "{out}"
    );
}

const DRIVES_PROBE: &str = r#"Species(
    name: "probe",
    drives: (
        params: (hunger_model: Exponential, p0: -0.1, appetite: 0.0, d0: NaN, u: -1.0, c: inf),
        meal_size: -1.0,
    ),
    initial: "school",
    behaviors: [
        (
            name: "school",
            priority: 1,
            steer: Blend([
                (w: 1.0, steer: Zones(repulsion: 6.0, matching: 2.5, attraction: 1.0, soft: 1.5)),
                (w: 1.0, steer: Vicsek(radius: -4.0, noise: NaN, speed: inf)),
                (w: 1.0, steer: Disperse(below: -0.3)),
                (w: 1.0, steer: Separation(k: NaN, radius: -2.0)),
            ]),
        ),
    ],
    recipes: {
        "equal": Zones(repulsion: 2.0, matching: 2.0, attraction: 6.0),
    },
)
"#;

/// Seed 000 §2 drive constants and seed 003 group rules that would reach the tick loop as
/// NaN, infinite or out of order.
#[test]
fn drive_and_group_numbers_are_refused_at_their_keys() {
    let w = world();
    let d = w.path();
    write(d, "behaviors/probe.ron", DRIVES_PROBE);
    let (code, out) = shoal(d, &["check", "behaviors/probe.ron"]);
    refused(code, &out);
    let f = "behaviors/probe.ron";
    for (needle, msg) in [
        ("p0: ", "`p0` must be a finite number ≥ 0, not -0.1"),
        ("appetite: ", "`appetite` must be a finite number > 0, not 0"),
        ("d0: ", "`d0` must be a finite number ≥ 0, not NaN"),
        ("u: ", "`u` must be a finite number > 0, not -1"),
        ("c: ", "`c` must be a finite number > 0, not inf"),
        ("meal_size: ", "`meal_size` must be a finite number ≥ 0, not -1"),
        (
            "repulsion: ",
            "`repulsion` (6) must be below `matching` (2.5): seed 003's zones need repulsion < matching < attraction",
        ),
        (
            "Zones(repulsion: 6.0, matching: ",
            "`matching` (2.5) must be below `attraction` (1)",
        ),
        (
            "soft: ",
            "`soft` must be a number from 0 up to (not including) 1, not 1.5",
        ),
        ("Vicsek(radius: ", "`radius` must be a finite number ≥ 0, not -4"),
        ("noise: ", "`noise` must be a finite number ≥ 0, not NaN"),
        ("speed: ", "`speed` must be a finite number ≥ 0, not inf"),
        ("below: ", "`below` must be a finite number ≥ 0, not -0.3"),
        ("Separation(k: ", "`k` must be a finite number, not NaN"),
        (
            "\"equal\": Zones(repulsion: ",
            "`repulsion` (2) must be below `matching` (2)",
        ),
    ] {
        let here = at(d, f, needle);
        assert!(
            out.contains(&format!("{here}: {msg}")),
            "{here}: {msg}\n{out}"
        );
    }
    // Equal to the shipped sardine's zones, in order: accepted.
    let ok = DRIVES_PROBE
        .replace(
            "p0: -0.1, appetite: 0.0, d0: NaN, u: -1.0, c: inf",
            "p0: 0.1",
        )
        .replace("meal_size: -1.0", "meal_size: 1.0")
        .replace(
            "repulsion: 6.0, matching: 2.5, attraction: 1.0, soft: 1.5",
            "repulsion: 0.6, matching: 2.5, attraction: 6.0, soft: 0.0",
        )
        .replace(
            "radius: -4.0, noise: NaN, speed: inf",
            "radius: 4.0, noise: 0.1",
        )
        .replace("below: -0.3", "below: 0.3")
        .replace("k: NaN, radius: -2.0", "k: 1.0")
        .replace("matching: 2.0, attraction", "matching: 2.5, attraction");
    write(d, "behaviors/probe.ron", &ok);
    let (code, out) = shoal(d, &["check", "behaviors/probe.ron"]);
    assert_eq!(code, 0, "{out}");
}

#[test]
fn expectation_bounds_that_are_not_numbers_in_range_are_refused_at_their_key() {
    let w = world();
    let d = w.path();
    let f = "scenarios/school_formation.ron";
    // A polarization is |mean heading|, in [0, 1]: NaN would fail every run, 1.5 could never
    // be met.
    for bad in ["NaN", "-0.5", "1.5"] {
        edit(
            d,
            f,
            "MinPolarization(\"sardine\", 0.7)",
            &format!("MinPolarization(\"sardine\", {bad})"),
        );
        let (code, out) = shoal(d, &["test", f]);
        assert_eq!(code, 1, "{out}");
        let here = at(d, f, "expect: [");
        assert!(
            out.contains(&format!(
                "{here}: `MinPolarization` expects a polarization between 0 and 1, not {bad}"
            )),
            "{here}\n{out}"
        );
        edit(
            d,
            f,
            &format!("MinPolarization(\"sardine\", {bad})"),
            "MinPolarization(\"sardine\", 0.7)",
        );
    }
    // A window that never closes.
    let f = "scenarios/predator_attack.ron";
    edit(d, f, "within: 10.0", "within: inf");
    let (code, out) = shoal(d, &["test", f]);
    assert_eq!(code, 1, "{out}");
    let here = at(d, f, "after: 5.0, ");
    assert!(
        out.contains(&format!(
            "{here}: `after` and `within` must be finite numbers of seconds ≥ 0, not 5 and inf"
        )),
        "{here}\n{out}"
    );
}
