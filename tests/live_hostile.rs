//! The live server and `shoal watch` under hostile or broken conditions: oversized and endless
//! requests, too many connections, slow clients, requests from other origins, a reload that
//! never finishes, signals while it hangs; and `rerun`/`diff` of an interrupted run.

mod live_support;

use live_support::*;
use shoal::live::http::HttpLimits;
use shoal::live::server::{live_page, Server};
use shoal::live::{LiveEvent, LiveOptions, Session};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Sends `raw` and reads the answer: (status, body); status 0 if the connection failed first.
fn exchange(addr: SocketAddr, raw: &[u8]) -> (u16, String) {
    let Ok(mut s) = TcpStream::connect(addr) else {
        return (0, String::new());
    };
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    let _ = s.write_all(raw);
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let out = String::from_utf8_lossy(&out).into_owned();
    let status = out.get(9..12).and_then(|c| c.parse().ok()).unwrap_or(0);
    let body = out.split_once("\r\n\r\n").map(|x| x.1.to_string());
    (status, body.unwrap_or_default())
}

fn get(addr: SocketAddr, path: &str) -> (u16, String) {
    exchange(
        addr,
        format!("GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").as_bytes(),
    )
}

fn post(addr: SocketAddr, host: &str, origin: Option<&str>, body: &str) -> (u16, String) {
    let origin = origin.map_or(String::new(), |o| format!("Origin: {o}\r\n"));
    exchange(
        addr,
        format!(
            "POST /control HTTP/1.1\r\nHost: {host}\r\n{origin}Content-Type: text/plain\r\nContent-Length: {}\r\n\r\n{body}",
            body.len()
        )
        .as_bytes(),
    )
}

/// Resident memory of this process (kB).
fn rss_kb() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap();
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

fn start(p: &Project, limits: HttpLimits) -> (Session, Server) {
    let s = Session::start(&p.scenario(), LiveOptions::default()).unwrap_or_else(|d| panic!("{d}"));
    let server = Server::start_with(s.handle(), live_page(), 0, limits).unwrap();
    (s, server)
}

#[test]
fn two_hundred_hostile_connections_neither_block_a_good_request_nor_grow_memory() {
    let p = Project::new();
    let (s, server) = start(&p, HttpLimits::default());
    let addr = server.addr();
    assert_eq!(get(addr, "/status").0, 200);
    let rss0 = rss_kb();
    let mut threads = Vec::new();
    let mut held = Vec::new();
    for i in 0..200 {
        match i % 4 {
            // Endless header bytes, no newline: 8 MiB each if the server kept reading.
            0 => threads.push(std::thread::spawn(move || {
                let Ok(mut c) = TcpStream::connect(addr) else {
                    return 0;
                };
                // A server that neither reads nor closes must fail the test, not hang it.
                c.set_write_timeout(Some(Duration::from_secs(20))).unwrap();
                let _ = c.write_all(b"GET /status HTTP/1.1\r\nX-Endless: ");
                let chunk = vec![b'a'; 64 * 1024];
                let mut sent = 0;
                while sent < 8 << 20 && c.write_all(&chunk).is_ok() {
                    sent += chunk.len();
                }
                sent
            })),
            // Half a request, then silence.
            1 => {
                if let Ok(mut c) = TcpStream::connect(addr) {
                    let _ = write!(c, "GET /status HTTP/1.1\r\nHost: {addr}\r\nX-Half: ");
                    held.push(c);
                }
            }
            // Another site's page, or a rebound DNS name, trying to pause the session.
            2 => threads.push(std::thread::spawn(move || {
                let here = addr.to_string();
                let (code, _) = if i % 8 == 2 {
                    post(
                        addr,
                        &here,
                        Some("http://evil.example"),
                        r#"{"cmd":"pause"}"#,
                    )
                } else {
                    post(
                        addr,
                        &format!("evil.example:{}", addr.port()),
                        None,
                        r#"{"cmd":"pause"}"#,
                    )
                };
                // 403, or 503/0 when refused at the cap before being read.
                assert_ne!(code, 200, "a foreign request was obeyed");
                code as usize
            })),
            // Connected, nothing sent.
            _ => {
                if let Ok(c) = TcpStream::connect(addr) {
                    held.push(c);
                }
            }
        }
    }
    // A good request is answered promptly, every time, while all that goes on. At the cap a
    // connection can be refused with 503 while the slots it could displace are still being
    // drained (a busy machine makes that window wider): like the viewer, it asks again.
    let mut worst = Duration::ZERO;
    for _ in 0..10 {
        let t0 = Instant::now();
        let (mut code, mut body) = get(addr, "/status");
        for _ in 0..4 {
            if code != 503 {
                break;
            }
            std::thread::sleep(Duration::from_millis(100));
            (code, body) = get(addr, "/status");
        }
        let took = t0.elapsed();
        assert_eq!(code, 200, "{body}");
        assert!(body.contains("\"tick\""));
        worst = worst.max(took);
        std::thread::sleep(Duration::from_millis(50));
    }
    // A burst of 200 connects can overflow the kernel's accept queue, and a client whose
    // handshake was dropped retries for up to a minute: wait a little, not for every one.
    let t_join = Instant::now();
    while threads.iter().any(|t| !t.is_finished()) && t_join.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let left = threads.iter().filter(|t| !t.is_finished()).count();
    eprintln!(
        "hostile clients: {left} still running {:?} after the good requests",
        t_join.elapsed()
    );
    for t in threads.into_iter().filter(|t| t.is_finished()) {
        t.join().unwrap();
    }
    let rss1 = rss_kb();
    eprintln!(
        "worst GET /status under attack: {worst:?}; RSS {rss0} kB -> {rss1} kB (+{} kB); open connections {}",
        rss1.saturating_sub(rss0),
        server.open_connections()
    );
    assert!(worst < Duration::from_secs(2), "{worst:?}");
    assert!(
        rss1 < rss0 + 48 * 1024,
        "memory grew from {rss0} kB to {rss1} kB"
    );
    assert!(server.open_connections() <= HttpLimits::default().connections);
    assert!(!s.status().paused, "a foreign request paused the session");
    drop(held);
}

