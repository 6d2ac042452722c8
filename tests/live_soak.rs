//! Soak: `shoal watch` runs under a stream of random good and bad edits and hostile HTTP clients.
//! The simulation must never stop, every good edit must be applied (a new version), every bad one
//! reported (a rejection naming the file), foreign requests never obeyed, and memory must stay
//! flat. The short run is part of `cargo test`; the long one (docs/testing.md has its figures):
//!
//!     SHOAL_SOAK_SECS=600 cargo test --release --test live_soak -- --ignored --nocapture

mod live_support;

use live_support::*;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{channel, Receiver};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// A small deterministic generator (xorshift64*), so a failing soak can be replayed by seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// The three files edited: species, its script, and the module the script imports.
const FILES: [&str; 3] = [
    "behaviors/fish.ron",
    "behaviors/fish.rhai",
    "behaviors/common/util.rhai",
];

/// A good version of file `f`, unique to edit `i` (so that it always differs from the running one).
fn good(f: usize, i: u64) -> String {
    match f {
        0 => format!(
            "// edit {i}\n{}",
            FISH.replace(
                "max_speed: 2.0",
                &format!("max_speed: {:.3}", 1.5 + (i % 997) as f32 / 997.0)
            )
            .replace("0.95", &format!("{:.3}", 0.5 + (i % 449) as f32 / 1000.0))
        ),
        1 => format!("// edit {i}\n{FISH_RHAI}").replace(
            "this[\"n\"] = util::next(n);",
            &format!("this[\"n\"] = util::next(n);\n    this[\"edit\"] = {i};"),
        ),
        _ => format!("// edit {i}\nfn next(n) {{ n + {} }}\n", 1 + i % 5),
    }
}

/// Bad versions of file `f`: (what, contents). Each must be rejected with a diagnostic naming
/// the file.
fn bad(f: usize, i: u64, pick: u64) -> (&'static str, Vec<u8>) {
    let base = good(f, i);
    let (what, text): (&str, String) = match (f, pick % 6) {
        (0, 0) => (
            "species: unclosed",
            base.trim_end().trim_end_matches(')').to_string(),
        ),
        (0, 1) => (
            "species: NaN speed",
            base.replace("max_speed: ", "max_speed: NaN, x: "),
        ),
        (0, 2) => (
            "species: negative turn",
            base.replace("max_turn: 1.0", "max_turn: -1.0"),
        ),
        (0, 3) => (
            "species: unknown condition",
            base.replace("Above(", "Abov("),
        ),
        (0, 4) => ("species: empty file", String::new()),
        (0, _) => (
            "species: 1 MiB garbage line",
            format!("{base}\n{}\n", "(]".repeat(512 * 1024)),
        ),
        (1, 0) => (
            "script: syntax",
            base.replace("fn on_tick() {", "fn on_tick( {"),
        ),
        (1, 1) => (
            "script: endless loop",
            base.replace("let n =", "while true {}\n    let n ="),
        ),
        (1, 2) => (
            "script: unknown function",
            base.replace("util::next(n)", "nexxt(n)"),
        ),
        (1, 3) => (
            "script: import missing",
            base.replace("common/util", "common/nope"),
        ),
        (1, 4) => (
            "script: import outside",
            base.replace("common/util", "../../../etc/passwd"),
        ),
        (1, _) => (
            "script: runtime type error",
            base.replace("util::next(n)", "util::next(n) + \"x\" - 1"),
        ),
        (_, 0) => ("module: syntax", base.replace("{ n +", "{ n * *")),
        (_, 1) => (
            "module: imports itself",
            format!("import \"common/util\" as u;\n{base}"),
        ),
        (_, 2) => ("module: unterminated", base.replace(" }", "")),
        _ => {
            let mut b = base.into_bytes();
            b.extend_from_slice(b"\n// \xff\xfe not UTF-8\n");
            return ("module: invalid UTF-8", b);
        }
    };
    (what, text.into_bytes())
}

/// What `shoal watch` printed about a reload.
#[derive(Debug)]
enum Reload {
    Accepted(u32),
    Rejected(u32, Vec<String>),
}

/// `shoal watch`'s standard output, line by line, as the test reads it.
struct Output {
    lines: Receiver<String>,
    peeked: Option<String>,
    all: Vec<String>,
}

