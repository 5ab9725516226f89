//! Reading one HTTP/1.1 request head (httparse), bounded in size and time, and writing a
//! response; the WebSocket opening handshake (RFC 6455 §4.2) on top of it.

use std::io::{Read, Write};
use std::net::TcpStream;

/// Largest request head accepted (request line and headers).
const MAX_HEAD_BYTES: usize = 8 * 1024;
const MAX_HEADERS: usize = 32;

/// A request that cannot be served, with the status and reason to answer.
#[derive(Debug)]
pub struct Refusal {
    pub status: u16,
    pub message: String,
}

fn refuse(status: u16, message: impl Into<String>) -> Refusal {
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
    /// Reads the request head.
    pub fn read(mut stream: &TcpStream) -> Result<Self, Refusal> {
        let mut buf = Vec::with_capacity(1024);
        let mut chunk = [0u8; 1024];
        loop {
            let n = stream.read(&mut chunk).map_err(|e| refuse(408, format!("request not received: {e}")))?;
            if n == 0 {
                return Err(refuse(400, "connection closed before the request was complete"));
            }
            buf.extend_from_slice(&chunk[..n]);
            let mut headers = [httparse::EMPTY_HEADER; MAX_HEADERS];
            let mut parsed = httparse::Request::new(&mut headers);
            match parsed.parse(&buf) {
                Ok(httparse::Status::Complete(len)) => {
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
                    return Ok(Self { method: parsed.method.unwrap_or("").into(), path, headers, rest: buf[len..].to_vec() });
                }
                Ok(httparse::Status::Partial) if buf.len() < MAX_HEAD_BYTES => {}
                Ok(httparse::Status::Partial) => return Err(refuse(431, "request head larger than 8 KiB")),
                Err(e) => return Err(refuse(400, format!("malformed request: {e}"))),
            }
        }
    }

    /// Checks that there is a `Host` header (HTTP/1.1 requires one: 400 otherwise) and that
    /// it names this machine when the server listens on loopback only: a page of another site whose name an attacker re-points at 127.0.0.1 (DNS
    /// rebinding) sends its own name as `Host`, and is refused here, beside the `Origin`
    /// check of the WebSocket upgrade.
    pub fn check_host(&self, loopback_only: bool) -> Result<(), Refusal> {
        let Some(host) = self.header("host") else {
            return Err(refuse(400, "Host header missing"));
        };
        if loopback_only && !is_loopback_host(host) {
            return Err(refuse(403, format!("host {host:?} is not this machine (the server listens on loopback only)")));
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
            let host = self.header("host").unwrap_or_default();
            let origin_host = origin.split_once("://").map_or(origin, |(_, h)| h);
            if !origin_host.eq_ignore_ascii_case(host) {
                return Err(refuse(403, format!("origin {origin} is not this server ({host})")));
            }
        }
        let key = self.header("sec-websocket-key").ok_or_else(|| refuse(400, "Sec-WebSocket-Key missing"))?;
        Ok(tungstenite::handshake::derive_accept_key(key.trim().as_bytes()))
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

/// Whether a `Host` value (`name[:port]`, `[v6][:port]`) names a loopback address.
fn is_loopback_host(host: &str) -> bool {
    let port = |p: &str| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit());
    let name = match host.strip_prefix('[') {
        Some(v6) => match v6.split_once(']') {
            Some((address, "")) => address,
            Some((address, rest)) if rest.strip_prefix(':').is_some_and(port) => address,
            _ => return false,
        },
        None => match host.rsplit_once(':') {
            Some((name, p)) if port(p) => name,
            Some(_) => return false,
            None => host,
        },
    };
    name.eq_ignore_ascii_case("localhost") || name.parse::<std::net::IpAddr>().is_ok_and(|ip| ip.is_loopback())
}

#[cfg(test)]
mod tests {
    use super::is_loopback_host;

    #[test]
    fn loopback_hosts() {
        for ok in ["127.0.0.1:8080", "127.0.0.1", "localhost:8080", "LOCALHOST", "[::1]:8080", "[::1]", "127.1.2.3:1"] {
            assert!(is_loopback_host(ok), "{ok}");
        }
        for bad in ["evil.example:8080", "evil.example", "10.0.0.1:8080", "[::2]:80", "localhost.evil.example", "127.0.0.1.evil.example", "", "[::1", "[::1]junk", "[::1]:", "localhost:80x"] {
            assert!(!is_loopback_host(bad), "{bad}");
        }
    }
}
