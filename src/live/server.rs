//! The live viewer's HTTP server: a small HTTP/1.1 handler on a loopback `TcpListener`, one
//! thread per connection up to a cap. Routes (protocol in `docs/viewer.md`, live mode):
//!
//! - `GET /`: the viewer page in live mode (the replay viewer's page, same rendering).
//! - `GET /stream`: server-sent events `world`, `frame`, `diagnostics`, `reload`.
//! - `POST /control`: `{"cmd": "pause"|"resume"|"step"|"speed", "value": 2}`.
//! - `GET /agent/<id>`: one agent's drives, behavior, stack, memory and last decisions.
//! - `GET /status`: tick, version, paused, speed, agents and current diagnostics.
//!
//! Hardening ([`HttpLimits`], requests read in [`super::http`]): bounded request line, headers and
//! body (414/431/413); a whole request must arrive within a deadline (408, slowloris); at most
//! [`HttpLimits::connections`] connections, where a new one first displaces the oldest that has not
//! finished sending its request, else gets 503; at most [`HttpLimits::streams`] event streams; every
//! request needs a loopback `Host` with this port and every state-changing one a missing or
//! loopback `Origin` (403), so no other web page can drive a session.
//!
//! Why hand-written rather than a crate: the limits above are what matter here and tiny_http 0.12
//! (the light option, ~11 s to build with tungstenite) has none on header size (tiny-http#56,
//! open since 2015) nor a connection cap, so it would need the same guards around it;
//! axum/hyper bring them but cost ~32 s debug / 50 s release with tokio for five routes on a
//! loopback socket. Neither checks `Host`/`Origin`. The server stays dependency-free, and its
//! parser is property-tested on arbitrary bytes.

use super::breakpoints::Breakpoint;
use super::http::{self, DeadlineReader, HttpLimits, Refusal};
use super::hub::Seen;
use super::{Control, SessionHandle};
use std::collections::BTreeMap;
use std::io::{BufReader, Write};
use std::net::{Ipv4Addr, Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A stream with nothing new sends a comment this often, so that dead connections are noticed.
const KEEPALIVE: Duration = Duration::from_secs(10);
/// After an error answer, how much of what the client still sends is read and dropped so that
/// closing does not reset the connection before the answer is read.
const LINGER_BYTES: usize = 256 * 1024;
/// How long that may take.
const LINGER_TIME: Duration = Duration::from_millis(500);

/// The page served at `/`: the viewer in live mode.
pub fn live_page() -> String {
    crate::view::live_html()
}

/// A running server. Dropping it stops accepting connections and closes the open ones.
pub struct Server {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    accept: Option<JoinHandle<()>>,
    conns: Arc<Connections>,
}

/// What a connection is doing: only one still sending its request, or one refused and being
/// drained before it is closed, may be displaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Reading,
    Answering,
    Streaming,
    Draining,
}

struct Entry {
    since: Instant,
    phase: Phase,
    /// Shut down to make room; its thread is on its way out.
    evicted: bool,
    stream: TcpStream,
}

/// The open connections, so that the cap can be enforced and the oldest idle one closed.
#[derive(Default)]
struct Connections {
    inner: Mutex<(u64, BTreeMap<u64, Entry>)>,
}

/// A connection's place among the open ones; dropping it frees the place.
struct Ticket {
    id: u64,
    conns: Arc<Connections>,
}

impl Connections {
    fn lock(&self) -> MutexGuard<'_, (u64, BTreeMap<u64, Entry>)> {
        // Every update is a single insert, remove or field assignment: consistent after a panic.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// A place for `stream` within `max`, closing the oldest connection still reading its
    /// request if need be; `None` if every place is taken by one being answered or streaming.
    fn admit(self: &Arc<Self>, stream: &TcpStream, max: usize) -> Option<Ticket> {
        let clone = stream.try_clone().ok()?;
        let mut g = self.lock();
        let (next, conns) = &mut *g;
        if conns.len() >= max {
            // Displaced connections still count until their thread ends (slow on a busy
            // machine); bound how many, so threads stay under twice the cap.
            let leaving = conns.values().filter(|e| e.evicted).count();
            if leaving >= max {
                return None;
            }
            // Refused ones being drained first, then the oldest unfinished request.
            let oldest = conns
                .values_mut()
                .filter(|e| matches!(e.phase, Phase::Reading | Phase::Draining) && !e.evicted)
                .min_by_key(|e| (e.phase != Phase::Draining, e.since))?;
            oldest.evicted = true;
            let _ = oldest.stream.shutdown(Shutdown::Both);
        }
        let id = *next;
        *next += 1;
        conns.insert(
            id,
            Entry {
                since: Instant::now(),
                phase: Phase::Reading,
                evicted: false,
                stream: clone,
            },
        );
        Some(Ticket {
            id,
            conns: self.clone(),
        })
    }