impl Output {
    /// Follows `child`'s standard output and returns it with the live viewer's address.
    fn follow(child: &mut Child) -> (SocketAddr, Output) {
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut line = String::new();
        let url = loop {
            line.clear();
            assert!(out.read_line(&mut line).unwrap() > 0, "no URL printed");
            if let Some(rest) = line.strip_prefix("live view: http://") {
                break rest.split('/').next().unwrap().to_string();
            }
        };
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            for line in out.lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let out = Output {
            lines: rx,
            peeked: None,
            all: Vec::new(),
        };
        (url.parse().unwrap(), out)
    }

    /// The next line within `timeout`; `None` when none came (or the process ended).
    fn line(&mut self, timeout: Duration) -> Option<String> {
        if let Some(l) = self.peeked.take() {
            return Some(l);
        }
        let l = self.lines.recv_timeout(timeout).ok()?;
        self.all.push(l.clone());
        Some(l)
    }

    /// The next reload outcome within `timeout`, with a rejection's diagnostic lines (indented,
    /// printed together with it).
    fn reload(&mut self, timeout: Duration) -> Option<Reload> {
        let deadline = Instant::now() + timeout;
        let version = |l: &str| {
            l.split("version ")
                .nth(1)
                .and_then(|v| v.split(' ').next())
                .and_then(|v| v.parse::<u32>().ok())
                .unwrap()
        };
        loop {
            let line = self.line(deadline.saturating_duration_since(Instant::now()))?;
            if line.contains("] accepted: version") {
                return Some(Reload::Accepted(version(&line)));
            }
            if line.contains("] rejected: version") {
                let mut d = Vec::new();
                while let Some(l) = self.line(Duration::from_millis(300)) {
                    if let Some(rest) = l.strip_prefix("    ") {
                        d.push(rest.trim().to_string());
                    } else {
                        self.peeked = Some(l);
                        break;
                    }
                }
                return Some(Reload::Rejected(version(&line), d));
            }
        }
    }
}

fn exchange(addr: SocketAddr, raw: &[u8], timeout: Duration) -> (u16, String) {
    let Ok(mut s) = TcpStream::connect_timeout(&addr, timeout) else {
        return (0, String::new());
    };
    let _ = s.set_read_timeout(Some(timeout));
    let _ = s.set_write_timeout(Some(timeout));
    let _ = s.write_all(raw);
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let out = String::from_utf8_lossy(&out).into_owned();
    let status = out.get(9..12).and_then(|c| c.parse().ok()).unwrap_or(0);
    let body = out.split_once("\r\n\r\n").map(|x| x.1.to_string());
    (status, body.unwrap_or_default())
}

