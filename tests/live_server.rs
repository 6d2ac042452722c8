//! The live viewer's HTTP protocol, spoken over a plain socket: the page, the event stream
//! (world, frames, diagnostics, reload), controls and agent inspection.

mod live_support;

use live_support::*;
use serde_json::Value;
use shoal::live::server::{live_page, Server};
use shoal::live::{LiveOptions, Session};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

fn request(addr: SocketAddr, method: &str, path: &str, body: &str) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    let status = out[9..12].parse().unwrap();
    let body = out.split_once("\r\n\r\n").unwrap().1.to_string();
    (status, body)
}

struct Stream {
    r: BufReader<TcpStream>,
}

impl Stream {
    fn open(addr: SocketAddr) -> Stream {
        let mut s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
        write!(
            s,
            "GET /stream HTTP/1.1\r\nHost: {addr}\r\nAccept: text/event-stream\r\n\r\n"
        )
        .unwrap();
        let mut r = BufReader::new(s);
        let mut line = String::new();
        r.read_line(&mut line).unwrap();
        assert!(line.starts_with("HTTP/1.1 200"), "{line}");
        let mut ct = false;
        loop {
            line.clear();
            r.read_line(&mut line).unwrap();
            if line.trim().is_empty() {
                break;
            }
            ct |= line
                .to_ascii_lowercase()
                .starts_with("content-type: text/event-stream");
        }
        assert!(ct, "not an event stream");
        Stream { r }
    }

    /// The next event: (name, JSON data).
    fn next(&mut self) -> (String, Value) {
        let (mut name, mut data) = (String::new(), String::new());
        loop {
            let mut line = String::new();
            assert!(self.r.read_line(&mut line).unwrap() > 0, "stream closed");
            let line = line.trim_end_matches(['\r', '\n']);
            if line.is_empty() {
                if !name.is_empty() {
                    return (name, serde_json::from_str(&data).unwrap());
                }
                continue;
            }
            if let Some(n) = line.strip_prefix("event: ") {
                name = n.to_string();
            } else if let Some(d) = line.strip_prefix("data: ") {
                data.push_str(d);
            }
        }
    }

    fn until(&mut self, what: &str, mut f: impl FnMut(&str, &Value) -> bool) -> Value {
        let deadline = Instant::now() + Duration::from_secs(15);
        while Instant::now() < deadline {
            let (n, v) = self.next();
            if f(&n, &v) {
                return v;
            }
        }
        panic!("no {what} on the stream");
    }
}