    fn close_all(&self) {
        for e in self.lock().1.values() {
            let _ = e.stream.shutdown(Shutdown::Both);
        }
    }
}

impl Ticket {
    fn set_phase(&self, phase: Phase) {
        if let Some(e) = self.conns.lock().1.get_mut(&self.id) {
            e.phase = phase;
        }
    }

    /// Turns this connection into an event stream if fewer than `max` are open.
    fn start_stream(&self, max: usize) -> bool {
        let mut g = self.conns.lock();
        let open = g.1.values().filter(|e| e.phase == Phase::Streaming).count();
        match g.1.get_mut(&self.id) {
            Some(e) if open < max => {
                e.phase = Phase::Streaming;
                true
            }
            _ => false,
        }
    }
}

impl Drop for Ticket {
    fn drop(&mut self) {
        self.conns.lock().1.remove(&self.id);
    }
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

/// Ends a connection whose request was refused: the client may still be sending, and closing
/// with unread data resets the connection, which can drop the answer before it is read.
fn linger_close(stream: &TcpStream) {
    let _ = stream.shutdown(Shutdown::Write);
    let until = Instant::now() + LINGER_TIME;
    let mut buf = [0u8; 16 * 1024];
    let mut drained = 0;
    let mut r = DeadlineReader::new(stream, until);
    while drained < LINGER_BYTES {
        match std::io::Read::read(&mut r, &mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => drained += n,
        }
    }
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
            "unknown cmd \"{other}\": expected pause, resume, step, speed, break or unbreak"
        )),
    }
}

/// A `/control` request: a [`Control`], or a change to the breakpoints.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    /// Pause, resume, step or speed.
    Control(Control),
    /// `{"cmd":"break", ...}`: add a breakpoint ([`Breakpoint::parse`]).
    Break(Breakpoint),
    /// `{"cmd":"unbreak","id":N}` removes one, `{"cmd":"unbreak"}` all.
    Unbreak(Option<u32>),
}

