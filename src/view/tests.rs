//! Unit tests: reading run folders and building the payload and page.

use std::fs;
use std::path::Path;

use super::payload::{self, Payload};
use super::*;

fn header() -> String {
    crate::record::schema::header(&crate::record::schema::TRAJECTORY_COLUMNS)
}

fn manifest(status: &str) -> String {
    format!(
        r#"{{"format":1,"status":"{status}","scenario":"reef","seed":7,"dt":0.05,"ticks":6,"record_interval":2,"threads":2,"files":{{"behaviors/reef_fish.ron":"00"}},"summary":{{"deaths":1}}}}"#
    )
}

const WORLD: &str = r##"{"bounds":{"min":[-10,-5,-10],"max":[10,5,10]},
 "obstacles":[{"id":0,"shape":"sphere","center":[0,0,0],"radius":2,"removed_tick":null},
              {"id":1,"shape":"box","min":[3,-1,3],"max":[5,1,5],"removed_tick":4}],
 "species":[{"name":"reef_fish","color":"#e0a030","length":1.0,"behaviors":["wander","escape","eat"]},
            {"name":"shark","color":"#708090","length":3.0,"behaviors":["patrol","hunt"]}],
 "terrain":null,"plans":[]}"##;

fn row(tick: u64, id: u32, species: &str, x: f32, behavior: &str) -> String {
    format!(
        "{tick},{:.2},{id},{species},{x},1,2,1,0,0,1.5,{behavior},2,0.5,0.25,1.0,0.5,-0.1",
        tick as f64 * 0.05
    )
}

/// A run of 3 recorded ticks: 3 agents, then 3, then 2 (one died); food at ticks 0 and 4.
fn write_run(dir: &Path, status: &str) {
    fs::write(dir.join("manifest.json"), manifest(status)).unwrap();
    fs::write(dir.join("world.json"), WORLD).unwrap();
    let mut t = vec![header()];
    for tick in [0u64, 2, 4] {
        t.push(row(tick, 1, "reef_fish", tick as f32, "wander"));
        t.push(row(
            tick,
            2,
            "shark",
            0.0,
            if tick < 2 { "patrol" } else { "hunt" },
        ));
        if tick < 4 {
            t.push(row(tick, 5, "crab", 0.0, "scuttle"));
        }
    }
    fs::write(dir.join("trajectories.csv"), t.join("\n") + "\n").unwrap();
    fs::write(
        dir.join("food.csv"),
        "tick,id,x,y,z\n0,1,1,2,3\n0,2,4,5,6\n4,1,1,2,3\n",
    )
    .unwrap();
    let events = [
        r#"{"tick":0,"time":0,"kind":"spawn","agent":1,"species":"reef_fish"}"#,
        r#"{"tick":2,"time":0.1,"kind":"transition","agent":2,"species":"shark","from":"patrol","to":"hunt","cause":"activated","condition":"hunger > 0.6 and sees prey </script>","stack":["patrol","hunt"]}"#,
        r#"{"tick":1,"time":0.05,"kind":"transition","agent":1,"species":"reef_fish","from":"","to":"wander","cause":"fallback","condition":"","stack":["wander"]}"#,
        r#"{"tick":3,"time":0.15,"kind":"death","agent":5,"species":"crab","cause":"caught"}"#,
        r#"{"tick":3,"time":0.15,"kind":"script_error","agent":2,"species":"shark","file":"scripts/hunt.rhai","line":4,"col":9,"message":"unknown variable"}"#,
    ];
    fs::write(dir.join("events.jsonl"), events.join("\n") + "\n").unwrap();
}

fn decode(b64: &str) -> Vec<u8> {
    let val = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => (c - b'A') as u32,
            b'a'..=b'z' => (c - b'a' + 26) as u32,
            b'0'..=b'9' => (c - b'0' + 52) as u32,
            b'+' => 62,
            _ => 63,
        }
    };
    let mut out = Vec::new();
    for chunk in b64.as_bytes().chunks(4) {
        let pad = chunk.iter().filter(|&&c| c == b'=').count();
        let n = chunk
            .iter()
            .fold(0u32, |n, &c| (n << 6) | if c == b'=' { 0 } else { val(c) });
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..3 - pad]);
    }
    out
}

fn col<'a>(p: &'a Payload, name: &str) -> &'a str {
    &p.columns.iter().find(|c| c.name == name).unwrap().base64
}

