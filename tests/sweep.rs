//! `shoal sweep` and `shoal run --set` end to end: a run with settings re-runs bit for bit from
//! its folder; `sweeps/tiny_grid.ron` (2 axes × 3 seeds) collected after `run -j 2` and after
//! eight `run --index` processes in shuffled order, one of them killed mid-sweep and run again,
//! gives the same `results.csv` bytes; changed inputs and unfinished runs are refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn shoal() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_shoal"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

fn ok(o: Output) -> String {
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "{text}");
    text
}

#[test]
fn a_run_with_settings_reruns_bit_for_bit() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("run");
    ok(shoal()
        .args([
            "run",
            "scenarios/tiny.ron",
            "-q",
            "--duration",
            "2",
            "--out",
        ])
        .arg(&out)
        .args(["--set", "scenario.groups[reef_fish].count=12"])
        .args(["--set", "reef_fish.senses.vision_radius=4.5"])
        .output()
        .unwrap());
    let m = std::fs::read_to_string(out.join("manifest.json")).unwrap();
    assert!(m.contains("\"reef_fish.senses.vision_radius=4.5\""), "{m}");
    let copy = std::fs::read_to_string(out.join("inputs/behaviors/reef_fish.ron")).unwrap();
    assert!(
        copy.contains("vision_radius: 4.5,"),
        "the copy is the patched text"
    );
    let r = ok(shoal().arg("rerun").arg(&out).output().unwrap());
    assert!(r.contains("re-run matches bit for bit"), "{r}");
    let o = shoal()
        .args(["run", "scenarios/tiny.ron", "-q", "--out"])
        .arg(&out)
        .args(["--set", "scenario.groups[0].cont=3"])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        e.contains("setting `scenario.groups[0].cont=3`: unknown field `cont`"),
        "{e}"
    );
    assert!(e.contains("(did you mean `count`?)"), "{e}");
}

fn sweep_run(out: &Path, extra: &[&str]) -> Command {
    let mut c = shoal();
    c.args(["sweep", "run", "sweeps/tiny_grid.ron", "-q", "--out"])
        .arg(out)
        .args(extra);
    c
}

fn collect(out: &Path) -> Vec<u8> {
    ok(shoal()
        .args(["sweep", "collect"])
        .arg(out)
        .output()
        .unwrap());
    std::fs::read(out.join("results.csv")).unwrap()
}

#[test]
fn results_are_the_same_whatever_the_sharding_order_and_interruptions() {
    let d = tempfile::tempdir().unwrap();
    let plan = ok(shoal()
        .args(["sweep", "plan", "sweeps/tiny_grid.ron"])
        .output()
        .unwrap());
    assert!(
        plan.contains("12 run(s) = 4 point(s) × 3 seed(s)"),
        "{plan}"
    );
    assert!(!d.path().join("a").exists());

    let a = d.path().join("a");
    ok(sweep_run(&a, &["-j", "2"]).output().unwrap());
    let table_a = collect(&a);

    let b = d.path().join("b");
    let shuffled = ["7,2", "11,0", "5,9", "3,10", "1", "8", "4", "6"];
    // The first process is killed once one of its runs is in place, mid-way through the other.
    let mut child = sweep_run(&b, &["--index", shuffled[0]]).spawn().unwrap();
    let runs = b.join("runs");
    let t0 = std::time::Instant::now();
    while !runs.join("00007").exists() && !runs.join("00002").exists() {
        if child.try_wait().unwrap().is_some() || t0.elapsed().as_secs() > 60 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    child.kill().ok();
    child.wait().unwrap();
    // Whatever it left is whole or hidden: no visible folder without its result.
    for e in std::fs::read_dir(&runs).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            name.starts_with(".tmp-") || p.join("result.json").is_file(),
            "{name}"
        );
    }
    let o = shoal().args(["sweep", "collect"]).arg(&b).output().unwrap();
    assert!(
        !o.status.success(),
        "a sweep with runs missing is not collected"
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("run(s) not finished: "), "{e}");
    assert!(e.contains("--partial"), "{e}");
    for idx in shuffled.iter().skip(1).chain(&shuffled[..1]) {
        ok(sweep_run(&b, &["--index", idx]).output().unwrap());
    }
    assert_eq!(collect(&b), table_a, "sharded, shuffled and resumed");

    // Changed inputs are refused, naming the file.
    let sweep = std::fs::read_to_string("sweeps/tiny_grid.ron").unwrap();
    let copy = d.path().join("s");
    std::fs::create_dir_all(&copy).unwrap();
    let f = copy.join("grid.ron");
    let abs = |p: &str| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join(p)
            .display()
            .to_string()
    };
    let text = sweep
        .replace(
            "\"../scenarios/tiny.ron\"",
            &format!("{:?}", abs("scenarios/tiny.ron")),
        )
        .replace(
            "\"tiny_reduce.rhai\"",
            &format!("{:?}", abs("sweeps/tiny_reduce.rhai")),
        );
    std::fs::write(&f, &text).unwrap();
    let c = d.path().join("c");
    let run_c = || {
        shoal()
            .args(["sweep", "run", "-q", "--index", "0", "--out"])
            .arg(&c)
            .arg(&f)
            .output()
            .unwrap()
    };
    ok(run_c());
    std::fs::write(&f, text.replace("seed: 7", "seed: 8")).unwrap();
    let o = run_c();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("holds runs of other inputs: grid.ron changed"),
        "{e}"
    );
}

#[test]
fn a_run_that_fails_records_its_error_in_its_row() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("bad.ron");
    let tiny = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/tiny.ron");
    std::fs::write(
        &f,
        format!(
            "Sweep(scenario: {:?}, duration: Some(1.0), axes: [(key: \"scenario.groups[0].count\", values: [3, -1])])",
            tiny.display().to_string()
        ),
    )
    .unwrap();
    let out = d.path().join("o");
    let o = shoal()
        .args(["sweep", "run", "-q", "-j", "2", "--out"])
        .arg(&out)
        .arg(&f)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("run 1 failed: "), "{e}");
    assert!(e.contains("`count` must be ≥ 0, not -1"), "{e}");
    collect(&out);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[1].contains(",ok,"), "{csv}");
    assert!(lines[2].contains(",failed,"), "{csv}");
    assert!(lines[2].contains("must be ≥ 0, not -1"), "{csv}");
}
