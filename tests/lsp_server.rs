//! `shoal lsp` driven over stdio by a minimal client (Content-Length framed JSON-RPC) on a copy of
//! the shipped project: diagnostics as you type (located, cleared, across files), the outline,
//! go to definition, references, rename across species, scripts and tests (after which
//! `shoal check` passes), and hostile requests.

mod lsp_rpc;

use lsp_rpc::{apply, pos_of, project, uri, Client};
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

fn check_passes(dir: &Path) {
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .arg("check")
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "shoal check failed: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

fn at(file: &Path, pos: Value) -> Value {
    json!({"textDocument": {"uri": uri(file)}, "position": pos})
}

#[test]
fn a_typo_is_located_before_save_and_cleared_after_the_fix() {
    let p = project();
    let f = p.path().join("behaviors/reef_fish.ron");
    let good = read(&f);
    let mut c = Client::initialized(p.path());
    c.open(&f, &good);
    let bad = good.replacen("when: TrafficNear,", "when: TrafficNaer,", 1);
    c.change(&f, 2, &bad);
    let d = c.diagnostics(&f, |d| !d.is_empty());
    assert_eq!(d.len(), 1, "{d:?}");
    let msg = d[0]["message"].as_str().unwrap();
    assert!(
        msg.contains("TrafficNaer") && msg.contains("TrafficNear"),
        "{msg}"
    );
    // Located on the typo, which is on disk nowhere: the buffer was checked.
    assert_eq!(
        d[0]["range"]["start"],
        pos_of(&bad, "TrafficNaer", 0),
        "{d:?}"
    );
    assert_eq!(
        d[0]["range"]["end"],
        pos_of(&bad, "TrafficNaer", 11),
        "{d:?}"
    );
    assert_eq!(d[0]["severity"], 1);
    assert_eq!(d[0]["source"], "shoal");
    c.change(&f, 3, &good);
    let d = c.diagnostics(&f, |d| d.is_empty());
    assert!(d.is_empty());
    assert_eq!(c.stop(), Some(0));
}

#[test]
fn editing_a_script_rechecks_the_species_that_loads_it() {
    let p = project();
    let script = p.path().join("behaviors/jellyfish.rhai");
    let species = p.path().join("behaviors/jellyfish.ron");
    let good = read(&script);
    let mut c = Client::initialized(p.path());
    c.open(&script, &good);
    // The species names `below_ceiling` in a `Script(..)` slot; the buffer renames the function.
    c.change(
        &script,
        2,
        &good.replace("fn below_ceiling()", "fn below_ceilin()"),
    );
    let d = c.diagnostics(&species, |d| !d.is_empty());
    let msg = d[0]["message"].as_str().unwrap();
    assert!(
        msg.contains("script function `below_ceiling()` is not defined")
            && msg.contains("below_ceilin"),
        "{msg}"
    );
    let text = read(&species);
    assert_eq!(
        d[0]["range"]["start"],
        pos_of(&text, "\"below_ceiling\"", 0)
    );
    c.change(&script, 3, &good);
    assert!(c.diagnostics(&species, |d| d.is_empty()).is_empty());
}

#[test]
fn outline_of_species_scripts_and_tests() {
    let p = project();
    let mut c = Client::initialized(p.path());
    let f = p.path().join("behaviors/cuttlefish.ron");
    let r = c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": uri(&f)}}),
    );
    let syms = r["result"].as_array().expect("symbols");
    let names: Vec<&str> = syms.iter().map(|s| s["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "avoid_static",
            "escape",
            "hunt",
            "feed",
            "return",
            "rest",
            "roam"
        ]
    );
    let hunt = &syms[2];
    let parts: Vec<&str> = hunt["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(parts, ["settle", "wait", "strike"]);
    assert_eq!(hunt["kind"], 5, "a behavior is a class symbol");
    let text = read(&f);
    assert_eq!(
        hunt["selectionRange"]["start"],
        pos_of(&text, "\"hunt\"", 1)
    );

    let s = p.path().join("behaviors/jellyfish.rhai");
    let r = c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": uri(&s)}}),
    );
    let names: Vec<&str> = r["result"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["below_ceiling", "pulse"]);

    let t = p.path().join("behaviors/tests/jellyfish.rhai");
    let r = c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": uri(&t)}}),
    );
    let tests: Vec<&Value> = r["result"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s["detail"] == "test")
        .collect();
    assert!(
        tests.iter().any(|s| s["name"] == "test_pulse_and_climb"),
        "{r}"
    );
}

