//! Reading one HTTP/1.1 request for the live viewer's server, within fixed limits: the request
//! line, each header line, the whole head and the body are bounded, so that no sequence of bytes
//! makes the server hold more than [`HttpLimits::head`] + [`HttpLimits::body`] per connection, and every
//! refusal maps to a status code. Also the loopback checks of `Host` and `Origin` that keep other
//! web pages (cross-site requests, DNS rebinding) away from a live session.

use std::io::{self, BufRead, Read};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Size and time limits of the server.
#[derive(Debug, Clone, PartialEq)]
pub struct HttpLimits {
    /// Longest request line or header line (bytes, without the line end).
    pub line: usize,
    /// Largest request head: request line and headers together.
    pub head: usize,
    /// Most header fields.
    pub headers: usize,
    /// Largest request body.
    pub body: usize,
    /// Most connections served at once (streams included).
    pub connections: usize,
    /// Most event streams at once (a subset of `connections`).
    pub streams: usize,
    /// Time a client has to send its whole request, from the moment it connects.
    pub request_timeout: Duration,
    /// Longest a write to a client may block (a reader that stopped reading).
    pub write_timeout: Duration,
}

impl Default for HttpLimits {
    fn default() -> Self {
        HttpLimits {
            line: 8 * 1024,
            head: 64 * 1024,
            headers: 100,
            body: 1024 * 1024,
            connections: 64,
            streams: 16,
            request_timeout: Duration::from_secs(10),
            write_timeout: Duration::from_secs(10),
        }
    }
}

/// Why a request was not read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Refusal {
    /// Malformed (400).
    BadRequest(&'static str),
    /// The request line is longer than [`HttpLimits::line`] (414).
    UriTooLong,
    /// A header line, the head or the number of headers is over its limit (431).
    HeadersTooLarge,
    /// The body is larger than [`HttpLimits::body`] (413).
    BodyTooLarge,
    /// A body without `Content-Length` (411).
    LengthRequired,
    /// The request did not arrive within [`HttpLimits::request_timeout`] (408).
    Timeout,
    /// The client closed the connection or it failed: nothing to answer.
    Closed,
}

impl Refusal {
    /// Status line and message of the answer, if one is due.
    pub fn status(&self) -> Option<(&'static str, &'static str)> {
        Some(match self {
            Refusal::BadRequest(m) => ("400 Bad Request", m),
            Refusal::UriTooLong => ("414 URI Too Long", "request line too long"),
            Refusal::HeadersTooLarge => (
                "431 Request Header Fields Too Large",
                "request headers too large",
            ),
            Refusal::BodyTooLarge => ("413 Content Too Large", "request body too large"),
            Refusal::LengthRequired => (
                "411 Length Required",
                "a body needs Content-Length (chunked bodies are not accepted)",
            ),
            Refusal::Timeout => ("408 Request Timeout", "request not received in time"),
            Refusal::Closed => return None,
        })
    }
}

/// A request as read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// Method, as sent (`GET`, `POST`...).
    pub method: String,
    /// Path of the target, without query or fragment.
    pub path: String,
    /// The `Host` header.
    pub host: Option<String>,
    /// The `Origin` header.
    pub origin: Option<String>,
    /// The body (`Content-Length` bytes).
    pub body: Vec<u8>,
}

fn io_refusal(e: &io::Error) -> Refusal {
    match e.kind() {
        // A socket read timeout shows as `WouldBlock` on Unix, `TimedOut` elsewhere.
        io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut => Refusal::Timeout,
        _ => Refusal::Closed,
    }
}

