//! `shoal bench` through the command line: the table it prints, and `--repeat`'s median row.

mod common;

use common::{named_figures, shoal};

/// The numeric columns of the row of `workload`.
fn row(stdout: &str, workload: &str) -> Vec<f64> {
    let line = stdout
        .lines()
        .find(|l| l.split_whitespace().next() == Some(workload))
        .unwrap_or_else(|| panic!("no {workload} row in:\n{stdout}"));
    line.split_whitespace()
        .skip(1)
        .map(|f| f.parse().unwrap_or(f64::NAN))
        .collect()
}

#[test]
fn a_repeated_bench_prints_the_median_run_between_the_slowest_and_fastest() {
    let (code, out, err) = shoal(&[
        "bench",
        "boids",
        "--agents",
        "300",
        "--ticks",
        "3",
        "--threads",
        "1",
        "--repeat",
        "3",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("slowest") && out.contains("fastest"), "{out}");
    // agents ticks ticks/s agent-upd/s ms/tick ns/upd nbrs B/agent slowest fastest
    let r = row(&out, "boids");
    assert_eq!(r.len(), 10, "{out}");
    assert_eq!((r[0], r[1]), (300.0, 3.0));
    let (ticks_per_s, slowest, fastest) = (r[2], r[8], r[9]);
    assert!(
        slowest > 0.0 && slowest <= ticks_per_s && ticks_per_s <= fastest,
        "{out}"
    );
    // agent-updates per second are agents × ticks per second.
    assert!((r[3] / (300.0 * ticks_per_s) - 1.0).abs() < 0.01, "{out}");
}

#[test]
fn a_single_bench_run_keeps_the_nine_column_table() {
    let (code, out, err) = shoal(&["bench", "boids", "--agents", "300", "--ticks", "2"]);
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains("slowest"), "{out}");
    assert_eq!(row(&out, "boids").len(), 8, "{out}");
}

#[test]
fn a_repeat_of_zero_is_refused() {
    let (code, _, err) = shoal(&["bench", "boids", "--repeat", "0"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--repeat"), "{err}");
}

/// The first line of `out` that starts with `prefix` (indented or not, as the notes under a
/// row are): its number and what follows the prefix.
fn note<'a>(out: &'a str, prefix: &str) -> (usize, &'a str) {
    out.lines()
        .enumerate()
        .find_map(|(k, l)| l.trim().strip_prefix(prefix).map(|rest| (k, rest)))
        .unwrap_or_else(|| panic!("no line starting {prefix:?} in:\n{out}"))
}

#[test]
fn stages_print_each_stage_under_its_row_and_add_up_to_at_most_the_tick() {
    let (code, out, err) = shoal(&[
        "bench", "boids", "--agents", "300", "--ticks", "4", "--stages",
    ]);
    assert_eq!(code, 0, "{err}");
    let (at, stages) = note(&out, "stages, ms/tick: ");
    let above = at.checked_sub(1).and_then(|k| out.lines().nth(k));
    assert!(
        above.is_some_and(|l| l.starts_with("boids")),
        "not under the boids row:\n{out}"
    );
    let parts = named_figures(stages);
    let names: Vec<&str> = parts.iter().map(|p| p.0).collect();
    assert_eq!(names, ["index", "perception", "agents", "events"], "{out}");
    let ms_per_tick = row(&out, "boids")[4];
    let staged: f64 = parts.iter().map(|p| p.1).sum();
    // Each of the five figures is rounded to 0.001 ms.
    assert!(
        staged <= ms_per_tick + 0.003,
        "{staged} > {ms_per_tick}:\n{out}"
    );
    assert!(parts[1].1 > 0.0 && parts[2].1 > 0.0, "{out}");
    // Without the flag, no such line.
    let (_, out, _) = shoal(&["bench", "boids", "--agents", "300", "--ticks", "2"]);
    assert!(!out.contains("stages"), "{out}");
}

#[test]
fn a_long_enough_run_says_how_fast_its_first_and_last_tenths_went() {
    let (code, out, err) = shoal(&["bench", "flock", "--agents", "200", "--ticks", "100"]);
    assert_eq!(code, 0, "{err}");
    let (_, line) = note(&out, "steady: ");
    let figures: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|f| f.parse().ok())
        .collect();
    let [first, last, ratio] = figures[..] else {
        panic!("not three figures in {line:?}");
    };
    assert!(first > 0.0 && last > 0.0, "{line}");
    assert!(
        (ratio - last / first).abs() <= 0.01 + 0.002 * ratio,
        "{ratio} is not {last} / {first}"
    );
    // A tenth of the ticks never took longer than the whole run: each tenth's speed is at
    // least a tenth of the whole run's (less the rounding of the figures).
    let whole = row(&out, "flock")[2];
    assert!(first.min(last) >= 0.1 * whole * 0.99, "{out}");
    // Under 100 timed ticks, no such line (a tenth would be a handful of ticks).
    let (code, out, _) = shoal(&["bench", "flock", "--agents", "200", "--ticks", "99"]);
    assert_eq!(code, 0);
    assert!(!out.contains("steady"), "{out}");
}

#[test]
fn every_boids_row_is_read_against_the_reference_kernel() {
    let (code, out, err) = shoal(&["bench", "boids", "--agents", "300", "--ticks", "3"]);
    assert_eq!(code, 0, "{err}");
    let (_, note) = note(&out, "reference kernel");
    let ratio: f64 = note
        .rsplit("boids runs at ")
        .next()
        .and_then(|r| r.split('×').next())
        .and_then(|r| r.parse().ok())
        .unwrap_or_else(|| panic!("no ratio in {note}"));
    assert!(ratio > 0.0 && ratio.is_finite(), "{note}");
    // The reference workload alone sees about as many kin as boids do at this density.
    let (code, out, err) = shoal(&["bench", "reference", "--agents", "2000", "--ticks", "2"]);
    assert_eq!(code, 0, "{err}");
    let kin = row(&out, "reference")[6];
    assert!((20.0..35.0).contains(&kin), "{kin} kin:\n{out}");
}

#[test]
fn the_weighted_plan_states_what_it_gave_up() {
    let (code, out, err) = shoal(&[
        "bench",
        "plan-weighted",
        "--ticks",
        "1",
        "--search-weight",
        "1.1",
    ]);
    assert_eq!(code, 0, "{err}");
    let note = out
        .lines()
        .find(|l| l.contains("search weight 1.1: score"))
        .unwrap_or_else(|| panic!("no note under the row:\n{out}"));
    assert!(
        note.contains("bound +10 %") && note.contains("nodes expanded"),
        "{note}"
    );
    let (code, _, err) = shoal(&["bench", "plan-weighted", "--search-weight", "0.5"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("the search weight must be from 1 to 10, not 0.5"),
        "{err}"
    );
}
