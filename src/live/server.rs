//! The live viewer's HTTP server: a small HTTP/1.1 handler on a loopback `TcpListener`, one
//! thread per connection. Routes (protocol in `docs/viewer.md`, live mode):
//!
//! - `GET /`: the viewer page in live mode (the replay viewer's page, same rendering).
//! - `GET /stream`: server-sent events `world`, `frame`, `diagnostics`, `reload`.
//! - `POST /control`: `{"cmd": "pause"|"resume"|"step"|"speed", "value": 2}`.
//! - `GET /agent/<id>`: one agent's drives, behavior, stack, memory and last decisions.
//! - `GET /status`: tick, version, paused, speed, agents and current diagnostics.

use super::hub::Seen;
use super::{Control, SessionHandle};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Ipv4Addr, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Largest request head accepted.
const MAX_HEAD: usize = 16 * 1024;
/// Largest request body accepted.
const MAX_BODY: usize = 64 * 1024;
/// A stream with nothing new sends a comment this often, so that dead connections are noticed.
const KEEPALIVE: Duration = Duration::from_secs(10);

/// The page served at `/`: the viewer in live mode.
pub fn live_page() -> String {
    crate::view::live_html()
}

/// A running server. Dropping it stops accepting connections.
pub struct Server {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    accept: Option<JoinHandle<()>>,
}

struct Request {
    method: String,
    path: String,
    body: Vec<u8>,
}

fn read_request(stream: &mut TcpStream) -> Option<Request> {
    let mut reader = BufReader::new(stream.try_clone().ok()?);
    let mut head = Vec::new();
    let mut line = String::new();
    let mut content_length = 0usize;
    let mut first = None;
    loop {
        line.clear();
        let n = reader.read_line(&mut line).ok()?;
        if n == 0 {
            return None;
        }
        head.extend_from_slice(line.as_bytes());
        if head.len() > MAX_HEAD {
            return None;
        }
        let l = line.trim_end();
        if l.is_empty() {
            break;
        }
        if first.is_none() {
            first = Some(l.to_string());
        } else if let Some((k, v)) = l.split_once(':') {
            if k.trim().eq_ignore_ascii_case("content-length") {
                content_length = v.trim().parse().ok()?;
            }
        }
    }
    let first = first?;
    let mut parts = first.split_whitespace();
    let method = parts.next()?.to_string();
    let target = parts.next()?;
    let path = target.split(['?', '#']).next().unwrap_or("/").to_string();
    if content_length > MAX_BODY {
        return None;
    }
    let mut body = vec![0; content_length];
    reader.read_exact(&mut body).ok()?;
    Some(Request { method, path, body })
}

fn respond(stream: &mut TcpStream, status: &str, content_type: &str, body: &[u8]) {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    );
    let _ = stream.write_all(head.as_bytes());
    let _ = stream.write_all(body);
    let _ = stream.flush();
}

fn json_error(stream: &mut TcpStream, status: &str, msg: &str) {
    let body = serde_json::json!({ "error": msg }).to_string();
    respond(stream, status, "application/json", body.as_bytes());
}

/// Parses a `/control` body.
pub fn parse_control(body: &[u8]) -> Result<Control, String> {
    let v: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| format!("body is not JSON: {e}"))?;
    let cmd = v["cmd"].as_str().ok_or("missing \"cmd\"")?;
    match cmd {
        "pause" => Ok(Control::Pause),
        "resume" | "play" => Ok(Control::Resume),
        "step" => Ok(Control::Step),
        "speed" => {
            let x = v["value"]
                .as_f64()
                .ok_or("\"speed\" needs a numeric \"value\"")?;
            if x.is_finite() && x > 0.0 {
                Ok(Control::Speed(x as f32))
            } else {
                Err("\"speed\" must be positive".into())
            }
        }
        other => Err(format!(
            "unknown cmd \"{other}\": expected pause, resume, step or speed"
        )),
    }
}

fn stream_events(mut stream: TcpStream, handle: &SessionHandle) {
    let head = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nConnection: keep-alive\r\nX-Accel-Buffering: no\r\n\r\nretry: 1000\n\n";
    if stream.write_all(head.as_bytes()).is_err() {
        return;
    }
    let _ = stream.set_write_timeout(Some(Duration::from_secs(10)));
    let mut seen = Seen::default();
    while let Some(items) = handle.hub().next(&mut seen, KEEPALIVE) {
        let mut out = String::new();
        if items.is_empty() {
            out.push_str(": keepalive\n\n");
        }
        for (name, data) in items {
            out.push_str("event: ");
            out.push_str(name);
            out.push_str("\ndata: ");
            // JSON has no raw newlines except inside the diagnostics' strings, where they are
            // escaped; one data line per event.
            out.push_str(&data);
            out.push_str("\n\n");
        }
        if stream.write_all(out.as_bytes()).is_err() || stream.flush().is_err() {
            return;
        }
    }
}

