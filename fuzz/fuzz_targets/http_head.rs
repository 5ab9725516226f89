//! The server's request-head reader, compiled in as is (the CLI is a binary the fuzz crate
//! cannot depend on): any bytes give a request, a refusal or "read on", never a panic; a head
//! over 8 KiB is refused with 431, never taken, and one arriving in pieces is read on until
//! then; the host and upgrade checks take any request; and a path that escapes once
//! percent-decoded (a `..` segment, NUL, a backslash) is never resolved to a file.
#![no_main]

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::LazyLock;

use libfuzzer_sys::fuzz_target;

// The server's own modules; the responses and file serving in them go unused here.
#[allow(dead_code)]
#[path = "../../crates/dqhand-cli/src/server/request.rs"]
mod request;
#[allow(dead_code)]
#[path = "../../crates/dqhand-cli/src/server/assets.rs"]
mod assets;

use request::Request;

/// The bound the server states (431 "request head larger than 8 KiB"), not its constant.
const HEAD_LIMIT: usize = 8 * 1024;

/// A built page to resolve paths in: `index.html` and `assets/app.js`, canonical.
static ROOT: LazyLock<PathBuf> = LazyLock::new(|| {
    let dir = std::env::temp_dir().join(format!("dqhand-fuzz-site-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    std::fs::write(dir.join("index.html"), "<html>").unwrap();
    std::fs::write(dir.join("assets/app.js"), "").unwrap();
    dir.canonicalize().unwrap()
});

/// Addresses the server may be bound to: loopback, all of them (IPv4), IPv6 loopback.
static BOUND: LazyLock<[SocketAddr; 3]> =
    LazyLock::new(|| ["127.0.0.1:8080", "0.0.0.0:80", "[::1]:9000"].map(|a| a.parse().unwrap()));

fuzz_target!(|bytes: &[u8]| {
    let request = match Request::parse(bytes) {
        Ok(Some(request)) => request,
        Ok(None) => return assert!(bytes.len() < HEAD_LIMIT, "an incomplete head over the bound is read on"),
        Err(refusal) => return assert!(matches!(refusal.status, 400 | 431), "{refusal:?}"),
    };
    let head = bytes.len() - request.rest.len();
    assert!(head <= HEAD_LIMIT, "a head of {head} bytes is taken");
    // The server reads heads as they arrive: a part of this one is not yet a request or refusal.
    for part in [head - 1, head / 2] {
        assert!(matches!(Request::parse(&bytes[..part]), Ok(None)), "{part} bytes of a {head}-byte head");
    }
    for bound in *BOUND {
        let _ = request.check_host(bound);
    }
    let _ = request.websocket_accept();
    let file = assets::resolve(&ROOT, &request.path);
    if request.path.split('/').any(|s| s == "..") || request.path.contains(['\0', '\\']) {
        assert_eq!(file, None, "{:?} escapes", request.path);
    }
    if let Some(file) = file {
        assert!(file.starts_with(&*ROOT) && file.is_file(), "{:?} resolves to {file:?}", request.path);
    }
});