/// Appends one line (without its `\n` or `\r\n`) to `line`; `too_long` once it passes `max`
/// bytes, before reading further.
fn read_line(
    r: &mut impl BufRead,
    line: &mut Vec<u8>,
    max: usize,
    too_long: Refusal,
) -> Result<(), Refusal> {
    line.clear();
    loop {
        let buf = match r.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(io_refusal(&e)),
        };
        if buf.is_empty() {
            return Err(Refusal::Closed);
        }
        let (take, done) = match buf.iter().position(|&b| b == b'\n') {
            Some(i) => (i, true),
            None => (buf.len(), false),
        };
        // +1: room for the `\r` of a line of exactly `max` bytes.
        if line.len() + take > max + 1 {
            return Err(too_long);
        }
        line.extend_from_slice(&buf[..take]);
        r.consume(if done { take + 1 } else { take });
        if done {
            if line.last() == Some(&b'\r') {
                line.pop();
            }
            if line.len() > max {
                return Err(too_long);
            }
            return Ok(());
        }
    }
}

fn is_token(s: &[u8]) -> bool {
    !s.is_empty()
        && s.iter()
            .all(|&b| b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b))
}

/// Reads one request from `r` within `limits` (sizes only; time limits belong to the reader).
pub fn read_request(r: &mut impl BufRead, limits: &HttpLimits) -> Result<Request, Refusal> {
    let mut line = Vec::new();
    let mut head_size = 0usize;
    // A client may send empty lines before the request line (RFC 9112 §2.2).
    for skipped in 0.. {
        read_line(r, &mut line, limits.line, Refusal::UriTooLong)?;
        head_size += line.len() + 2;
        if !line.is_empty() {
            break;
        }
        if skipped >= 4 {
            return Err(Refusal::BadRequest("no request line"));
        }
    }
    let mut parts = line.split(|&b| b == b' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(Refusal::BadRequest("malformed request line"));
    };
    if !is_token(method) || !version.starts_with(b"HTTP/1.") || target.is_empty() {
        return Err(Refusal::BadRequest("malformed request line"));
    }
    let method = String::from_utf8_lossy(method).into_owned();
    let target = String::from_utf8_lossy(target);
    let path = target.split(['?', '#']).next().unwrap_or("/").to_string();
    let (mut host, mut origin, mut length, mut chunked) = (None, None, None, false);
    let mut count = 0;
    loop {
        read_line(r, &mut line, limits.line, Refusal::HeadersTooLarge)?;
        head_size += line.len() + 2;
        if head_size > limits.head {
            return Err(Refusal::HeadersTooLarge);
        }
        if line.is_empty() {
            break;
        }
        count += 1;
        if count > limits.headers {
            return Err(Refusal::HeadersTooLarge);
        }
        let colon = line.iter().position(|&b| b == b':');
        let Some(colon) = colon.filter(|&c| is_token(&line[..c])) else {
            return Err(Refusal::BadRequest("malformed header line"));
        };
        let name = &line[..colon];
        let value = String::from_utf8_lossy(&line[colon + 1..])
            .trim_matches([' ', '\t'])
            .to_string();
        let once = |slot: &mut Option<String>, v: String| {
            if slot.replace(v).is_some() {
                Err(Refusal::BadRequest("repeated header"))
            } else {
                Ok(())
            }
        };
        if name.eq_ignore_ascii_case(b"host") {
            once(&mut host, value)?;
        } else if name.eq_ignore_ascii_case(b"origin") {
            once(&mut origin, value)?;
        } else if name.eq_ignore_ascii_case(b"content-length") {
            if value.is_empty() || !value.bytes().all(|b| b.is_ascii_digit()) {
                return Err(Refusal::BadRequest("bad Content-Length"));
            }
            // More digits than fit: certainly too large.
            let n: usize = value.parse().unwrap_or(usize::MAX);
            if length.is_some_and(|l| l != n) {
                return Err(Refusal::BadRequest("conflicting Content-Length"));
            }
            length = Some(n);
        } else if name.eq_ignore_ascii_case(b"transfer-encoding") {
            chunked = true;
        }
    }
    if chunked {
        return Err(Refusal::LengthRequired);
    }
    let length = length.unwrap_or(0);
    if length > limits.body {
        return Err(Refusal::BodyTooLarge);
    }
    let mut body = vec![0; length];
    r.read_exact(&mut body).map_err(|e| match e.kind() {
        io::ErrorKind::UnexpectedEof => Refusal::Closed,
        _ => io_refusal(&e),
    })?;
    Ok(Request {
        method,
        path,
        host,
        origin,
        body,
    })
}

