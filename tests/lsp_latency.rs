//! Response times of `shoal lsp` on the shipped project, per request kind: median and p95 over
//! repeated requests, from sending to receiving (for an edit: from `didChange` to the
//! `publishDiagnostics` it causes). Ignored by default; run it on a release build:
//! `cargo test --release --test lsp_latency -- --ignored --nocapture`.

mod lsp_rpc;

use lsp_rpc::{pos_of, uri, Client};
use serde_json::json;
use std::path::Path;
use std::time::{Duration, Instant};

const ROUNDS: usize = 60;

fn report(kind: &str, mut t: Vec<Duration>) -> Duration {
    t.sort();
    let ms = |d: Duration| d.as_secs_f64() * 1000.0;
    let median = t[t.len() / 2];
    let p95 = t[(t.len() * 95 / 100).min(t.len() - 1)];
    println!(
        "{kind:<28} median {:>7.2} ms   p95 {:>7.2} ms   max {:>7.2} ms   (n = {})",
        ms(median),
        ms(p95),
        ms(t[t.len() - 1]),
        t.len()
    );
    p95
}

#[test]
#[ignore = "a measurement: run with --release --ignored --nocapture"]
fn latency_on_the_shipped_project() {
    let root = std::env::current_dir().unwrap();
    let start = Instant::now();
    let mut c = Client::initialized(&root);
    let species = root.join("behaviors/sardine.ron");
    let text = std::fs::read_to_string(&species).unwrap();
    c.open(&species, &text);
    // The first check of the project is done when a request after it is answered.
    c.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": uri(&species)}}),
    );
    println!("initialize + open + first check: {:?}", start.elapsed());
    let bad = text.replacen("Script(\"sluggish\")", "Script(\"sluggsh\")", 1);
    let mut worst = Vec::new();

    let mut t = Vec::new();
    for i in 0..ROUNDS {
        let (next, want_empty) = if i % 2 == 0 {
            (&bad, false)
        } else {
            (&text, true)
        };
        let s = Instant::now();
        c.change(&species, i as i64 + 2, next);
        c.diagnostics(&species, |d| d.is_empty() == want_empty);
        t.push(s.elapsed());
    }
    worst.push(report("didChange → diagnostics", t));

    let script = root.join("behaviors/sardine.rhai");
    let script_text = std::fs::read_to_string(&script).unwrap();
    let at = |file: &Path, text: &str, needle: &str, skip: usize| json!({"textDocument": {"uri": uri(file)}, "position": pos_of(text, needle, skip)});
    let cases = [
        (
            "completion",
            "textDocument/completion",
            at(&species, &text, "steer: ", 7),
        ),
        (
            "hover",
            "textDocument/hover",
            at(&species, &text, "Script(\"sluggish\")", 2),
        ),
        (
            "definition",
            "textDocument/definition",
            at(&species, &text, "Script(\"sluggish\")", 9),
        ),
        ("references", "textDocument/references", {
            let mut p = at(&species, &text, "name: \"school\"", 8);
            p["context"] = json!({"includeDeclaration": true});
            p
        }),
        ("rename", "textDocument/rename", {
            let mut p = at(&script, &script_text, "fn sluggish", 4);
            p["newName"] = json!("slow");
            p
        }),
        (
            "documentSymbol",
            "textDocument/documentSymbol",
            json!({"textDocument": {"uri": uri(&species)}}),
        ),
    ];
    for (kind, method, params) in cases {
        let mut t = Vec::new();
        for _ in 0..ROUNDS {
            let s = Instant::now();
            let r = c.request(method, params.clone());
            t.push(s.elapsed());
            assert!(r.get("error").is_none(), "{kind}: {r}");
        }
        worst.push(report(kind, t));
    }
    assert_eq!(c.stop(), Some(0));
    let limit = Duration::from_millis(100);
    assert!(
        worst.iter().all(|p| *p < limit),
        "a p95 over 100 ms: {worst:?}"
    );
}
