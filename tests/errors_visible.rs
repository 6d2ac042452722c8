//! Errors where the designer looks: `shoal run` prints its first script errors (agent, species,
//! place), and a live session's record (`shoal watch --record`) opens with `shoal view` and
//! `shoal rerun`; a folder that is neither names its path.

mod live_support;

use live_support::{wait_past_tick, Project};
use shoal::live::{LiveOptions, Session};
use std::process::{Command, Output};

fn shoal(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(args)
        .output()
        .expect("run shoal")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn run_prints_the_first_script_errors_with_agent_species_and_place() {
    let p = Project::debugging();
    let out = p.path("out");
    let o = shoal(&[
        "run".as_ref(),
        p.scenario().as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("script errors: "), "{t}");
    let first = t
        .lines()
        .find(|l| l.trim_start().starts_with("tick ") && l.contains("(fish): "))
        .unwrap_or_else(|| panic!("no script error line in:\n{t}"));
    assert!(
        first.contains("fish.rhai:") && first.contains("gave up after 40 passes"),
        "{first}"
    );
    // At most five printed in full.
    let listed = t.lines().filter(|l| l.contains("(fish): ")).count();
    assert!((1..=5).contains(&listed), "{t}");
}

#[test]
fn a_live_record_opens_with_view_and_rerun() {
    let p = Project::new();
    let rec = p.path("rec");
    let s = Session::start(
        &p.scenario(),
        LiveOptions {
            record: Some(rec.clone()),
            speed: 20.0,
            ..LiveOptions::default()
        },
    )
    .unwrap();
    wait_past_tick(&s, 30);
    assert!(s.stop_because("test over"));
    let ticks: u64 = serde_json::from_str::<serde_json::Value>(
        &std::fs::read_to_string(rec.join("live.json")).unwrap(),
    )
    .unwrap()["ticks"]
        .as_u64()
        .unwrap();

    let o = shoal(&["view".as_ref(), rec.as_os_str()]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("live session record"), "{t}");
    assert!(rec.join("replay/view.html").is_file(), "{t}");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rec.join("replay/manifest.json")).unwrap())
            .unwrap();
    assert_eq!(manifest["ticks"].as_u64(), Some(ticks));

    let o = shoal(&["rerun".as_ref(), rec.as_os_str()]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(rec.join("rerun/trajectories.csv").is_file(), "{t}");
    // The re-run and the replay are the same run.
    assert_eq!(
        std::fs::read(rec.join("rerun/trajectories.csv")).unwrap(),
        std::fs::read(rec.join("replay/trajectories.csv")).unwrap()
    );

    // A broken record names the file at fault.
    std::fs::remove_file(rec.join("reloads.jsonl")).unwrap();
    std::fs::remove_dir_all(rec.join("replay")).unwrap();
    let o = shoal(&["view".as_ref(), rec.as_os_str()]);
    let t = text(&o);
    assert!(!o.status.success());
    assert!(
        t.contains(&rec.join("reloads.jsonl").display().to_string()),
        "{t}"
    );
}

#[test]
fn view_and_rerun_of_a_folder_that_is_no_run_name_it() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("not-a-run");
    std::fs::create_dir_all(&dir).unwrap();
    for cmd in ["view", "rerun"] {
        let o = shoal(&[cmd.as_ref(), dir.as_os_str()]);
        let t = text(&o);
        assert!(!o.status.success(), "{cmd}: {t}");
        assert!(t.contains(&dir.display().to_string()), "{cmd}: {t}");
    }
}
