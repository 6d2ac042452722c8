//! A minimal LSP client for tests: spawns `shoal lsp`, frames JSON-RPC messages with
//! `Content-Length` headers over its stdio, and waits for responses and notifications.

#![allow(dead_code)]

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

/// A copy of the shipped behaviors and scenarios (and assets) to edit.
pub fn project() -> tempfile::TempDir {
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
        if Path::new(d).is_dir() {
            copy(Path::new(d), &t.path().join(d));
        }
    }
    t
}

/// The `file:` URI of an absolute path (test paths hold no characters that need escaping).
pub fn uri(p: &Path) -> String {
    format!("file://{}", p.display())
}

/// The path of a `file:` URI.
pub fn path(uri: &str) -> PathBuf {
    PathBuf::from(uri.trim_start_matches("file://"))
}

/// A running `shoal lsp` and what it sent that was not yet read.
pub struct Client {
    pub child: Child,
    stdin: Option<ChildStdin>,
    rx: Receiver<Value>,
    next: i64,
    /// Notifications received while waiting for something else.
    pub pending: Vec<Value>,
}

fn read_message(r: &mut impl BufRead) -> Option<Value> {
    let mut len = None;
    loop {
        let mut line = String::new();
        if r.read_line(&mut line).ok()? == 0 {
            return None;
        }
        let line = line.trim_end();
        if line.is_empty() {
            break;
        }
        if let Some(v) = line.strip_prefix("Content-Length: ") {
            len = v.parse::<usize>().ok();
        }
    }
    let mut buf = vec![0; len?];
    r.read_exact(&mut buf).ok()?;
    serde_json::from_slice(&buf).ok()
}