fn f32s(p: &Payload, name: &str) -> Vec<f32> {
    decode(col(p, name))
        .chunks(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

fn u32s(p: &Payload, name: &str) -> Vec<u32> {
    decode(col(p, name))
        .chunks(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

fn build(dir: &Path) -> Payload {
    payload::build(dir, DEFAULT_MAX_PAYLOAD_BYTES).unwrap()
}

#[test]
fn frames_agents_and_food_per_frame() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let p = build(tmp.path());
    let fr = &p.meta["frames"];
    assert_eq!(fr["count"], 3);
    assert_eq!(fr["tick"], serde_json::json!([0, 2, 4]));
    assert_eq!(fr["offset"], serde_json::json!([0, 3, 6, 8]));
    assert_eq!(fr["food_offset"], serde_json::json!([0, 2, 2, 3]));
    assert_eq!(p.meta["rows"], 8);
    assert_eq!(p.meta["stride"], 1);
    assert_eq!(u32s(&p, "id"), vec![1, 2, 5, 1, 2, 5, 1, 2]);
    let pos = f32s(&p, "pos");
    assert_eq!(pos.len(), 24);
    assert_eq!(&pos[18..21], &[4.0, 1.0, 2.0]);
    assert_eq!(f32s(&p, "food").len(), 9);
    // drives are bytes: 0.5 → 128, 1.0 → 255
    assert_eq!(decode(col(&p, "hunger"))[0], 128);
    assert_eq!(decode(col(&p, "fear"))[0], 255);
}

#[test]
fn species_and_behavior_tables_extend_the_world() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let p = build(tmp.path());
    let names: Vec<&str> = p.meta["species"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["reef_fish", "shark", "crab"]);
    assert_eq!(p.meta["species"][1]["length"], 3.0);
    assert_eq!(
        p.meta["behaviors"],
        serde_json::json!(["wander", "escape", "eat", "patrol", "hunt", "scuttle"])
    );
    assert_eq!(decode(col(&p, "species")), vec![0, 1, 2, 0, 1, 2, 0, 1]);
}

#[test]
fn histories_are_sorted_by_agent_then_tick() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let p = build(tmp.path());
    assert_eq!(p.meta["history"]["count"], 2);
    assert_eq!(u32s(&p, "h_agent"), vec![1, 2]);
    assert_eq!(u32s(&p, "h_tick"), vec![1, 2]);
    let strings = p.meta["history"]["strings"].as_array().unwrap();
    let to = u32s(&p, "h_to");
    assert_eq!(strings[to[1] as usize], "hunt");
    let stack = u32s(&p, "h_stack");
    assert_eq!(strings[stack[1] as usize], "patrol > hunt");
    assert_eq!(p.meta["deaths"]["5"], serde_json::json!([3, "caught"]));
    assert_eq!(p.meta["event_counts"]["transition"], 2);
    assert_eq!(p.meta["script_errors"].as_array().unwrap().len(), 1);
}

#[test]
fn page_embeds_payload_safely() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let html = build_html(tmp.path()).unwrap();
    assert!(html.contains("window.SHOAL_LIVE = false;"));
    assert!(html.contains("id=\"shoal-meta\""));
    assert!(html.contains("data-name=\"pos\" data-kind=\"f32\""));
    // the condition's `</script>` must not close the data element early
    // (page scripts, meta, columns, the explanation table)
    assert_eq!(html.matches("</script>").count(), 2 + 1 + 20 + 1);
    assert!(html.contains("sees prey \\u003c/script>"));
    assert!(!html.contains("/*@JS@*/"));
    assert!(html.contains("data-testid=\"agent-panel\""));
}

#[test]
fn incomplete_run_sets_flag_and_skips_unfinished_line() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "incomplete");
    let path = tmp.path().join("trajectories.csv");
    let mut text = fs::read_to_string(&path).unwrap();
    text.push_str("6,0.30,1,reef_fi");
    fs::write(&path, text).unwrap();
    let p = build(tmp.path());
    assert_eq!(p.meta["incomplete"], true);
    assert_eq!(p.meta["frames"]["count"], 3);
    let notes = p.meta["notes"].as_array().unwrap();
    assert!(
        notes[0].as_str().unwrap().contains("trajectories.csv"),
        "{notes:?}"
    );

    write_run(tmp.path(), "complete");
    assert_eq!(build(tmp.path()).meta["incomplete"], false);
}

#[test]
fn unfinished_line_of_a_complete_run_is_an_error() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let path = tmp.path().join("trajectories.csv");
    let mut text = fs::read_to_string(&path).unwrap();
    text.push_str("6,0.30,1,reef_fi");
    fs::write(&path, text).unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert_eq!(err.line(), Some(10));
}

