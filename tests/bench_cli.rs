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

#[test]
fn stages_print_each_stage_under_its_row_and_add_up_to_at_most_the_tick() {
    let (code, out, err) = shoal(&[
        "bench", "boids", "--agents", "300", "--ticks", "4", "--stages",
    ]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with("boids"))
        .unwrap_or_else(|| panic!("no boids row in:\n{out}"));
    let stages = lines
        .get(at + 1)
        .and_then(|l| l.trim().strip_prefix("stages, ms/tick: "))
        .unwrap_or_else(|| panic!("no stages line under the row:\n{out}"));
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