#[test]
fn the_live_protocol_streams_controls_and_inspects() {
    let p = Project::new();
    let s = Session::start(&p.scenario(), LiveOptions::default()).unwrap_or_else(|d| panic!("{d}"));
    let server = Server::start(s.handle(), live_page(), 0).unwrap();
    let addr = server.addr();
    assert!(addr.ip().is_loopback());

    let (code, page) = request(addr, "GET", "/", "");
    assert_eq!(code, 200);
    assert!(page.contains("window.SHOAL_LIVE = true"));

    let mut st = Stream::open(addr);
    let world = st.until("world", |n, _| n == "world");
    assert_eq!(world["species"][0]["name"], "fish");
    assert_eq!(world["species"][0]["color"], "#f0a030");
    assert_eq!(
        world["species"][0]["behaviors"],
        serde_json::json!(["graze", "wander"])
    );
    assert_eq!(
        world["bounds"]["min"],
        serde_json::json!([-20.0, 0.0, -20.0])
    );
    assert!(world["terrain"].is_null() && world["plans"] == serde_json::json!([]));
    let f1 = st.until("frame", |n, _| n == "frame");
    for (k, per) in [
        ("ids", 1),
        ("species", 1),
        ("behavior", 1),
        ("pos", 3),
        ("fwd", 3),
        ("speed", 1),
        ("stack_depth", 1),
        ("hunger", 1),
        ("libido", 1),
        ("fear", 1),
    ] {
        assert_eq!(f1[k].as_array().unwrap().len(), 24 * per, "{k}");
    }
    let t1 = f1["tick"].as_u64().unwrap();
    let f2 = st.until("a later frame", |n, v| {
        n == "frame" && v["tick"].as_u64().unwrap() >= t1 + 5
    });
    assert!((f2["time"].as_f64().unwrap() - f2["tick"].as_f64().unwrap() * 0.05).abs() < 1e-6);
    assert_ne!(f1["pos"], f2["pos"], "agents do not move");
    // Run health streams as the replay shows it: columns with bounds, the species' figures.
    let h = st.until("health", |n, v| {
        n == "health" && v["ticks"].as_u64().unwrap_or(0) > 0
    });
    assert_eq!(h["species"][0]["name"], "fish");
    assert_eq!(h["species"][0]["agents"], 24);
    let columns = h["columns"].as_array().unwrap();
    assert_eq!(
        h["species"][0]["values"].as_array().unwrap().len(),
        columns.len()
    );
    assert!(columns.iter().any(|c| c["key"] == "switch_rate"), "{h}");
    assert!(h["warnings"].is_array() && h["since_tick"] == 0, "{h}");

    // A broken edit shows up as diagnostics, the fix clears them and announces a reload.
    let broken = FISH.replace("Above(Drive(Hunger), 0.95)", "Abov(Drive(Hunger), 0.95)");
    p.write("behaviors/fish.ron", &broken);
    let d = st.until("diagnostics", |n, v| {
        n == "diagnostics" && !v.as_array().unwrap().is_empty()
    });
    let text = d[0].as_str().unwrap();
    assert!(
        text.contains("fish.ron:15:19: unknown condition `Abov`"),
        "{text}"
    );
    let (_, status) = request(addr, "GET", "/status", "");
    let status: Value = serde_json::from_str(&status).unwrap();
    assert_eq!(status["diagnostics"][0], d[0]);
    p.write("behaviors/fish.ron", &FISH.replace("0.95", "0.5"));
    // Cleared diagnostics, the new world (its behaviors) and a reload message, in one batch or
    // several.
    let (mut cleared, mut world, mut reload) = (false, false, None);
    st.until("the reload", |n, v| {
        match n {
            "diagnostics" => cleared |= v.as_array().unwrap().is_empty(),
            "world" => world = true,
            "reload" => reload = Some(v.clone()),
            _ => {}
        }
        cleared && world && reload.is_some()
    });
    let r = reload.unwrap();
    assert!(r["message"].as_str().unwrap().contains("version 1"), "{r}");

    // Controls.
    let (code, _) = request(addr, "POST", "/control", r#"{"cmd":"pause"}"#);
    assert_eq!(code, 200);
    let paused = poll(Duration::from_secs(5), "pause", || {
        let st = s.status();
        st.paused.then_some(st.tick)
    });
    request(addr, "POST", "/control", r#"{"cmd":"step"}"#);
    poll(Duration::from_secs(5), "a step", || {
        (s.status().tick == paused + 1).then_some(())
    });
    request(addr, "POST", "/control", r#"{"cmd":"speed","value":2}"#);
    poll(Duration::from_secs(5), "speed", || {
        (s.status().speed == 2.0).then_some(())
    });
    let (code, body) = request(addr, "POST", "/control", r#"{"cmd":"fly"}"#);
    assert_eq!(code, 400);
    assert!(body.contains("unknown cmd"));
    request(addr, "POST", "/control", r#"{"cmd":"resume"}"#);

    // Inspection: an agent that started grazing after the fix.
    let w = s.world().unwrap();
    let grazer = w.agents.iter().find(|a| a.drives.hunger > 0.5).unwrap();
    let (code, body) = request(addr, "GET", &format!("/agent/{}", grazer.id.0), "");
    assert_eq!(code, 200);
    let a: Value = serde_json::from_str(&body).unwrap();
    assert_eq!(a["id"], grazer.id.0);
    assert_eq!(a["species"], "fish");
    assert_eq!(a["behavior"], "graze");
    assert_eq!(a["stack"], serde_json::json!(["wander"]));
    assert!((a["drives"]["hunger"].as_f64().unwrap() - grazer.drives.hunger as f64).abs() < 1e-6);
    assert!(a["drives"]["libido"].is_number() && a["drives"]["fear"].is_number());
    assert!(a["memory"]["n"].as_i64().unwrap() > 0);
    let last = a["decisions"].as_array().unwrap().last().unwrap().clone();
    assert_eq!(last["from"], "wander");
    assert_eq!(last["to"], "graze");
    assert_eq!(last["cause"], "interrupted");
    assert_eq!(last["condition"], "hunger > 0.5");
    assert!(last["tick"].is_u64());
    // Once inspected, the agent is explained from the next tick on.
    let explained = poll(Duration::from_secs(5), "explained agent", || {
        let (_, body) = request(addr, "GET", &format!("/agent/{}", grazer.id.0), "");
        let a: Value = serde_json::from_str(&body).ok()?;
        a["explain"].is_object().then_some(a)
    });
    assert_eq!(explained["explain"]["id"], grazer.id.0);
    assert!(explained["explain"]["term"]
        .as_str()
        .is_some_and(|t| !t.is_empty()));
    assert!(explained["dt"].as_f64().is_some_and(|d| d > 0.0));
    assert_eq!(request(addr, "GET", "/agent/999999", "").0, 404);
    assert_eq!(request(addr, "GET", "/agent/x", "").0, 400);
    assert_eq!(request(addr, "GET", "/nowhere", "").0, 404);
    assert_eq!(request(addr, "DELETE", "/control", "").0, 405);
    drop(st);
    drop(server);
    s.stop();
}