/// `GET /status`, asked again while the server answers 503 (at the connection cap, as the
/// viewer does): (status, tick, version, paused, time taken).
fn status(addr: SocketAddr) -> (u16, u64, u32, bool, Duration) {
    let t0 = Instant::now();
    let req = format!("GET /status HTTP/1.1\r\nHost: {addr}\r\n\r\n");
    let (mut code, mut body) = (0, String::new());
    for _ in 0..20 {
        (code, body) = exchange(addr, req.as_bytes(), Duration::from_secs(5));
        if code != 503 && code != 0 {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let v: serde_json::Value = serde_json::from_str(&body).unwrap_or_default();
    (
        code,
        v["tick"].as_u64().unwrap_or(0),
        v["version"].as_u64().unwrap_or(0) as u32,
        v["paused"].as_bool().unwrap_or(false),
        t0.elapsed(),
    )
}

/// Resident memory of process `pid` (kB).
fn rss_kb(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmRSS:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}

/// Counters the hostile clients keep.
#[derive(Default)]
struct Hostile {
    connections: AtomicU64,
    obeyed: AtomicU64,
    refused: AtomicU64,
}

/// One hostile client action of kind `k`; held connections go to `held` (dropped after 12 s,
/// past the server's 10 s request deadline).
fn attack(addr: SocketAddr, k: u64, held: &mut Vec<(Instant, TcpStream)>, h: &Hostile) {
    h.connections.fetch_add(1, Ordering::Relaxed);
    let here = addr.to_string();
    let post = |host: &str, origin: &str| {
        format!(
            "POST /control HTTP/1.1\r\nHost: {host}\r\n{origin}Content-Length: 15\r\n\r\n{{\"cmd\":\"pause\"}}"
        )
    };
    let t = Duration::from_secs(3);
    match k {
        // Endless header bytes, no line end.
        0 => {
            if let Ok(mut c) = TcpStream::connect_timeout(&addr, t) {
                let _ = c.set_write_timeout(Some(t));
                let _ = c.write_all(b"GET /status HTTP/1.1\r\nX-Endless: ");
                let chunk = vec![b'a'; 64 * 1024];
                for _ in 0..32 {
                    if c.write_all(&chunk).is_err() {
                        break;
                    }
                }
            }
        }
        // Half a request, then silence.
        1 => {
            if let Ok(mut c) = TcpStream::connect_timeout(&addr, t) {
                let _ = write!(c, "GET /status HTTP/1.1\r\nHost: {here}\r\nX-Half: ");
                held.push((Instant::now(), c));
            }
        }
        // Connected, nothing sent.
        2 => {
            if let Ok(c) = TcpStream::connect_timeout(&addr, t) {
                held.push((Instant::now(), c));
            }
        }
        // Another site's page, then a rebound DNS name, trying to pause the session.
        3 | 4 => {
            let raw = if k == 3 {
                post(&here, "Origin: http://evil.example\r\n")
            } else {
                post(&format!("evil.example:{}", addr.port()), "")
            };
            match exchange(addr, raw.as_bytes(), t).0 {
                200 => h.obeyed.fetch_add(1, Ordering::Relaxed),
                _ => h.refused.fetch_add(1, Ordering::Relaxed),
            };
        }
        // A body far over the limit.
        5 => {
            let raw = format!(
                "POST /control HTTP/1.1\r\nHost: {here}\r\nContent-Length: 50000000\r\n\r\n"
            );
            if exchange(addr, raw.as_bytes(), t).0 == 200 {
                h.obeyed.fetch_add(1, Ordering::Relaxed);
            }
        }
        // Binary garbage.
        6 => {
            exchange(addr, b"\x00\xff\xfe\r\n\r\n\x16\x03\x01", t);
        }
        // An event stream opened and never read.
        7 => {
            if let Ok(mut c) = TcpStream::connect_timeout(&addr, t) {
                let _ = write!(c, "GET /stream HTTP/1.1\r\nHost: {here}\r\n\r\n");
                held.push((Instant::now(), c));
            }
        }
        // A burst of connections closed at once.
        _ => {
            for _ in 0..40 {
                let _ = TcpStream::connect_timeout(&addr, t);
            }
        }
    }
}

/// What a soak measured.
#[derive(Debug, Default)]
struct Report {
    good: u64,
    applied: u64,
    bad: u64,
    reported: u64,
    repeated: u64,
    transient: Vec<String>,
    located: u64,
    not_named: Vec<String>,
    missing: Vec<String>,
    stalls: u64,
    samples: u64,
    worst_status: Duration,
    ticks: u64,
    rss: Vec<(f64, u64)>,
}

fn soak(secs: u64, seed: u64) -> Report {
    let p = Project::new();
    let mut child = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .arg("watch")
        .arg(p.scenario())
        .args(["--port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let pid = child.id();
    let (addr, mut out) = Output::follow(&mut child);
    let stop = Arc::new(AtomicBool::new(false));
    let hostile = Arc::new(Hostile::default());
    let t0 = Instant::now();

    // Hostile clients, two threads.
    let mut threads = Vec::new();
    for t in 0..2 {
        let (stop, h) = (stop.clone(), hostile.clone());
        threads.push(std::thread::spawn(move || {
            let mut rng = Rng(seed ^ (0x9e37_79b9 + t));
            let mut held: Vec<(Instant, TcpStream)> = Vec::new();
            while !stop.load(Ordering::Relaxed) {
                held.retain(|(at, _)| at.elapsed() < Duration::from_secs(12));
                if held.len() < 60 {
                    attack(addr, rng.below(9), &mut held, &h);
                }
                std::thread::sleep(Duration::from_millis(20 + rng.below(80)));
            }
        }));
    }

    // The watcher's view: the simulation advances, /status answers, memory.
    let samples = Arc::new(Mutex::new(Vec::<(Instant, u64, Duration, bool)>::new()));
    let rss = Arc::new(Mutex::new(Vec::new()));
    {
        let (stop, samples, rss) = (stop.clone(), samples.clone(), rss.clone());
        threads.push(std::thread::spawn(move || {
            let mut n = 0u64;
            while !stop.load(Ordering::Relaxed) {
                let (code, tick, _, paused, took) = status(addr);
                assert_eq!(code, 200, "GET /status failed under load");
                samples
                    .lock()
                    .unwrap()
                    .push((Instant::now(), tick, took, paused));
                if n.is_multiple_of(5) {
                    rss.lock()
                        .unwrap()
                        .push((t0.elapsed().as_secs_f64(), rss_kb(pid)));
                }
                n += 1;
                std::thread::sleep(Duration::from_millis(1000));
            }
        }));
    }

    // The designer: random good and bad edits; a bad one is always repaired by the next edit of
    // the same file, so that every good edit can be applied.
    let mut rng = Rng(seed);
    let mut r = Report::default();
    let mut version = 0u32;
    let mut i = 0u64;
    let mut fifo = [false; 3];
    let write = |p: &Project, f: usize, bytes: &[u8], atomic: bool, fifo: &mut [bool; 3]| {
        let path = p.path(FILES[f]);
        if atomic || fifo[f] {
            let tmp = path.with_file_name(format!(".soak{}.tmp", std::process::id()));
            std::fs::write(&tmp, bytes).unwrap();
            std::fs::rename(&tmp, &path).unwrap();
        } else {
            std::fs::write(&path, bytes).unwrap();
        }
        fifo[f] = false;
    };
    while t0.elapsed() < Duration::from_secs(secs) {
        i += 1;
        let f = rng.below(3) as usize;
        let atomic = rng.below(2) == 0;
        if rng.below(10) < 4 {
            // A bad edit: one of the file's breakages, or now and then a named pipe.
            let pipe = rng.below(40) == 0;
            let what = if pipe {
                let path = p.path(FILES[f]);
                let tmp = path.with_file_name(".soak.fifo");
                let _ = std::fs::remove_file(&tmp);
                assert!(Command::new("mkfifo").arg(&tmp).status().unwrap().success());
                std::fs::rename(&tmp, &path).unwrap();
                fifo[f] = true;
                "named pipe"
            } else {
                let (what, bytes) = bad(f, i, rng.next());
                write(&p, f, &bytes, atomic, &mut fifo);
                what
            };
            r.bad += 1;
            match out.reload(Duration::from_secs(30)) {
                Some(Reload::Rejected(running, d)) => {
                    assert_eq!(running, version, "{what}: wrong running version");
                    r.reported += 1;
                    let name = FILES[f].rsplit('/').next().unwrap();
                    let first = d.first().cloned().unwrap_or_default();
                    if !d.iter().any(|l| l.contains(name)) {
                        r.not_named.push(format!("{what}: {first}"));
                    }
                    let located = first
                        .split_once(&format!("{name}:"))
                        .is_some_and(|(_, rest)| rest.starts_with(|c: char| c.is_ascii_digit()));
                    r.located += located as u64;
                }
                Some(Reload::Accepted(v)) => panic!("bad edit ({what}) accepted as version {v}"),
                None => r
                    .missing
                    .push(format!("bad edit {i} ({what}) not reported")),
            }
            // A save seen as two changes (truncate, then write) may be reported twice.
            while let Some(again) = out.reload(Duration::from_millis(1000)) {
                match again {
                    Reload::Rejected(..) => r.repeated += 1,
                    Reload::Accepted(v) => panic!("bad edit ({what}) accepted as version {v}"),
                }
            }
            i += 1;
        }
        // A good edit (or the repair of the bad one).
        write(&p, f, good(f, i).as_bytes(), atomic, &mut fifo);
        r.good += 1;
        loop {
            match out.reload(Duration::from_secs(30)) {
                Some(Reload::Accepted(v)) => {
                    assert_eq!(v, version + 1, "edit {i}: versions must follow each other");
                    version = v;
                    r.applied += 1;
                    break;
                }
                // Read half-written: reported, then the whole file is loaded.
                Some(Reload::Rejected(_, d)) => r.transient.push(format!(
                    "good edit {i} of {}: {}",
                    FILES[f],
                    d.first().cloned().unwrap_or_default()
                )),
                None => {
                    r.missing.push(format!("good edit {i} not applied"));
                    break;
                }
            }
        }
        std::thread::sleep(Duration::from_millis(100 + rng.below(1400)));
    }
    // What the viewer sees at the end is the last version applied.
    let (code, _, v, paused, _) = status(addr);
    assert_eq!((code, v, paused), (200, version, false));

    stop.store(true, Ordering::Relaxed);
    for t in threads {
        t.join().unwrap();
    }
    r.obeyed_check(&hostile);
    // The samples: every 2 s window saw ticks.
    let samples = samples.lock().unwrap();
    for (a, b) in samples.iter().zip(samples.iter().skip(2)) {
        r.samples += 1;
        if b.1 <= a.1 {
            r.stalls += 1;
        }
    }
    r.worst_status = samples.iter().map(|s| s.2).max().unwrap_or_default();
    r.ticks = samples.last().map_or(0, |s| s.1);
    r.rss = rss.lock().unwrap().clone();
    let connections = hostile.connections.load(Ordering::Relaxed);

    // SIGTERM ends it cleanly.
    let term = Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .status()
        .unwrap();
    assert!(term.success());
    let t_stop = Instant::now();
    let exit = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if t_stop.elapsed() > Duration::from_secs(15) {
            let _ = child.kill();
            panic!("shoal watch did not stop within 15 s of SIGTERM");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(exit.success(), "{exit:?}");
    std::thread::sleep(Duration::from_millis(200));
    while out.line(Duration::from_millis(500)).is_some() {}
    assert!(
        out.all.iter().any(|l| l.contains("stopped at tick")),
        "no closing line"
    );
    eprintln!(
        "soak {secs} s (seed {seed}): {} ticks; good edits {} applied {}; bad edits {} reported {} (located at line:col {}, reported twice {}); \
         hostile connections {connections} (pause requests refused {}, obeyed {}); /status worst {:?}; \
         windows without a tick {}/{}; RSS (s, kB): {:?}; good edits first seen half-written {:?}",
        r.ticks,
        r.good,
        r.applied,
        r.bad,
        r.reported,
        r.located,
        r.repeated,
        hostile.refused.load(Ordering::Relaxed),
        hostile.obeyed.load(Ordering::Relaxed),
        r.worst_status,
        r.stalls,
        r.samples,
        r.rss,
        r.transient
    );
    r
}

impl Report {
    fn obeyed_check(&self, h: &Hostile) {
        assert_eq!(
            h.obeyed.load(Ordering::Relaxed),
            0,
            "a foreign request was obeyed"
        );
    }

    /// Every edit accounted for, the simulation never stopped.
    fn check(&self) {
        assert!(self.missing.is_empty(), "{:?}", self.missing);
        assert_eq!(self.applied, self.good);
        assert_eq!(self.reported, self.bad);
        assert!(
            self.not_named.is_empty(),
            "rejections not naming the file: {:?}",
            self.not_named
        );
        assert_eq!(self.stalls, 0, "the simulation stopped");
        assert!(
            self.worst_status < Duration::from_secs(3),
            "{:?}",
            self.worst_status
        );
        assert!(self.good > 0 && self.bad > 0);
    }

    /// Resident memory after the first tenth of the run (warm) and at the end; the growth.
    fn memory(&self) -> (u64, u64) {
        let end = self.rss.last().map_or(0, |x| x.1);
        let t_end = self.rss.last().map_or(0.0, |x| x.0);
        let warm = self
            .rss
            .iter()
            .find(|x| x.0 >= t_end * 0.1)
            .map_or(0, |x| x.1);
        (warm, end)
    }
}

#[test]
fn twenty_seconds_of_edits_and_hostile_clients_under_watch() {
    let r = soak(20, 1);
    r.check();
}

#[test]
#[ignore = "the long soak (10 minutes): SHOAL_SOAK_SECS=600 cargo test --release --test live_soak -- --ignored --nocapture"]
fn long_soak() {
    let secs = std::env::var("SHOAL_SOAK_SECS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(600);
    let seed = std::env::var("SHOAL_SOAK_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(7);
    let r = soak(secs, seed);
    r.check();
    let (warm, end) = r.memory();
    eprintln!("RSS warm {warm} kB, end {end} kB");
    // Flat: no more than 16 MiB over the warm figure after the whole run.
    assert!(
        end < warm + 16 * 1024,
        "memory grew from {warm} kB to {end} kB"
    );
}
