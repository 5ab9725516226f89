//! Reading one HTTP/1.1 request head (httparse), bounded in size and time, and writing a
//! response; the WebSocket opening handshake (RFC 6455 §4.2) on top of it.

use std::io::{Read, Write};
use std::net::{IpAddr, SocketAddr, TcpStream};
use std::time::{Duration, Instant};

/// Largest request head accepted (request line and headers).
const MAX_HEAD_BYTES: usize = 8 * 1024;
const MAX_HEADERS: usize = 32;

/// A request that cannot be served, with the status and reason to answer.
#[derive(Debug)]
pub struct Refusal {
    pub status: u16,
    pub message: String,
}

pub fn refuse(status: u16, message: impl Into<String>) -> Refusal {
    Refusal { status, message: message.into() }
}

/// The parts of a request the server looks at.
#[derive(Debug)]
pub struct Request {
    pub method: String,
    /// Path without the query, percent-decoded.
    pub path: String,
    headers: Vec<(String, String)>,
    /// Bytes read past the head (a WebSocket client may send its first frame right away).
    pub rest: Vec<u8>,
}

impl Request {
    /// Reads the request head, all of it by `deadline` (408 after it: a head dripped a byte at
    /// a time gets no longer than one sent at once).
    pub fn read(mut stream: &TcpStream, deadline: Instant) -> Result<Self, Refusal> {
        let mut buf = Vec::with_capacity(1024);
        let mut chunk = [0u8; 1024];
        let late = || refuse(408, "request head not complete in time");
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(late());
            }
            stream.set_read_timeout(Some(left)).map_err(|e| refuse(400, format!("request not received: {e}")))?;
            let n = stream.read(&mut chunk).map_err(|e| match e.kind() {
                std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut => late(),
                _ => refuse(400, format!("request not received: {e}")),
            })?;
            if n == 0 {
                return Err(refuse(400, "connection closed before the request was complete"));
            }
            buf.extend_from_slice(&chunk[..n]);
            if let Some(request) = Self::parse(&buf)? {
                return Ok(request);
            }
        }
    }

    /// Parses a request head from the bytes received so far: `None` while it is incomplete
    /// and within [`MAX_HEAD_BYTES`]; over it, 431 whether complete or not (the bound does not
    /// depend on how the head arrived). Over bytes alone, so the `http_head` fuzz target runs it.
    pub fn parse(buf: &[u8]) -> Result<Option<Self>, Refusal> {
        let mut headers = [httparse::EMPTY_HEADER; MAX_HEADERS];
        let mut parsed = httparse::Request::new(&mut headers);
        match parsed.parse(buf) {
            Ok(httparse::Status::Complete(len)) if len <= MAX_HEAD_BYTES => {
                let target = parsed.path.unwrap_or("/");
                let raw = target.split(['?', '#']).next().unwrap_or("/");
                let path = percent_encoding::percent_decode_str(raw)
                    .decode_utf8()
                    .map_err(|_| refuse(400, "the path is not UTF-8 once percent-decoded"))?
                    .into_owned();
                let headers = parsed
                    .headers
                    .iter()
                    .map(|h| (h.name.to_ascii_lowercase(), String::from_utf8_lossy(h.value).into_owned()))
                    .collect();
                Ok(Some(Self { method: parsed.method.unwrap_or("").into(), path, headers, rest: buf[len..].to_vec() }))
            }
            Ok(httparse::Status::Partial) if buf.len() < MAX_HEAD_BYTES => Ok(None),
            Ok(_) => Err(refuse(431, "request head larger than 8 KiB")),
            Err(e) => Err(refuse(400, format!("malformed request: {e}"))),
        }
    }

    /// Checks that there is a `Host` header (HTTP/1.1 requires one: 400 otherwise) and that
    /// it names this server, listening at `bound`: `localhost`, a loopback address or the
    /// address it is bound to (any address when bound to all of them), at its port. A page of
    /// another site whose name an attacker re-points at this machine (DNS rebinding) sends its
    /// own name as `Host`, and is refused here (403), for files, the stream and the input
    /// socket alike, beside the `Origin` check of the WebSocket upgrade.
    pub fn check_host(&self, bound: SocketAddr) -> Result<(), Refusal> {
        let Some(host) = self.header("host") else {
            return Err(refuse(400, "Host header missing"));
        };
        if !names_server(host, bound) {
            return Err(refuse(403, format!("host {host:?} is not this server ({bound}; reach it as localhost or by its address)")));
        }
        Ok(())
    }

    /// The value of a header (names are compared case-insensitively).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }

    /// Checks a WebSocket upgrade request and returns the `Sec-WebSocket-Accept` value.
    ///
    /// Browsers send an `Origin`; one that is not this server (another site the person has
    /// open) is refused, so a web page cannot drive the engine behind their back.
    pub fn websocket_accept(&self) -> Result<String, Refusal> {
        let has = |name: &str, token: &str| {
            self.header(name).is_some_and(|v| v.split(',').any(|t| t.trim().eq_ignore_ascii_case(token)))
        };
        if self.method != "GET" || !has("upgrade", "websocket") || !has("connection", "upgrade") {
            return Err(refuse(426, "this path is a WebSocket: an upgrade is required"));
        }
        if self.header("sec-websocket-version") != Some("13") {
            return Err(refuse(426, "WebSocket version 13 is required"));
        }
        if let Some(origin) = self.header("origin") {
            // The page's own origin: this server's scheme and the `Host` it was reached by.
            let host = self.header("host").unwrap_or_default();
            if !origin.strip_prefix("http://").is_some_and(|h| h.eq_ignore_ascii_case(host)) {
                return Err(refuse(403, format!("origin {origin} is not this server (http://{host})")));
            }
        }
        let key = self.header("sec-websocket-key").ok_or_else(|| refuse(400, "Sec-WebSocket-Key missing"))?;
        Ok(tungstenite::handshake::derive_accept_key(key.trim().as_bytes()))
    }
}

