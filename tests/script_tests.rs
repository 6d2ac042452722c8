//! Runs every shipped designers' test (`behaviors/tests/*.rhai`, `scenarios/tests/*.ron`) through
//! the library runner, so CI covers them, and checks what failures and errors print using the
//! fixtures kept for that (`*/tests/fixtures/`, excluded from the default run).

use shoal::testing::{self, Options, Report, TestResult, TestStatus};
use std::path::{Path, PathBuf};
use std::process::Command;

fn run(paths: &[&str], opts: &Options) -> Report {
    let paths: Vec<PathBuf> = paths.iter().map(PathBuf::from).collect();
    testing::run(&paths, opts)
}

fn only(report: &Report) -> &TestResult {
    assert_eq!(report.results.len(), 1, "{report}");
    &report.results[0]
}

fn find<'a>(report: &'a Report, id: &str) -> &'a TestResult {
    report
        .results
        .iter()
        .find(|r| r.id == id)
        .unwrap_or_else(|| panic!("no test {id} in\n{report}"))
}

#[test]
fn every_shipped_script_and_scenario_test_passes() {
    let report = run(&["behaviors/tests", "scenarios/tests"], &Options::default());
    let failures: Vec<String> = report
        .results
        .iter()
        .filter(|r| r.status != TestStatus::Passed)
        .map(|r| format!("{} {}\n{}", r.id, r.details, ""))
        .collect();
    assert!(
        failures.is_empty(),
        "{} designers' tests did not pass:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(report.passed() >= 30, "{report}");
    assert!(
        report.results.iter().all(|r| !r.id.contains("fixtures")),
        "fixtures must only run when named"
    );
    assert_eq!(
        report.summary(),
        format!("{} passed, 0 failed", report.results.len())
    );
}

#[test]
fn every_shipped_species_has_tests_exercising_each_behavior() {
    let mut species: Vec<String> = std::fs::read_dir("behaviors")
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    species.sort();
    assert!(species.len() >= 2);
    let report = run(&["behaviors/tests"], &Options::default());
    let coverage = report.coverage();
    for s in &species {
        assert!(
            Path::new(&format!("behaviors/tests/{s}.rhai")).is_file(),
            "species {s} has no behaviors/tests/{s}.rhai"
        );
        let line = coverage
            .lines()
            .find(|l| l.starts_with(&format!("{s}: ")))
            .unwrap_or_else(|| panic!("{s} missing from the coverage report:\n{coverage}"));
        let (a, rest) = line[s.len() + 2..].split_once(" of ").unwrap();
        let b = rest.split_once(' ').unwrap().0;
        assert_eq!(a, b, "{s}: some behavior is never exercised:\n{coverage}");
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let one = run(
        &["behaviors/tests"],
        &Options {
            threads: Some(1),
            ..Options::default()
        },
    );
    let four = run(
        &["behaviors/tests"],
        &Options {
            threads: Some(4),
            ..Options::default()
        },
    );
    assert_eq!(one.results, four.results);
    assert_eq!(one.coverage(), four.coverage());
}

#[test]
fn a_failing_test_prints_where_what_and_the_last_decisions() {
    let report = run(
        &["behaviors/tests/fixtures/failing.rhai"],
        &Options::default(),
    );
    let r = only(&report);
    assert_eq!(
        r.id,
        "behaviors/tests/fixtures/failing.rhai::test_a_fish_ignores_a_shark"
    );
    assert_eq!(r.status, TestStatus::Failed);
    let lines: Vec<&str> = r.details.lines().collect();
    assert_eq!(
        lines[0],
        "behaviors/tests/fixtures/failing.rhai:12:5: expected nemo (reef_fish #0) in `wander`, but it is in `escape`"
    );
    assert_eq!(lines[1], "12 |     assert_behavior(fish, \"wander\");");
    assert_eq!(lines[2], "   |     ^");
    assert!(
        lines[3]
            .starts_with("nemo (reef_fish #0) now (tick 3, 0.15 s): in `escape` [stack: wander]"),
        "{}",
        r.details
    );
    assert_eq!(lines[4], "last decisions of nemo (reef_fish #0):");
    assert_eq!(
        lines[5],
        "  tick 1 (0.05 s): wander → escape, interrupted (when sees predator or (heard danger and perceives predator)) [stack: wander]"
    );
    assert_eq!(report.summary(), "0 passed, 1 failed");
    let shown = report.to_string();
    assert!(shown.starts_with(
        "FAIL  behaviors/tests/fixtures/failing.rhai::test_a_fish_ignores_a_shark\n      behaviors/tests/fixtures/failing.rhai:12:5: expected"
    ));
    assert!(shown.ends_with("\n0 passed, 1 failed"));
}

#[test]
fn a_syntax_error_is_located_in_the_test_file() {
    let report = run(
        &["behaviors/tests/fixtures/syntax_error.rhai"],
        &Options::default(),
    );
    let r = only(&report);
    assert_eq!(r.id, "behaviors/tests/fixtures/syntax_error.rhai");
    assert_eq!(r.status, TestStatus::Error);
    assert_eq!(
        r.details,
        "behaviors/tests/fixtures/syntax_error.rhai:5:19: Unexpected ';'; the `(` at line 5, column 18 is never closed\n5 |     let w = world(;\n  |                   ^"
    );
    assert_eq!(report.failed(), 1);
}

#[test]
fn tests_that_never_end_are_stopped_by_a_limit() {
    let report = run(
        &["behaviors/tests/fixtures/endless.rhai"],
        &Options::default(),
    );
    let loops = find(
        &report,
        "behaviors/tests/fixtures/endless.rhai::test_loops_forever",
    );
    assert_eq!(loops.status, TestStatus::Error);
    assert!(
        loops.details.starts_with(
            "behaviors/tests/fixtures/endless.rhai:4:1: test exceeded its limit of 5000000 operations"
        ),
        "{}",
        loops.details
    );
    let waits = find(
        &report,
        "behaviors/tests/fixtures/endless.rhai::test_waits_forever",
    );
    assert_eq!(waits.status, TestStatus::Error);
    assert!(
        waits.details.starts_with(
            "behaviors/tests/fixtures/endless.rhai:15:7: test exceeded its limit of 20000 ticks"
        ),
        "{}",
        waits.details
    );
    // The limits are options.
    let report = run(
        &["behaviors/tests/fixtures/endless.rhai"],
        &Options {
            filter: Some("waits".into()),
            max_ticks: 50,
            ..Options::default()
        },
    );
    assert!(only(&report).details.contains("limit of 50 ticks"));
}

#[test]
fn an_unknown_behavior_name_is_an_error_at_load() {
    let report = run(
        &["behaviors/tests/fixtures/unknown_behavior.rhai"],
        &Options::default(),
    );
    let r = only(&report);
    assert_eq!(r.id, "behaviors/tests/fixtures/unknown_behavior.rhai");
    assert_eq!(r.status, TestStatus::Error);
    assert_eq!(
        r.details.lines().next().unwrap(),
        "behaviors/tests/fixtures/unknown_behavior.rhai:8:27: \"escpae\" is not a behavior of species \"reef_fish\" (did you mean `escape`?): it has \"avoid_static\", \"escape\", \"avoid_dynamic\", \"eat\", \"eat/bite\", \"eat/chase\", \"mate\", \"mate/court\", \"mate/leave\", \"make_room\", \"school\", \"wander\""
    );
    let lines: Vec<&str> = r.details.lines().collect();
    assert!(
        lines.iter().any(|l| l.starts_with(
            "behaviors/tests/fixtures/unknown_behavior.rhai:9:47: \"wnder\" is not a behavior"
        )),
        "{}",
        r.details
    );
    // Both ends of an asserted transition are behavior names too.
    assert!(
        lines.iter().any(|l| l.starts_with(
            "behaviors/tests/fixtures/unknown_behavior.rhai:16:39: \"eat/bit\" is not a behavior"
        ) && l.contains("did you mean `eat/bite`?")),
        "{}",
        r.details
    );
}

#[test]
fn an_unknown_species_name_is_an_error_at_load() {
    let report = run(
        &["behaviors/tests/fixtures/unknown_species.rhai"],
        &Options::default(),
    );
    let r = only(&report);
    assert_eq!(r.status, TestStatus::Error);
    assert!(
        r.details.starts_with(
            "behaviors/tests/fixtures/unknown_species.rhai:5:25: unknown species \"sardin\" (did you mean `sardine`?): behaviors has "
        ),
        "{}",
        r.details
    );
}

#[test]
fn scenario_expectations_fail_with_what_was_observed() {
    let report = run(&["scenarios/tests/fixtures/unmet.ron"], &Options::default());
    let r = only(&report);
    assert_eq!(r.status, TestStatus::Failed);
    assert_eq!(
        r.details,
        "FAIL expected at least 1 catch: 0 catches\nok   expected no script errors: none\n"
    );
    let report = run(
        &["scenarios/tests/fixtures/bad_expect.ron"],
        &Options::default(),
    );
    let r = only(&report);
    assert_eq!(r.status, TestStatus::Error);
    assert!(
        r.details.starts_with(
            "scenarios/tests/fixtures/bad_expect.ron:8:56: species \"shark\" has no behavior \"sleep\": expected one of avoid_static, hunt, stalk, rest, patrol"
        ),
        "{}",
        r.details
    );
}

#[test]
fn the_filter_selects_tests_by_name() {
    let report = run(
        &["behaviors/tests"],
        &Options {
            filter: Some("stack_unwinds".into()),
            ..Options::default()
        },
    );
    let r = only(&report);
    assert_eq!(
        r.id,
        "behaviors/tests/reef_fish.rhai::test_the_stack_unwinds_in_order"
    );
    assert_eq!(r.status, TestStatus::Passed);
}

#[test]
fn the_command_prints_one_line_per_test_and_exits_non_zero_on_failure() {
    let shoal = env!("CARGO_BIN_EXE_shoal");
    let out = Command::new(shoal)
        .args(["test", "behaviors/tests/fixtures/failing.rhai"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().last(), Some("0 passed, 1 failed"));
    assert!(stdout.starts_with("FAIL  behaviors/tests/fixtures/failing.rhai::"));

    let out = Command::new(shoal)
        .args(["test", "--filter", "lone", "behaviors/tests"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(lines.len() >= 3, "{stdout}");
    assert!(lines[..lines.len() - 1]
        .iter()
        .all(|l| l.starts_with("ok    ")));
    assert_eq!(
        lines.last(),
        Some(&format!("{} passed, 0 failed", lines.len() - 1).as_str())
    );

    let out = Command::new(shoal)
        .args(["test", "no/such/folder"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn coverage_lists_what_no_test_exercised() {
    let report = run(
        &["behaviors/tests"],
        &Options {
            filter: Some("reef_fish.rhai::test_a_lone_fish_wanders".into()),
            ..Options::default()
        },
    );
    assert_eq!(report.passed(), 1);
    let c = report.coverage();
    let fish: Vec<&str> = c
        .lines()
        .skip_while(|l| !l.starts_with("reef_fish: "))
        .take(2)
        .collect();
    assert!(
        fish[0].starts_with("reef_fish: 1 of 12 behaviors, 0 of "),
        "{c}"
    );
    assert_eq!(
        fish[1],
        "  behaviors never exercised: avoid_static, escape, avoid_dynamic, eat, eat/bite, eat/chase, mate, mate/court, mate/leave, make_room, school"
    );
    assert!(
        c.contains("    wander → avoid_static (interrupted), escape (interrupted),"),
        "{c}"
    );
}