/// Reads from a socket until a fixed deadline: each read waits at most the time left, so a
/// client that sends one byte every few seconds still runs out of time.
pub struct DeadlineReader<'a> {
    stream: &'a TcpStream,
    until: Instant,
}

impl<'a> DeadlineReader<'a> {
    /// Reads `stream` until `until`.
    pub fn new(stream: &'a TcpStream, until: Instant) -> Self {
        DeadlineReader { stream, until }
    }
}

impl Read for DeadlineReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let left = self.until.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(io::ErrorKind::TimedOut.into());
        }
        self.stream.set_read_timeout(Some(left))?;
        (&mut &*self.stream).read(buf)
    }
}

/// Whether `host` (a `Host` header, or the authority of an origin) names this server on the
/// loopback interface: `localhost`, `127.0.0.1` or `[::1]`, with `port` (which may be left out
/// only when it is 80).
pub fn is_loopback_host(host: &str, port: u16) -> bool {
    let (name, rest) = match host.strip_prefix('[') {
        Some(v6) => match v6.split_once(']') {
            Some((name, rest)) => (name, rest),
            None => return false,
        },
        // Without brackets, a colon can only start the port.
        None => match host.split_once(':') {
            Some((name, _)) => (name, &host[name.len()..]),
            None => (host, ""),
        },
    };
    let port_ok = match rest.strip_prefix(':') {
        Some(p) => !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()) && p.parse() == Ok(port),
        None => rest.is_empty() && port == 80,
    };
    let name_ok = name.eq_ignore_ascii_case("localhost") || name == "127.0.0.1" || name == "::1";
    port_ok && name_ok
}

/// Whether `origin` (an `Origin` header) is a page served by this server: `http://` and a
/// loopback host with `port`. `null` (sandboxed frames, files) is not.
pub fn is_loopback_origin(origin: &str, port: u16) -> bool {
    origin
        .strip_prefix("http://")
        .is_some_and(|h| !h.contains(['/', '@']) && is_loopback_host(h, port))
}

/// Methods that change nothing; any other must come from this server's own page.
pub fn is_safe_method(method: &str) -> bool {
    matches!(method, "GET" | "HEAD" | "OPTIONS")
}