/// Answers a refused request with its status and reason, then lingers: the client may still be
/// sending (an oversized head, a body), and closing on unread data would reset the connection
/// before it read the answer.
pub fn answer_refusal(stream: &TcpStream, refusal: &Refusal) -> std::io::Result<()> {
    let answered = respond(stream, refusal.status, "text/plain", format!("{}\n", refusal.message).as_bytes(), false);
    linger(stream);
    answered
}

/// Closes our side and reads (and drops) what the client is still sending, for up to a
/// second, before the socket goes: closing with unread data makes the kernel reset the
/// connection, and the client would lose the error message sent just before.
pub fn linger(mut stream: &TcpStream) {
    let _ = stream.shutdown(std::net::Shutdown::Write);
    let deadline = Instant::now() + Duration::from_secs(1);
    let mut sink = [0u8; 16 * 1024];
    let _ = stream.set_read_timeout(Some(Duration::from_millis(100)));
    while Instant::now() < deadline {
        match stream.read(&mut sink) {
            Ok(0) => return,
            Ok(_) => {}
            Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
            Err(_) => return,
        }
    }
}

/// Writes a complete response and lets the connection close.
pub fn respond(mut stream: &TcpStream, status: u16, content_type: &str, body: &[u8], head_only: bool) -> std::io::Result<()> {
    let reason = match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        426 => "Upgrade Required",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        _ => "Error",
    };
    let head = format!(
        "HTTP/1.1 {status} {reason}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\n\
         X-Content-Type-Options: nosniff\r\nCache-Control: no-cache\r\nConnection: close\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes())?;
    if !head_only {
        stream.write_all(body)?;
    }
    stream.flush()
}

/// Whether a `Host` value (`name[:port]`, `[v6][:port]`; port 80 when absent) names the server
/// listening at `bound`: its port, and `localhost`, a loopback address, or `bound`'s address
/// (any address when that is unspecified: the server listens on all of them). A name other
/// than `localhost` never does: a browser sends a name only for a site it resolved, which may
/// be an attacker's rebound to this machine.
fn names_server(host: &str, bound: SocketAddr) -> bool {
    let (name, port) = match host.strip_prefix('[') {
        Some(v6) => match v6.split_once(']') {
            Some((address, "")) => (address, None),
            Some((address, rest)) => match rest.strip_prefix(':') {
                Some(port) => (address, Some(port)),
                None => return false,
            },
            None => return false,
        },
        None => match host.rsplit_once(':') {
            Some((name, port)) => (name, Some(port)),
            None => (host, None),
        },
    };
    let port = match port {
        None => 80,
        Some(p) if !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()) => match p.parse::<u16>() {
            Ok(p) => p,
            Err(_) => return false,
        },
        Some(_) => return false,
    };
    let address = name.parse::<IpAddr>().ok().filter(|_| host.starts_with('[') == name.contains(':'));
    let ours = |ip: IpAddr| ip.is_loopback() || ip == bound.ip() || bound.ip().is_unspecified();
    port == bound.port() && (name.eq_ignore_ascii_case("localhost") || address.is_some_and(ours))
}

#[cfg(test)]
mod tests {
    use super::names_server;

    #[test]
    fn hosts_that_name_this_server() {
        let loopback = "127.0.0.1:8080".parse().unwrap();
        for ok in ["127.0.0.1:8080", "localhost:8080", "LOCALHOST:8080", "[::1]:8080", "127.1.2.3:8080"] {
            assert!(names_server(ok, loopback), "{ok}");
        }
        let bad = [
            "evil.example:8080", "evil.example", "127.0.0.1", "localhost", "127.0.0.1:8081", "localhost:80", "10.0.0.1:8080",
            "[::2]:8080", "localhost.evil.example:8080", "127.0.0.1.evil.example:8080", "", "[::1", "[::1]junk", "[::1]:",
            "localhost:80x", "localhost:", "::1:8080", "[127.0.0.1]:8080", "localhost:99999",
        ];
        for host in bad {
            assert!(!names_server(host, loopback), "{host}");
        }
        // Bound to one LAN address, that address too; bound to all, any address (not a name).
        let lan = "192.168.1.5:8080".parse().unwrap();
        assert!(names_server("192.168.1.5:8080", lan) && names_server("localhost:8080", lan));
        assert!(!names_server("192.168.1.6:8080", lan) && !names_server("evil.example:8080", lan));
        let all = "0.0.0.0:80".parse().unwrap();
        assert!(names_server("192.168.1.6", all) && names_server("[fe80::1]:80", all));
        assert!(!names_server("evil.example", all) && !names_server("mybox.local", all));
    }
}