#[test]
fn oversized_requests_are_refused_with_their_status() {
    let p = Project::new();
    let (_s, server) = start(&p, HttpLimits::default());
    let addr = server.addr();
    let long = "a".repeat(9 * 1024);
    let (code, _) = exchange(
        addr,
        format!("GET /{long} HTTP/1.1\r\nHost: {addr}\r\n\r\n").as_bytes(),
    );
    assert_eq!(code, 414);
    // A 100 KiB header line: the answer arrives although the client sent more than was read.
    let huge = "h".repeat(100 * 1024);
    let (code, body) = exchange(
        addr,
        format!("GET /status HTTP/1.1\r\nHost: {addr}\r\nX-Big: {huge}\r\n\r\n").as_bytes(),
    );
    assert_eq!(code, 431, "{body}");
    let (code, _) = exchange(
        addr,
        format!("POST /control HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 2000000\r\n\r\n")
            .as_bytes(),
    );
    assert_eq!(code, 413);
    let (code, _) = exchange(addr, b"\x00\xff\r\n\r\n");
    assert_eq!(code, 400);
    assert_eq!(get(addr, "/status").0, 200);
}

#[test]
fn foreign_hosts_and_origins_are_refused_and_change_nothing() {
    let p = Project::new();
    let (s, server) = start(&p, HttpLimits::default());
    let addr = server.addr();
    let port = addr.port();
    let pause = r#"{"cmd":"pause"}"#;
    let here = addr.to_string();
    for (host, origin) in [
        (here.clone(), Some("http://evil.example".to_string())),
        (here.clone(), Some("null".to_string())),
        (here.clone(), Some(format!("http://127.0.0.1:{}", port + 1))),
        (format!("evil.example:{port}"), None),
        (format!("localhost:{}", port + 1), None),
    ] {
        let (code, body) = post(addr, &host, origin.as_deref(), pause);
        assert_eq!(code, 403, "{host} {origin:?}: {body}");
    }
    // Reading with a rebound name is refused too.
    let (code, _) = exchange(
        addr,
        format!("GET /status HTTP/1.1\r\nHost: evil.example:{port}\r\n\r\n").as_bytes(),
    );
    assert_eq!(code, 403);
    let (code, _) = exchange(addr, b"GET /status HTTP/1.0\r\n\r\n");
    assert_eq!(code, 403, "no Host");
    std::thread::sleep(Duration::from_millis(300));
    assert!(!s.status().paused);
    // The page's own requests, by any loopback name, still work.
    for origin in [
        format!("http://127.0.0.1:{port}"),
        format!("http://localhost:{port}"),
    ] {
        let host = origin.trim_start_matches("http://");
        assert_eq!(post(addr, host, Some(&origin), pause).0, 200);
    }
    assert_eq!(post(addr, &here, None, r#"{"cmd":"resume"}"#).0, 200);
    poll(Duration::from_secs(5), "pause then resume", || {
        (!s.status().paused).then_some(())
    });
}

#[test]
fn over_the_connection_cap_the_oldest_unfinished_request_makes_room_then_503() {
    let p = Project::new();
    let limits = HttpLimits {
        connections: 4,
        streams: 4,
        ..HttpLimits::default()
    };
    let (_s, server) = start(&p, limits);
    let addr = server.addr();
    // Four event streams take every place; none may be displaced.
    let mut streams = Vec::new();
    for _ in 0..4 {
        let mut c = TcpStream::connect(addr).unwrap();
        write!(c, "GET /stream HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
        let mut r = BufReader::new(c);
        let mut line = String::new();
        r.read_line(&mut line).unwrap();
        assert!(line.starts_with("HTTP/1.1 200"), "{line}");
        streams.push(r);
    }
    let mut c = TcpStream::connect(addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let mut out = String::new();
    let _ = c.read_to_string(&mut out);
    assert!(out.starts_with("HTTP/1.1 503"), "{out}");
    drop(streams);
    poll(Duration::from_secs(15), "the streams to close", || {
        (server.open_connections() == 0).then_some(())
    });
    // Silent connections fill the places; a good request displaces the oldest.
    let idle: Vec<TcpStream> = (0..4).map(|_| TcpStream::connect(addr).unwrap()).collect();
    poll(Duration::from_secs(5), "the idle connections", || {
        (server.open_connections() == 4).then_some(())
    });
    assert_eq!(get(addr, "/status").0, 200);
    drop(idle);
}

#[test]
fn a_request_sent_too_slowly_times_out_with_408() {
    let p = Project::new();
    let limits = HttpLimits {
        request_timeout: Duration::from_secs(1),
        ..HttpLimits::default()
    };
    let (_s, server) = start(&p, limits);
    let addr = server.addr();
    let mut c = TcpStream::connect(addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let t0 = Instant::now();
    // One byte every 300 ms: each read is quick, the whole request is not.
    for b in format!("GET /status HTTP/1.1\r\nHost: {addr}\r\n").bytes() {
        if c.write_all(&[b]).is_err() {
            break;
        }
        std::thread::sleep(Duration::from_millis(300));
        if t0.elapsed() > Duration::from_secs(3) {
            break;
        }
    }
    let mut out = String::new();
    let _ = c.read_to_string(&mut out);
    assert!(out.starts_with("HTTP/1.1 408"), "{out}");
    assert!(t0.elapsed() < Duration::from_secs(4));
}

/// Replaces `rel` in `p` by a named pipe nobody writes to: reading it never finishes.
fn make_fifo(p: &Project, rel: &str) {
    let path = p.path(rel);
    std::fs::remove_file(&path).unwrap();
    let ok = Command::new("mkfifo").arg(&path).status().unwrap();
    assert!(ok.success());
}

#[test]
fn a_reload_that_never_finishes_times_out_and_later_edits_still_load() {
    let p = Project::new();
    let s = Session::start(
        &p.scenario(),
        LiveOptions {
            reload_timeout: Duration::from_millis(1500),
            ..LiveOptions::default()
        },
    )
    .unwrap_or_else(|d| panic!("{d}"));
    wait_past_tick(&s, 2);
    make_fifo(&p, "behaviors/fish.ron");
    let (e, _) = wait_for(
        &s,
        Duration::from_secs(20),
        "the timeout",
        |e| matches!(e, LiveEvent::Rejected(r) if r.diagnostics.iter().any(|d| d.contains("did not finish"))),
    );
    let LiveEvent::Rejected(r) = e else {
        unreachable!()
    };
    assert!(r.diagnostics[0].contains("fish.ron"), "{:?}", r.diagnostics);
    assert_eq!(r.running, 0);
    // The viewer's status shows it, and the simulation never stopped.
    assert!(s.status().diagnostics[0].contains("did not finish"));
    let t = s.status().tick;
    wait_past_tick(&s, t + 3);
    // The fix is loaded by a fresh worker while the old one still hangs on the pipe.
    std::fs::remove_file(p.path("behaviors/fish.ron")).unwrap();
    p.write("behaviors/fish.ron", &FISH.replace("0.95", "0.5"));
    let a = accepted(&s);
    assert_eq!(a.version, 1);
    assert!(s.status().diagnostics.is_empty());
    let t0 = Instant::now();
    s.stop();
    assert!(t0.elapsed() < Duration::from_secs(3));
}

#[test]
fn sigterm_and_ctrl_c_end_watch_during_a_hung_reload_and_mark_the_record_incomplete() {
    for signal in ["-TERM", "-INT"] {
        let p = Project::new();
        let rec = p.path("record");
        let mut child = Command::new(env!("CARGO_BIN_EXE_shoal"))
            .arg("watch")
            .arg(p.scenario())
            .args(["--port", "0", "--reload-timeout-ms", "600000", "--record"])
            .arg(&rec)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut line = String::new();
        while !line.starts_with("live view:") {
            line.clear();
            assert!(out.read_line(&mut line).unwrap() > 0, "no URL");
        }
        let marker = std::fs::read_to_string(rec.join("INCOMPLETE")).unwrap();
        assert!(marker.contains("being recorded"), "{marker}");
        // Wedge the loader, then stop.
        make_fifo(&p, "behaviors/fish.ron");
        std::thread::sleep(Duration::from_millis(1500));
        let t0 = Instant::now();
        let kill = Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let status = loop {
            if let Some(st) = child.try_wait().unwrap() {
                break st;
            }
            if t0.elapsed() > Duration::from_secs(15) {
                let _ = child.kill();
                panic!("{signal}: shoal watch did not stop within 15 s");
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        let mut rest = String::new();
        let _ = out.read_to_string(&mut rest);
        eprintln!("{signal}: stopped in {:?}", t0.elapsed());
        assert!(status.success(), "{signal}: {status:?}\n{rest}");
        assert!(rest.contains("stopped at tick"), "{rest}");
        let meta: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(rec.join("live.json")).unwrap()).unwrap();
        assert_eq!(meta["status"], "incomplete", "{meta}");
        assert!(meta["stopped"].as_str().unwrap().contains("interrupted"));
        let marker = std::fs::read_to_string(rec.join("INCOMPLETE")).unwrap();
        assert!(marker.contains("stopped at tick"), "{marker}");
        let log = std::fs::read_to_string(rec.join("reloads.jsonl")).unwrap();
        let last: serde_json::Value = serde_json::from_str(log.lines().last().unwrap()).unwrap();
        assert_eq!(last["status"], "stopped");
        assert_eq!(last["tick"], meta["ticks"]);
    }
}

/// Runs `shoal` with `args`: (exit code, stdout).
fn shoal(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned()
            + String::from_utf8_lossy(&out.stderr).as_ref(),
    )
}

#[test]
fn rerun_and_diff_say_up_front_that_a_run_is_incomplete_and_compare_as_far_as_it_got() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("run");
    let child = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["run", "scenarios/reef.ron", "--duration", "3600", "--quiet"])
        .arg("--out")
        .arg(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    poll(Duration::from_secs(60), "the run to start", || {
        dir.join("trajectories.csv.partial").exists().then_some(())
    });
    std::thread::sleep(Duration::from_millis(300));
    assert!(Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "SIGTERM marks the run incomplete"
    );
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    let ticks = manifest["ticks"].as_u64().unwrap();
    let d = dir.to_str().unwrap();

    let t0 = Instant::now();
    let (code, text) = shoal(&["rerun", d]);
    eprintln!("rerun of {ticks} ticks took {:?}", t0.elapsed());
    assert!(text.contains("is an incomplete run"), "{text}");
    assert!(
        text.contains(&format!("re-running only the {ticks} ticks")),
        "{text}"
    );
    assert!(text.contains("matches bit for bit"), "{text}");
    assert_eq!(code, Some(0), "{text}");

    // A complete run a little longer than the interrupted one: same up to where it stopped.
    let full = t.path().join("full");
    let dt = manifest["dt"].as_f64().unwrap();
    let seconds = format!("{}", (ticks + 10) as f64 * dt);
    let (code, text) = shoal(&[
        "run",
        "scenarios/reef.ron",
        "--duration",
        &seconds,
        "--quiet",
        "--no-health",
        "--out",
        full.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{text}");
    let (code, text) = shoal(&["diff", d, full.to_str().unwrap()]);
    assert!(
        text.contains("A (") && text.contains("is an incomplete run"),
        "{text}"
    );
    assert!(text.contains("no divergence"), "{text}");
    assert!(!text.contains("first divergence"), "{text}");
    assert!(!text.contains("differing decisions"), "{text}");
    assert_eq!(code, Some(1));
}