/// Why `req` may not be served on `port`, if it may not: a `Host` that is not this server on the
/// loopback interface (DNS rebinding), or a state-changing request from another origin.
pub fn forbidden(req: &Request, port: u16) -> Option<&'static str> {
    match &req.host {
        None => return Some("missing Host header"),
        Some(h) if !is_loopback_host(h, port) => {
            return Some("Host must be localhost, 127.0.0.1 or [::1] with this server's port")
        }
        Some(_) => {}
    }
    match &req.origin {
        Some(o) if !is_safe_method(&req.method) && !is_loopback_origin(o, port) => {
            Some("cross-origin request refused")
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn read(bytes: &[u8]) -> Result<Request, Refusal> {
        read_request(&mut io::BufReader::new(bytes), &HttpLimits::default())
    }

    #[test]
    fn a_well_formed_request() {
        let r = read(
            b"POST /control?x=1 HTTP/1.1\r\nHost: 127.0.0.1:7471\r\nOrigin: http://localhost:7471\r\ncontent-length: 4\r\n\r\nabcdEXTRA",
        )
        .unwrap();
        assert_eq!(r.method, "POST");
        assert_eq!(r.path, "/control");
        assert_eq!(r.host.as_deref(), Some("127.0.0.1:7471"));
        assert_eq!(r.origin.as_deref(), Some("http://localhost:7471"));
        assert_eq!(r.body, b"abcd");
        // Bare `\n` line ends, leading empty lines.
        let r = read(b"\r\nGET / HTTP/1.0\nHost: localhost:1\n\n").unwrap();
        assert_eq!((r.method.as_str(), r.path.as_str()), ("GET", "/"));
    }

    #[test]
    fn sizes_over_the_limits_are_refused_with_their_status() {
        let long = "a".repeat(9 * 1024);
        let line = format!("GET /{long} HTTP/1.1\r\n\r\n");
        assert_eq!(read(line.as_bytes()), Err(Refusal::UriTooLong));
        let header = format!("GET / HTTP/1.1\r\nX: {long}\r\n\r\n");
        assert_eq!(read(header.as_bytes()), Err(Refusal::HeadersTooLarge));
        // A line of exactly the limit passes.
        let exact = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "b".repeat(8 * 1024 - 3));
        assert!(read(exact.as_bytes()).is_ok());
        // Many lines, each short, add up.
        let many = format!(
            "GET / HTTP/1.1\r\n{}\r\n",
            format!("X: {}\r\n", "c".repeat(4000)).repeat(20)
        );
        assert_eq!(read(many.as_bytes()), Err(Refusal::HeadersTooLarge));
        let count = format!("GET / HTTP/1.1\r\n{}\r\n", "X: 1\r\n".repeat(101));
        assert_eq!(read(count.as_bytes()), Err(Refusal::HeadersTooLarge));
        let body = "POST /control HTTP/1.1\r\nContent-Length: 1048577\r\n\r\n";
        assert_eq!(read(body.as_bytes()), Err(Refusal::BodyTooLarge));
        let huge = "POST /control HTTP/1.1\r\nContent-Length: 99999999999999999999999\r\n\r\n";
        assert_eq!(read(huge.as_bytes()), Err(Refusal::BodyTooLarge));
        let chunked = "POST /control HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n";
        assert_eq!(read(chunked.as_bytes()), Err(Refusal::LengthRequired));
    }

    #[test]
    fn an_endless_line_is_refused_after_the_limit_not_read_to_its_end() {
        // 1 GiB of `a` without a newline, produced lazily: the reader must stop early.
        let endless = io::repeat(b'a').take(1 << 30);
        let mut r = io::BufReader::new(b"GET / HTTP/1.1\r\nX-Long: ".chain(endless));
        let mut limits = HttpLimits::default();
        assert_eq!(read_request(&mut r, &limits), Err(Refusal::HeadersTooLarge));
        limits.line = 16;
        let mut r = io::BufReader::new(io::repeat(b'G').take(1 << 30));
        assert_eq!(read_request(&mut r, &limits), Err(Refusal::UriTooLong));
    }

    #[test]
    fn malformed_requests_are_bad_requests_or_closed() {
        for bad in [
            &b"GET /\r\n\r\n"[..],
            b"GET / HTTP/1.1 extra\r\n\r\n",
            b"G\xffT / HTTP/1.1\r\n\r\n",
            b"GET / SPDY/3\r\n\r\n",
            b"GET / HTTP/1.1\r\nno colon\r\n\r\n",
            b"GET / HTTP/1.1\r\n folded: x\r\n\r\n",
            b"GET / HTTP/1.1\r\nContent-Length: -1\r\n\r\n",
            b"GET / HTTP/1.1\r\nContent-Length: 1\r\nContent-Length: 2\r\n\r\n",
            b"GET / HTTP/1.1\r\nHost: a\r\nHost: b\r\n\r\n",
            b"\r\n\r\n\r\n\r\n\r\n\r\n",
        ] {
            assert!(
                matches!(read(bad), Err(Refusal::BadRequest(_))),
                "{:?}: {:?}",
                String::from_utf8_lossy(bad),
                read(bad)
            );
        }
        assert_eq!(read(b"GET / HTTP/1.1\r\nHost: x"), Err(Refusal::Closed));
        assert_eq!(
            read(b"POST / HTTP/1.1\r\nContent-Length: 10\r\n\r\nabc"),
            Err(Refusal::Closed)
        );
    }

    #[test]
    fn loopback_hosts_and_origins() {
        for ok in [
            "localhost:7471",
            "LocalHost:7471",
            "127.0.0.1:7471",
            "[::1]:7471",
        ] {
            assert!(is_loopback_host(ok, 7471), "{ok}");
            assert!(is_loopback_origin(&format!("http://{ok}"), 7471), "{ok}");
        }
        for bad in [
            "localhost:7472",
            "localhost",
            "localhost:",
            "evil.example:7471",
            "localhost.evil.example:7471",
            "127.0.0.2:7471",
            "[::1]",
            "[::1:7471",
            "::1:7471",
            "127.0.0.1:7471:7471",
            "127.0.0.1:+7471",
            "",
        ] {
            assert!(!is_loopback_host(bad, 7471), "{bad}");
        }
        assert!(is_loopback_host("localhost", 80));
        for bad in [
            "null",
            "https://localhost:7471",
            "http://evil.example:7471",
            "http://localhost:7471/",
            "http://user@localhost:7471",
            "localhost:7471",
        ] {
            assert!(!is_loopback_origin(bad, 7471), "{bad}");
        }
    }

    #[test]
    fn state_changes_need_this_servers_host_and_origin() {
        let req = |method: &str, host: Option<&str>, origin: Option<&str>| Request {
            method: method.into(),
            path: "/control".into(),
            host: host.map(Into::into),
            origin: origin.map(Into::into),
            body: Vec::new(),
        };
        let here = Some("127.0.0.1:9000");
        assert_eq!(forbidden(&req("POST", here, None), 9000), None);
        assert_eq!(
            forbidden(&req("POST", here, Some("http://localhost:9000")), 9000),
            None
        );
        assert!(forbidden(&req("POST", here, Some("http://evil.example")), 9000).is_some());
        assert!(forbidden(&req("POST", here, Some("null")), 9000).is_some());
        assert!(forbidden(&req("PUT", here, Some("http://evil.example")), 9000).is_some());
        // Reading needs the right Host only (a cross-site page cannot read the answer).
        assert_eq!(
            forbidden(&req("GET", here, Some("http://evil.example")), 9000),
            None
        );
        assert!(forbidden(&req("GET", Some("evil.example:9000"), None), 9000).is_some());
        assert!(forbidden(&req("GET", None, None), 9000).is_some());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        #[test]
        fn any_bytes_give_a_request_or_a_refusal(bytes in proptest::collection::vec(any::<u8>(), 0..2048)) {
            let _ = read(&bytes);
        }

        #[test]
        fn any_request_shaped_bytes_too(
            method in "[A-Z]{0,8}",
            target in "[ -~]{0,40}",
            headers in proptest::collection::vec(("[ -~]{0,12}", "[ -~\\x80-\\xff]{0,40}"), 0..8),
            body in proptest::collection::vec(any::<u8>(), 0..64),
        ) {
            let mut s = format!("{method} {target} HTTP/1.1\r\n").into_bytes();
            for (k, v) in &headers {
                s.extend_from_slice(format!("{k}: {v}\r\n").as_bytes());
            }
            s.extend_from_slice(b"\r\n");
            s.extend_from_slice(&body);
            if let Ok(r) = read(&s) {
                let _ = forbidden(&r, 7471);
                prop_assert!(r.body.len() <= body.len());
            }
        }

        #[test]
        fn host_checks_never_panic(host in "\\PC{0,30}", port in any::<u16>()) {
            let _ = is_loopback_host(&host, port);
            let _ = is_loopback_origin(&host, port);
        }
    }
}