#[test]
fn definition_from_slots_behavior_names_imports_and_species() {
    let p = project();
    let mut c = Client::initialized(p.path());
    let ron = p.path().join("behaviors/jellyfish.ron");
    let rhai = p.path().join("behaviors/jellyfish.rhai");
    let ron_text = read(&ron);
    let rhai_text = read(&rhai);
    // `Script("pulse")` → `fn pulse` (not the behavior of the same name).
    let r = c.request(
        "textDocument/definition",
        at(&ron, pos_of(&ron_text, "Script(\"pulse\")", 9)),
    );
    assert_eq!(r["result"]["uri"], uri(&rhai), "{r}");
    assert_eq!(
        r["result"]["range"]["start"],
        pos_of(&rhai_text, "fn pulse", 3)
    );
    // A behavior name in a test → its definition in the species file.
    let t = p.path().join("behaviors/tests/jellyfish.rhai");
    let t_text = read(&t);
    let r = c.request(
        "textDocument/definition",
        at(&t, pos_of(&t_text, "j.behavior == \"pulse\"", 16)),
    );
    assert_eq!(r["result"]["uri"], uri(&ron), "{r}");
    assert_eq!(
        r["result"]["range"]["start"],
        pos_of(&ron_text, "name: \"pulse\"", 7)
    );
    // `import "common/schooling"` → the module.
    let s = p.path().join("behaviors/sardine.rhai");
    let r = c.request(
        "textDocument/definition",
        at(&s, pos_of(&read(&s), "import \"common/schooling\"", 10)),
    );
    assert_eq!(
        r["result"]["uri"],
        uri(&p.path().join("behaviors/common/schooling.rhai")),
        "{r}"
    );
    // A species in a scenario → its file.
    let sc = p.path().join("scenarios/reef.ron");
    let sc_text = read(&sc);
    let r = c.request(
        "textDocument/definition",
        at(&sc, pos_of(&sc_text, "\"reef_fish\"", 2)),
    );
    assert_eq!(
        r["result"]["uri"],
        uri(&p.path().join("behaviors/reef_fish.ron")),
        "{r}"
    );
}

#[test]
fn references_of_a_behavior_span_species_script_and_tests() {
    let p = project();
    let mut c = Client::initialized(p.path());
    let ron = p.path().join("behaviors/goby.ron");
    let text = read(&ron);
    let mut params = at(&ron, pos_of(&text, "name: \"flee\"", 8));
    params["context"] = json!({"includeDeclaration": true});
    let r = c.request("textDocument/references", params);
    let mut files: Vec<String> = r["result"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            l["uri"]
                .as_str()
                .unwrap()
                .rsplit("behaviors/")
                .next()
                .unwrap()
                .to_string()
        })
        .collect();
    files.sort();
    // The definition, two comparisons in the script, one assertion in the test file (the
    // message "flicks sent on entering flee" is not a behavior name).
    assert_eq!(
        files,
        ["goby.rhai", "goby.rhai", "goby.ron", "tests/goby.rhai"],
        "{r}"
    );
}

#[test]
fn rename_a_behavior_and_a_function_then_check_passes() {
    let p = project();
    let mut c = Client::initialized(p.path());
    let ron = p.path().join("behaviors/goby.ron");
    let text = read(&ron);
    let pos = at(&ron, pos_of(&text, "name: \"flee\"", 8));
    let r = c.request("textDocument/prepareRename", pos.clone());
    assert_eq!(
        r["result"]["start"],
        pos_of(&text, "name: \"flee\"", 7),
        "{r}"
    );
    let mut params = pos;
    params["newName"] = json!("bolt");
    let r = c.request("textDocument/rename", params);
    apply(&r["result"]);
    assert!(read(&ron).contains("name: \"bolt\""));
    let script = read(&p.path().join("behaviors/goby.rhai"));
    assert!(
        script.contains("this.behavior == \"bolt\"") && !script.contains("\"flee\""),
        "{script}"
    );
    let tests = read(&p.path().join("behaviors/tests/goby.rhai"));
    assert!(
        tests.contains("assert_behavior(lookout, \"bolt\")"),
        "{tests}"
    );
    assert!(
        tests.contains("flicks sent on entering flee"),
        "only names change"
    );
    check_passes(p.path());

    // A function named like a behavior: only the function's uses change.
    let jr = p.path().join("behaviors/jellyfish.ron");
    let jt = read(&jr);
    let mut params = at(&jr, pos_of(&jt, "Script(\"pulse\")", 9));
    params["newName"] = json!("thrust");
    let r = c.request("textDocument/rename", params);
    apply(&r["result"]);
    let jt = read(&jr);
    assert!(
        jt.contains("Script(\"thrust\")") && jt.contains("name: \"pulse\""),
        "{jt}"
    );
    assert!(read(&p.path().join("behaviors/jellyfish.rhai")).contains("fn thrust()"));
    check_passes(p.path());

    // Names that cannot be written are refused.
    let mut params = at(&jr, pos_of(&jt, "Script(\"thrust\")", 9));
    params["newName"] = json!("two words");
    let r = c.request("textDocument/rename", params);
    assert!(
        r["error"]["message"]
            .as_str()
            .unwrap()
            .contains("cannot name a script function"),
        "{r}"
    );
    let mut params = at(&jr, pos_of(&jt, "Script(\"thrust\")", 9));
    params["newName"] = json!("below_ceiling");
    let r = c.request("textDocument/rename", params);
    assert!(
        r["error"]["message"]
            .as_str()
            .unwrap()
            .contains("already defined"),
        "{r}"
    );
}