fn handle_connection(mut stream: TcpStream, handle: SessionHandle, page: Arc<str>) {
    let _ = stream.set_read_timeout(Some(Duration::from_secs(10)));
    let _ = stream.set_nodelay(true);
    let Some(req) = read_request(&mut stream) else {
        json_error(&mut stream, "400 Bad Request", "malformed request");
        return;
    };
    match (req.method.as_str(), req.path.as_str()) {
        ("GET", "/") | ("GET", "/index.html") => respond(
            &mut stream,
            "200 OK",
            "text/html; charset=utf-8",
            page.as_bytes(),
        ),
        ("GET", "/stream") => stream_events(stream, &handle),
        ("GET", "/status") => {
            let body = serde_json::to_string(&handle.status()).unwrap_or_default();
            respond(&mut stream, "200 OK", "application/json", body.as_bytes());
        }
        ("POST", "/control") => match parse_control(&req.body) {
            Ok(c) => {
                handle.control(c);
                respond(&mut stream, "200 OK", "application/json", b"{\"ok\":true}");
            }
            Err(e) => json_error(&mut stream, "400 Bad Request", &e),
        },
        ("GET", p) if p.starts_with("/agent/") => match p["/agent/".len()..].parse::<u32>() {
            Ok(id) => match handle.inspect(id) {
                Some(info) => {
                    let body = serde_json::to_string(&info).unwrap_or_default();
                    respond(&mut stream, "200 OK", "application/json", body.as_bytes());
                }
                None => json_error(&mut stream, "404 Not Found", "no such agent"),
            },
            Err(_) => json_error(&mut stream, "400 Bad Request", "agent ids are integers"),
        },
        (_, "/" | "/stream" | "/status" | "/control") => {
            json_error(&mut stream, "405 Method Not Allowed", "method not allowed")
        }
        _ => json_error(&mut stream, "404 Not Found", "not found"),
    }
}

impl Server {
    /// Serves `page` and the live protocol of `handle` on `127.0.0.1:port` (0: any free port).
    pub fn start(handle: SessionHandle, page: String, port: u16) -> std::io::Result<Server> {
        let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, port))?;
        let addr = listener.local_addr()?;
        let stop = Arc::new(AtomicBool::new(false));
        let page: Arc<str> = page.into();
        let stop2 = stop.clone();
        let accept = std::thread::Builder::new()
            .name("shoal-http".into())
            .spawn(move || {
                for conn in listener.incoming() {
                    if stop2.load(Ordering::Relaxed) {
                        break;
                    }
                    let Ok(stream) = conn else { continue };
                    let (handle, page) = (handle.clone(), page.clone());
                    let _ = std::thread::Builder::new()
                        .name("shoal-http-conn".into())
                        .spawn(move || handle_connection(stream, handle, page));
                }
            })?;
        Ok(Server {
            addr,
            stop,
            accept: Some(accept),
        })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// `http://127.0.0.1:<port>/`.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        // Wake the accept loop.
        let _ = TcpStream::connect_timeout(&self.addr, Duration::from_millis(200));
        if let Some(t) = self.accept.take() {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_bodies() {
        assert_eq!(parse_control(br#"{"cmd":"pause"}"#), Ok(Control::Pause));
        assert_eq!(parse_control(br#"{"cmd":"resume"}"#), Ok(Control::Resume));
        assert_eq!(parse_control(br#"{"cmd":"step"}"#), Ok(Control::Step));
        assert_eq!(
            parse_control(br#"{"cmd":"speed","value":2}"#),
            Ok(Control::Speed(2.0))
        );
        assert!(parse_control(br#"{"cmd":"speed"}"#).is_err());
        assert!(parse_control(br#"{"cmd":"speed","value":-1}"#).is_err());
        assert!(parse_control(br#"{"cmd":"jump"}"#)
            .unwrap_err()
            .contains("unknown cmd"));
        assert!(parse_control(b"nope").is_err());
    }
}
