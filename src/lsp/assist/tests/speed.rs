//! Completion and hover on every key of the shipped files, and Rhai completion on the shipped
//! scripts, within their time budgets.

use super::*;
use crate::lsp::assist::api::{self, Api};

#[test]
fn every_key_of_the_shipped_files_completes_and_hovers_quickly() {
    // At each key of each shipped species and scenario, completion offers that key and hover
    // has something to say; the slowest call is reported (and bounded loosely: debug builds on
    // a busy machine).
    let mut slowest = std::time::Duration::ZERO;
    let mut calls = 0;
    for (dir, kind) in [
        ("behaviors", FileKind::Species),
        ("scenarios", FileKind::Scenario),
    ] {
        for (p, text) in shipped(dir) {
            let toks = cursor::tokens(&text);
            for w in toks.windows(2) {
                if !(w[0].0 == cursor::Tok::Word && w[1].0 == cursor::Tok::Colon) {
                    continue;
                }
                let (s, e) = (w[0].1, w[0].2);
                let key = &text[s..e];
                let t0 = std::time::Instant::now();
                let items = complete(kind, &text, e, &names());
                let h = hover(kind, &text, s);
                slowest = slowest.max(t0.elapsed() / 2);
                calls += 2;
                let line = text[..s].matches('\n').count() + 1;
                assert!(
                    labels(&items).contains(&key),
                    "{}:{line}: `{key}` not offered",
                    p.display()
                );
                assert!(h.is_some(), "{}:{line}: no hover on `{key}`", p.display());
            }
        }
    }
    eprintln!("{calls} calls on the shipped files, slowest {slowest:?}");
    assert!(calls > 200, "{calls}");
    assert!(
        slowest < std::time::Duration::from_millis(50),
        "slowest call {slowest:?}"
    );
}

#[test]
fn rhai_completion_on_the_shipped_scripts_is_quick() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("behaviors");
    let _ = api::functions(Api::Script);
    let _ = api::functions(Api::Test);
    let mut slowest = std::time::Duration::ZERO;
    for (dir, kind) in [
        (root.clone(), FileKind::Script),
        (root.join("tests"), FileKind::Test),
    ] {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_none_or(|x| x != "rhai") {
                continue;
            }
            let text = std::fs::read_to_string(&p).unwrap();
            for (i, _) in text.match_indices("this.").take(50) {
                let t0 = std::time::Instant::now();
                let items = complete(kind, &text, i + 5, &names());
                let _ = hover(kind, &text, i + 6);
                slowest = slowest.max(t0.elapsed());
                assert!(labels(&items).contains(&"pos"), "{}", p.display());
            }
        }
    }
    eprintln!("slowest Rhai completion + hover {slowest:?}");
    assert!(
        slowest < std::time::Duration::from_millis(50),
        "{slowest:?}"
    );
}