/// Parses a `/control` body; a bad one gets a reason, never a panic.
pub fn parse_request(body: &[u8]) -> Result<Request, String> {
    let v: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| format!("body is not JSON: {e}"))?;
    match v["cmd"].as_str() {
        Some("break") => Breakpoint::parse(&v).map(Request::Break),
        Some("unbreak") => match &v["id"] {
            serde_json::Value::Null => Ok(Request::Unbreak(None)),
            id => id
                .as_u64()
                .and_then(|i| u32::try_from(i).ok())
                .map(|i| Request::Unbreak(Some(i)))
                .ok_or_else(|| "\"id\" must be a breakpoint number".to_string()),
        },
        _ => parse_control(body).map(Request::Control),
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

fn handle_connection(
    mut stream: TcpStream,
    ticket: Ticket,
    handle: SessionHandle,
    page: Arc<str>,
    limits: &HttpLimits,
    port: u16,
) {
    let _ = stream.set_nodelay(true);
    let _ = stream.set_write_timeout(Some(limits.write_timeout));
    let deadline = Instant::now() + limits.request_timeout;
    let read = {
        let mut r = BufReader::new(DeadlineReader::new(&stream, deadline));
        http::read_request(&mut r, limits)
    };
    ticket.set_phase(Phase::Answering);
    let req = match read {
        Ok(r) => r,
        Err(refusal @ (Refusal::Closed | Refusal::Timeout)) => {
            // A client that vanished needs no answer; one that is too slow gets one.
            if let Some((status, msg)) = refusal.status() {
                json_error(&mut stream, status, msg);
            }
            return;
        }
        Err(refusal) => {
            if let Some((status, msg)) = refusal.status() {
                json_error(&mut stream, status, msg);
            }
            ticket.set_phase(Phase::Draining);
            linger_close(&stream);
            return;
        }
    };
    if let Some(why) = http::forbidden(&req, port) {
        json_error(&mut stream, "403 Forbidden", why);
        return;
    }
    match (req.method.as_str(), req.path.as_str()) {
        ("GET", "/") | ("GET", "/index.html") => respond(
            &mut stream,
            "200 OK",
            "text/html; charset=utf-8",
            page.as_bytes(),
        ),
        ("GET", "/stream") => {
            if ticket.start_stream(limits.streams) {
                stream_events(stream, &handle);
            } else {
                json_error(
                    &mut stream,
                    "503 Service Unavailable",
                    "too many event streams open",
                );
            }
        }
        // The control state (paused, tick, breakpoints, the hit) is the status.
        ("GET", "/status") | ("GET", "/control") => {
            let body = serde_json::to_string(&handle.status()).unwrap_or_default();
            respond(&mut stream, "200 OK", "application/json", body.as_bytes());
        }
        ("POST", "/control") => match parse_request(&req.body) {
            Ok(Request::Control(c)) => {
                handle.control(c);
                respond(&mut stream, "200 OK", "application/json", b"{\"ok\":true}");
            }
            Ok(Request::Break(b)) => match handle.add_breakpoint(b) {
                Ok(id) => {
                    let body = serde_json::json!({ "ok": true, "id": id }).to_string();
                    respond(&mut stream, "200 OK", "application/json", body.as_bytes());
                }
                Err(e) => json_error(&mut stream, "400 Bad Request", &e),
            },
            Ok(Request::Unbreak(id)) => {
                handle.remove_breakpoint(id);
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

/// Refuses a connection over the cap, from the accept loop: the answer fits the socket's send
/// buffer, so this does not block.
fn refuse_busy(mut stream: TcpStream) {
    let _ = stream.set_write_timeout(Some(Duration::from_millis(100)));
    json_error(
        &mut stream,
        "503 Service Unavailable",
        "too many connections",
    );
    let _ = stream.shutdown(Shutdown::Write);
}

impl Server {
    /// Serves `page` and the live protocol of `handle` on `127.0.0.1:port` (0: any free port)
    /// with the default [`HttpLimits`].
    pub fn start(handle: SessionHandle, page: String, port: u16) -> std::io::Result<Server> {
        Self::start_with(handle, page, port, HttpLimits::default())
    }

    /// [`Server::start`] with other limits.
    pub fn start_with(
        handle: SessionHandle,
        page: String,
        port: u16,
        limits: HttpLimits,
    ) -> std::io::Result<Server> {
        let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, port))?;
        let addr = listener.local_addr()?;
        let stop = Arc::new(AtomicBool::new(false));
        let conns = Arc::new(Connections::default());
        let page: Arc<str> = page.into();
        let limits = Arc::new(limits);
        let (stop2, conns2) = (stop.clone(), conns.clone());
        let accept = std::thread::Builder::new()
            .name("shoal-http".into())
            .spawn(move || {
                for conn in listener.incoming() {
                    if stop2.load(Ordering::Relaxed) {
                        break;
                    }
                    let stream = match conn {
                        Ok(s) => s,
                        Err(_) => {
                            // Out of file descriptors, say: wait instead of spinning.
                            std::thread::sleep(Duration::from_millis(50));
                            continue;
                        }
                    };
                    let Some(ticket) = conns2.admit(&stream, limits.connections) else {
                        refuse_busy(stream);
                        continue;
                    };
                    let (handle, page, limits) = (handle.clone(), page.clone(), limits.clone());
                    // If the thread cannot start, the closure and its ticket are dropped.
                    let _ = std::thread::Builder::new()
                        .name("shoal-http-conn".into())
                        .spawn(move || {
                            handle_connection(stream, ticket, handle, page, &limits, addr.port())
                        });
                }
            })?;
        Ok(Server {
            addr,
            stop,
            accept: Some(accept),
            conns,
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

    /// Connections open now (for tests and diagnostics).
    pub fn open_connections(&self) -> usize {
        self.conns.lock().1.len()
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
        self.conns.close_all();
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

    #[test]
    fn breakpoint_bodies() {
        assert_eq!(
            parse_request(br#"{"cmd":"step"}"#),
            Ok(Request::Control(Control::Step))
        );
        match parse_request(br#"{"cmd":"break","on":"enter","behavior":"graze","species":"fish"}"#)
        {
            Ok(Request::Break(b)) => assert_eq!(b.text(), "any fish: enters graze"),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            parse_request(br#"{"cmd":"unbreak","id":3}"#),
            Ok(Request::Unbreak(Some(3)))
        );
        assert_eq!(
            parse_request(br#"{"cmd":"unbreak"}"#),
            Ok(Request::Unbreak(None))
        );
        for bad in [
            &br#"{"cmd":"break"}"#[..],
            br#"{"cmd":"break","on":"enter"}"#,
            br#"{"cmd":"break","on":"enter","behavior":"a","agent":"x"}"#,
            br#"{"cmd":"unbreak","id":-2}"#,
            br#"[1,2]"#,
            b"\xff\xfe",
        ] {
            assert!(
                parse_request(bad).is_err(),
                "{:?}",
                String::from_utf8_lossy(bad)
            );
        }
    }
}