#[test]
fn malformed_csv_line_names_file_line_and_field() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let path = tmp.path().join("trajectories.csv");
    let text = fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines[4] = lines[4].replace(",1.5,", ",fast,");
    fs::write(&path, lines.join("\n") + "\n").unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert_eq!(err.file(), path);
    assert_eq!(err.line(), Some(5));
    let msg = err.to_string();
    assert!(msg.contains("trajectories.csv:5:"), "{msg}");
    assert!(msg.contains("`speed`") && msg.contains("`fast`"), "{msg}");
}

#[test]
fn wrong_field_count_and_header_are_located() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let path = tmp.path().join("food.csv");
    fs::write(&path, "tick,id,x,y,z\n0,1,1,2\n").unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert_eq!((err.file(), err.line()), (path.as_path(), Some(2)));
    assert!(err
        .to_string()
        .contains("expected 5 comma-separated fields"));

    fs::write(&path, "tick,x,y,z\n").unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert_eq!(err.line(), Some(1));
    assert!(err.to_string().contains("unexpected header"));
}

#[test]
fn ticks_and_ids_must_ascend() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let path = tmp.path().join("trajectories.csv");
    let rows = [
        header(),
        row(0, 2, "shark", 0.0, "patrol"),
        row(0, 1, "shark", 0.0, "patrol"),
    ];
    fs::write(&path, rows.join("\n") + "\n").unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert_eq!(err.line(), Some(3));
    assert!(err.to_string().contains("ids must ascend"));

    let rows = [
        header(),
        row(2, 1, "shark", 0.0, "patrol"),
        row(0, 1, "shark", 0.0, "patrol"),
    ];
    fs::write(&path, rows.join("\n") + "\n").unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert_eq!(err.line(), Some(3));
}

#[test]
fn malformed_event_and_json_files_are_located() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let path = tmp.path().join("events.jsonl");
    fs::write(&path, "{\"tick\":0,\"kind\":\"spawn\"}\n{\"tick\":1,\n").unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert_eq!((err.file(), err.line()), (path.as_path(), Some(2)));

    fs::write(&path, "{\"kind\":\"spawn\"}\n").unwrap();
    assert!(build_html(tmp.path())
        .unwrap_err()
        .to_string()
        .contains("no `tick`"));

    fs::remove_file(&path).unwrap();
    let world = tmp.path().join("world.json");
    fs::write(&world, "{\"bounds\":{\"min\":[0,0,0],\n\"max\":[1,1]}}").unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert_eq!((err.file(), err.line()), (world.as_path(), Some(2)));
}

#[test]
fn terrain_size_is_checked() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let world = WORLD.replace(
        "\"terrain\":null",
        "\"terrain\":{\"origin\":[0,0],\"cell\":2,\"cols\":2,\"rows\":2,\"heights\":[1,2,3],\"blocked\":[0,0,0,1]}",
    );
    fs::write(tmp.path().join("world.json"), world).unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert!(
        err.to_string().contains("expected cols * rows = 4"),
        "{err}"
    );
}

#[test]
fn unsupported_format_and_missing_files_are_reported() {
    let tmp = tempfile::tempdir().unwrap();
    let err = build_html(tmp.path()).unwrap_err();
    assert!(matches!(err, ViewError::Io { .. }));
    assert!(err.file().ends_with("manifest.json"));

    write_run(tmp.path(), "complete");
    fs::write(
        tmp.path().join("manifest.json"),
        manifest("complete").replace("\"format\":1", "\"format\":2"),
    )
    .unwrap();
    assert!(build_html(tmp.path())
        .unwrap_err()
        .to_string()
        .contains("format 2 is not supported"));
}

#[test]
fn missing_food_and_events_mean_none() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    fs::remove_file(tmp.path().join("food.csv")).unwrap();
    fs::remove_file(tmp.path().join("events.jsonl")).unwrap();
    let p = build(tmp.path());
    assert_eq!(p.meta["frames"]["count"], 3);
    assert_eq!(p.meta["history"]["count"], 0);
}