impl Client {
    /// Starts `shoal lsp` in `dir`.
    pub fn start(dir: &Path) -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_shoal"))
            .arg("lsp")
            .current_dir(dir)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let stdout = child.stdout.take().unwrap();
        let stdin = child.stdin.take();
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            let mut r = BufReader::new(stdout);
            while let Some(v) = read_message(&mut r) {
                if tx.send(v).is_err() {
                    break;
                }
            }
        });
        Client {
            child,
            stdin,
            rx,
            next: 1,
            pending: Vec::new(),
        }
    }

    /// Starts the server and initializes it with `root` as the workspace folder.
    pub fn initialized(root: &Path) -> Client {
        let mut c = Client::start(root);
        let r = c.request(
            "initialize",
            json!({"processId": null, "rootUri": uri(root), "capabilities": {},
                   "workspaceFolders": [{"uri": uri(root), "name": "p"}]}),
        );
        assert!(r.get("result").is_some(), "{r}");
        c.notify("initialized", json!({}));
        c
    }

    /// Sends raw bytes (for malformed input).
    pub fn send_raw(&mut self, bytes: &[u8]) {
        if let Some(s) = self.stdin.as_mut() {
            let _ = s.write_all(bytes);
            let _ = s.flush();
        }
    }

    /// Sends one message.
    pub fn send(&mut self, v: &Value) {
        let body = v.to_string();
        let framed = format!("Content-Length: {}\r\n\r\n{body}", body.len());
        self.send_raw(framed.as_bytes());
    }

    /// Sends a notification.
    pub fn notify(&mut self, method: &str, params: Value) {
        self.send(&json!({"jsonrpc": "2.0", "method": method, "params": params}));
    }

    /// Sends a request and returns the whole response (`result` or `error`).
    pub fn request(&mut self, method: &str, params: Value) -> Value {
        let id = self.next;
        self.next += 1;
        self.send(&json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
        self.response(id)
    }

    /// Waits for the response with `id` (up to 30 s).
    pub fn response(&mut self, id: i64) -> Value {
        let end = Instant::now() + Duration::from_secs(30);
        loop {
            let left = end.saturating_duration_since(Instant::now());
            let v = self
                .rx
                .recv_timeout(left)
                .unwrap_or_else(|_| panic!("no response to request {id}"));
            if v.get("id") == Some(&json!(id)) && v.get("method").is_none() {
                return v;
            }
            self.pending.push(v);
        }
    }

    /// Waits for a `publishDiagnostics` for `file` whose list satisfies `ok` (up to 30 s);
    /// returns its diagnostics.
    pub fn diagnostics(&mut self, file: &Path, ok: impl Fn(&[Value]) -> bool) -> Vec<Value> {
        let want = uri(file);
        let matches = |v: &Value| {
            v["method"] == "textDocument/publishDiagnostics" && v["params"]["uri"] == want.as_str()
        };
        // The latest one already received counts first.
        if let Some(v) = self.pending.iter().rev().find(|v| matches(v)) {
            let list = v["params"]["diagnostics"]
                .as_array()
                .cloned()
                .unwrap_or_default();
            if ok(&list) {
                self.pending.retain(|v| !matches(v));
                return list;
            }
        }
        self.pending.retain(|v| !matches(v));
        let end = Instant::now() + Duration::from_secs(30);
        loop {
            let left = end.saturating_duration_since(Instant::now());
            let v = self
                .rx
                .recv_timeout(left)
                .unwrap_or_else(|_| panic!("no matching diagnostics for {}", file.display()));
            if matches(&v) {
                let list = v["params"]["diagnostics"]
                    .as_array()
                    .cloned()
                    .unwrap_or_default();
                if ok(&list) {
                    return list;
                }
            } else {
                self.pending.push(v);
            }
        }
    }

    /// Opens `file` with `text`.
    pub fn open(&mut self, file: &Path, text: &str) {
        let lang = if file.extension().is_some_and(|x| x == "rhai") {
            "rhai"
        } else {
            "ron"
        };
        self.notify(
            "textDocument/didOpen",
            json!({"textDocument": {"uri": uri(file), "languageId": lang, "version": 1, "text": text}}),
        );
    }

    /// Replaces the text of the open `file`.
    pub fn change(&mut self, file: &Path, version: i64, text: &str) {
        self.notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": uri(file), "version": version},
                   "contentChanges": [{"text": text}]}),
        );
    }

    /// `shutdown` then `exit`; returns the exit code.
    pub fn stop(mut self) -> Option<i32> {
        let r = self.request("shutdown", Value::Null);
        assert!(r.get("error").is_none(), "{r}");
        self.notify("exit", Value::Null);
        self.wait()
    }

    /// Waits (up to 10 s) for the process to end; its exit code.
    pub fn wait(&mut self) -> Option<i32> {
        self.stdin.take();
        let end = Instant::now() + Duration::from_secs(10);
        while Instant::now() < end {
            if let Some(s) = self.child.try_wait().unwrap() {
                return s.code();
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = self.child.kill();
        panic!("`shoal lsp` did not exit");
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The LSP position (line, UTF-16 column; the test files are ASCII) of the first `needle` in
/// `text`, plus `skip` characters.
pub fn pos_of(text: &str, needle: &str, skip: usize) -> Value {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle} not in text"))
        + skip;
    let line = text[..at].matches('\n').count();
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1);
    json!({"line": line, "character": col})
}

/// Applies a WorkspaceEdit's `changes` to the files on disk.
pub fn apply(edit: &Value) {
    let changes = edit["changes"].as_object().expect("changes");
    for (u, edits) in changes {
        let p = path(u);
        let text = std::fs::read_to_string(&p).unwrap();
        let starts: Vec<usize> = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        let off = |pos: &Value| {
            starts[pos["line"].as_u64().unwrap() as usize]
                + pos["character"].as_u64().unwrap() as usize
        };
        let mut list: Vec<(usize, usize, String)> = edits
            .as_array()
            .unwrap()
            .iter()
            .map(|e| {
                (
                    off(&e["range"]["start"]),
                    off(&e["range"]["end"]),
                    e["newText"].as_str().unwrap().to_string(),
                )
            })
            .collect();
        list.sort_by_key(|e| std::cmp::Reverse(e.0));
        let mut out = text.clone();
        for (a, b, t) in list {
            out.replace_range(a..b, &t);
        }
        std::fs::write(&p, out).unwrap();
    }
}