#[test]
fn hostile_requests_get_errors_not_crashes() {
    let p = project();
    let mut c = Client::start(p.path());
    // Before initialize.
    let r = c.request("textDocument/hover", json!({}));
    assert_eq!(r["error"]["code"], -32002, "{r}");
    let r = c.request(
        "initialize",
        json!({"processId": null, "rootUri": null, "capabilities": {}}),
    );
    assert!(
        r["result"]["capabilities"]["renameProvider"].is_object(),
        "{r}"
    );
    c.notify("initialized", json!({}));
    let r = c.request("no/such/method", json!({}));
    assert_eq!(r["error"]["code"], -32601, "{r}");
    let r = c.request("textDocument/definition", json!({"textDocument": 3}));
    assert_eq!(r["error"]["code"], -32602, "{r}");
    let r = c.request(
        "textDocument/definition",
        at(Path::new("/x"), json!({"line": 0, "character": 0})),
    );
    assert!(
        r.get("error").is_none(),
        "an unknown file has no definitions: {r}"
    );
    let r = c.request(
        "textDocument/hover",
        json!({"textDocument": {"uri": "untitled:Untitled-1"}, "position": {"line": 0, "character": 0}}),
    );
    assert_eq!(r["error"]["code"], -32602, "{r}");
    // A non-UTF-8 path, positions far past the end, a huge document.
    let odd = json!({"textDocument": {"uri": "file:///tmp/%FF%FE.ron"}, "position": {"line": 4000000000u32, "character": 4000000000u32}});
    for m in [
        "textDocument/definition",
        "textDocument/hover",
        "textDocument/completion",
        "textDocument/references",
    ] {
        let mut q = odd.clone();
        if m.ends_with("references") {
            q["context"] = json!({"includeDeclaration": true});
        }
        let r = c.request(m, q);
        assert!(r.get("result").is_some(), "{m}: {r}");
    }
    let f = p.path().join("behaviors/reef_fish.ron");
    let huge = format!("{}\n{}", read(&f), "// é😀 padding\n".repeat(200_000));
    c.open(&f, &huge);
    let end = json!({"line": 999_999_999u32, "character": 7});
    for m in [
        "textDocument/definition",
        "textDocument/hover",
        "textDocument/completion",
        "textDocument/prepareRename",
    ] {
        let r = c.request(m, at(&f, end.clone()));
        assert!(
            r.get("result").is_some() || r.get("error").is_some(),
            "{m}: {r}"
        );
    }
    let r = c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": uri(&f)}}),
    );
    assert!(r["result"].as_array().is_some_and(|a| a.len() > 5), "{r}");
    // Garbage notifications are ignored.
    c.notify("textDocument/didChange", json!({"textDocument": 1}));
    c.notify("textDocument/didOpen", json!(null));
    // Shut down: further requests are refused; `exit` ends with 0.
    let r = c.request("shutdown", Value::Null);
    assert!(r.get("error").is_none(), "{r}");
    let r = c.request(
        "textDocument/hover",
        at(&f, json!({"line": 0, "character": 0})),
    );
    assert_eq!(r["error"]["code"], -32600, "{r}");
    c.notify("exit", Value::Null);
    assert_eq!(c.wait(), Some(0));
}

#[test]
fn exit_without_shutdown_is_exit_code_1() {
    let p = project();
    let mut c = Client::initialized(p.path());
    c.notify("exit", Value::Null);
    assert_eq!(c.wait(), Some(1));
}