#[test]
fn large_runs_are_subsampled_with_a_note() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let mut t = vec![header()];
    for tick in 0..50u64 {
        for id in 0..20 {
            t.push(row(tick, id, "reef_fish", 0.0, "wander"));
        }
    }
    fs::write(tmp.path().join("trajectories.csv"), t.join("\n") + "\n").unwrap();
    // 50 frames of 20 rows; a budget for about 10 of them
    let budget = 10 * 20 * payload::ROW_BYTES * 4 / 3 + 4096;
    let p = payload::build(tmp.path(), budget).unwrap();
    let stride = p.meta["stride"].as_u64().unwrap();
    assert!(stride >= 5, "stride {stride}");
    let ticks = p.meta["frames"]["tick"].as_array().unwrap();
    assert_eq!(ticks[0], 0);
    assert_eq!(ticks[1], stride);
    assert_eq!(*ticks.last().unwrap(), 49);
    assert_eq!(p.meta["recorded_frames"], 50);
    assert!(p.meta["notes"][0].as_str().unwrap().contains("every"));
    assert_eq!(
        p.meta["rows"].as_u64().unwrap(),
        ticks.len() as u64 * 20,
        "only kept frames are parsed"
    );
    let html = build_html_with(
        tmp.path(),
        &ViewOptions {
            max_payload_bytes: budget,
        },
    )
    .unwrap();
    assert!(html.len() < budget + 200_000);
}

#[test]
fn write_html_replaces_view_html_atomically() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    fs::write(tmp.path().join("view.html"), "old").unwrap();
    let out = write_html(tmp.path()).unwrap();
    assert_eq!(out, tmp.path().join("view.html"));
    let text = fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("<!doctype html>"));
    let leftovers: Vec<_> = fs::read_dir(tmp.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn live_page_has_no_payload() {
    let html = live_html();
    assert!(html.contains("window.SHOAL_LIVE = true;"));
    assert!(!html.contains("shoal-meta\">"));
    assert!(html.contains("EventSource('/stream')"));
}

/// A `health.json` with one species past two bounds (pitch limit at tick 3 agent 2, turning waste
/// at tick 2 agent 1) and the warnings list `shoal run` adds (which readers ignore).
fn health_json() -> String {
    let species = r#"{"name":"shark","agents":1,"agent_ticks":6,"stopped_share":0.0,
      "frozen_agents":0,"frozen_episodes":0,"pitch_limit_share":0.5,
      "pitch_limit_at":{"tick":3,"agent":2},"transitions":1,"switch_rate":0.1,"episodes":1,
      "short_episode_share":0.0,"one_tick_share":0.0,"flips":[],"turning":3.0,"net_turning":1.0,
      "turning_waste":3.0,"turning_waste_at":{"tick":2,"agent":1},"neighbor_pairs":0,
      "overlapping_pairs":0,"overlap_share":0.0,
      "obstacles":{"agent_ticks":0,"inside_ticks":0,"agents_inside":0},
      "messages":0,"messages_per_agent_second":0.0,"behaviors":[],"frozen":[]}"#;
    format!(
        r#"{{"format":1,"dt":0.05,"ticks":6,"pair_interval":5,"species":[{species}],
        "coincident":{{"samples":1,"mean":0.0,"max":0}},"warnings":["ignored"]}}"#
    )
}

#[test]
fn health_section_carries_figures_and_warnings() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    fs::write(tmp.path().join(crate::health::FILE), health_json()).unwrap();
    let p = build(tmp.path());
    let h = &p.meta["health"];
    assert_eq!(h["ticks"], 6);
    let columns: Vec<&str> = h["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["key"].as_str().unwrap())
        .collect();
    assert_eq!(columns.len(), 9);
    let at = |k: &str| columns.iter().position(|c| *c == k).unwrap();
    let shark = &h["species"][0];
    assert_eq!(shark["name"], "shark");
    assert_eq!(shark["values"][at("pitch_limit_share")], 0.5);
    assert_eq!(shark["over"][at("pitch_limit_share")], true);
    assert_eq!(shark["over"][at("turning_waste")], true);
    assert_eq!(shark["over"][at("switch_rate")], false);
    assert!(h["columns"][at("messages_per_agent_second")]["bound"].is_null());
    let warnings = h["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    let pitch = warnings
        .iter()
        .find(|w| w["message"].as_str().unwrap().contains("pitch limit"))
        .expect("pitch-limit warning");
    assert_eq!(pitch["tick"], 3);
    assert_eq!(pitch["agent"], 2);
    assert_eq!(pitch["species"], "shark");
    assert!(p.meta["notes"].as_array().unwrap().is_empty());
}

#[test]
fn health_section_is_null_without_health_json_and_noted_when_malformed() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path(), "complete");
    let p = build(tmp.path());
    assert!(p.meta["health"].is_null());
    assert!(p.meta["notes"].as_array().unwrap().is_empty());

    fs::write(tmp.path().join(crate::health::FILE), "{\"format\":1,").unwrap();
    let p = build(tmp.path());
    assert!(p.meta["health"].is_null());
    let notes = p.meta["notes"].to_string();
    assert!(notes.contains("health.json"), "{notes}");
}
