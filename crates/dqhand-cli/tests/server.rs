//! `dqhand demo` as a server: what it binds to, the files it serves (and refuses), and the
//! engine stream under good and bad clients.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use dqhand::skin::MethodSet;
use dqhand_stream::{FrameView, Topology};
use serde_json::Value;
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

/// A running `dqhand demo` on a free loopback port, killed when dropped.
struct Server {
    child: Child,
    address: String,
    banner: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A directory that stands in for the built page, and a secret beside it.
fn site(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dqhand-server-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("site/assets")).unwrap();
    std::fs::write(dir.join("site/index.html"), "<!doctype html><title>viewer</title>").unwrap();
    std::fs::write(dir.join("site/assets/app.js"), "console.log(1)").unwrap();
    std::fs::write(dir.join("secret.txt"), "do not serve").unwrap();
    dir
}

fn start(test: &str, extra: &[&str]) -> Server {
    let dir = site(test);
    let viewer = dir.join("site");
    let mut child = Command::new(env!("CARGO_BIN_EXE_dqhand"))
        .args(["demo", "--no-open", "--port", "0", "--viewer"])
        .arg(&viewer)
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let mut banner = String::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        banner.push_str(&line);
        banner.push('\n');
        if let Some(url) = line.strip_prefix("viewer: http://") {
            let address = url.trim_end_matches('/').to_string();
            std::thread::spawn(move || lines.for_each(drop));
            return Server { child, address, banner };
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    panic!("no URL printed: {banner}");
}

/// Sends a raw request and returns the status code and body.
fn http(address: &str, request: &str) -> (u16, String) {
    let mut s = TcpStream::connect(address).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut response = String::new();
    let _ = s.read_to_string(&mut response);
    let status = response.split(' ').nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
    let body = response.split_once("\r\n\r\n").map_or("", |(_, b)| b).to_string();
    (status, body)
}

fn get(address: &str, path: &str) -> (u16, String) {
    http(address, &format!("GET {path} HTTP/1.1\r\nHost: {address}\r\n\r\n"))
}

type Client = WebSocket<MaybeTlsStream<TcpStream>>;

fn connect(server: &Server) -> Client {
    let (mut ws, _) = tungstenite::connect(format!("ws://{}/stream", server.address)).unwrap();
    if let MaybeTlsStream::Plain(s) = ws.get_mut() {
        s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    }
    ws
}

fn text(ws: &mut Client) -> Value {
    loop {
        match ws.read().unwrap() {
            Message::Text(t) => return serde_json::from_str(&t).unwrap(),
            Message::Binary(_) => {}
            other => panic!("unexpected {other:?}"),
        }
    }
}

/// The next frame, acknowledged.
fn next_frame(ws: &mut Client) -> FrameView {
    loop {
        if let Message::Binary(b) = ws.read().unwrap() {
            if b.starts_with(b"DQHF") {
                let f = FrameView::parse(&b).unwrap();
                ws.send(Message::text(format!(r#"{{"type":"ack","seq":{}}}"#, f.header.sequence))).unwrap();
                return f;
            }
        }
    }
}

/// Reads until an error message arrives (acknowledging frames meanwhile).
fn next_error(ws: &mut Client) -> String {
    loop {
        match ws.read().unwrap() {
            Message::Text(t) => {
                let v: Value = serde_json::from_str(&t).unwrap();
                if v["type"] == "error" {
                    return v["message"].as_str().unwrap().to_string();
                }
            }
            Message::Binary(b) if b.starts_with(b"DQHF") => {
                let seq = FrameView::parse(&b).unwrap().header.sequence;
                // The server may already be closing (after an oversized message).
                let _ = ws.send(Message::text(format!(r#"{{"type":"ack","seq":{seq}}}"#)));
            }
            _ => {}
        }
    }
}

#[test]
fn binds_to_loopback_by_default_and_says_so() {
    let server = start("banner", &[]);
    assert!(server.address.starts_with("127.0.0.1:"), "{}", server.address);
    assert!(server.banner.contains("this machine only"), "{}", server.banner);
}

#[test]
fn serves_the_page_and_nothing_outside_it() {
    let server = start("files", &[]);
    let a = &server.address;
    assert_eq!(get(a, "/"), (200, "<!doctype html><title>viewer</title>".into()));
    assert_eq!(get(a, "/assets/app.js").0, 200);
    assert_eq!(get(a, "/index.html?x=1").0, 200);
    // The page runs its engine here rather than in itself (a static host has no such file).
    let (status, body) = get(a, "/engine.json");
    assert_eq!((status, serde_json::from_str::<Value>(&body).unwrap()["engine"].as_str()), (200, Some("dqhand demo")));
    assert_eq!(http(a, &format!("POST /engine.json HTTP/1.1\r\nHost: {a}\r\nContent-Length: 0\r\n\r\n")).0, 405);
    assert_eq!(http(a, &format!("GET /engine.json HTTP/1.1\r\nHost: evil.example:{}\r\n\r\n", a.rsplit(':').next().unwrap())).0, 403, "a rebound Host is refused here too");
    for path in ["/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt", "/..%2fsecret.txt", "/assets%5c..%5c..%5csecret.txt", "//etc/passwd", "/missing.js", "/%zz"] {
        let (status, body) = get(a, path);
        assert!(status == 404 || status == 400, "{path}: {status}");
        assert!(!body.contains("do not serve"), "{path} leaked the file");
    }
    assert_eq!(http(a, &format!("POST / HTTP/1.1\r\nHost: {a}\r\nContent-Length: 0\r\n\r\n")).0, 405);
    assert_eq!(http(a, "this is not http\r\n\r\n").0, 400);
    let huge = format!("GET / HTTP/1.1\r\nHost: {a}\r\nX-Big: {}\r\n\r\n", "a".repeat(10_000));
    assert_eq!(http(a, &huge).0, 431);
    assert_eq!(get(a, "/stream").0, 426, "the stream path needs an upgrade");
    let foreign = format!(
        "GET /stream HTTP/1.1\r\nHost: {a}\r\nOrigin: http://evil.example\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"
    );
    assert_eq!(http(a, &foreign).0, 403, "another site's page may not drive the engine");
    assert_eq!(get(a, "/").0, 200, "still serving");
}

/// Issue 9 bug 8: DNS rebinding. A page of evil.example whose name was re-pointed at
/// 127.0.0.1 sends `Host: evil.example` and a matching `Origin`; on loopback, refused.
#[test]
fn on_loopback_a_host_that_is_not_this_machine_is_refused() {
    let server = start("host", &[]);
    let a = &server.address;
    let port = a.rsplit_once(':').unwrap().1;
    let rebound = format!(
        "GET /stream HTTP/1.1\r\nHost: evil.example:{port}\r\nOrigin: http://evil.example:{port}\r\nUpgrade: websocket\r\n\
         Connection: Upgrade\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"
    );
    let (status, body) = http(a, &rebound);
    assert_eq!(status, 403, "{body}");
    assert!(body.contains("evil.example"), "{body}");
    assert_eq!(http(a, &format!("GET / HTTP/1.1\r\nHost: evil.example:{port}\r\n\r\n")).0, 403, "files too");
    assert_eq!(http(a, "GET / HTTP/1.1\r\n\r\n").0, 400, "no Host at all");
    for host in [format!("localhost:{port}"), format!("127.0.0.1:{port}")] {
        assert_eq!(http(a, &format!("GET / HTTP/1.1\r\nHost: {host}\r\n\r\n")).0, 200, "{host}");
    }
    // Issue 15: this machine at another port, or without one, is not this server either; the
    // input socket refuses a rebound page as the stream does; an Origin must be this server's
    // http origin (not https, not null).
    let other_port = port.parse::<u16>().unwrap().wrapping_add(1);
    for host in [format!("127.0.0.1:{other_port}"), "localhost".to_owned(), "127.0.0.1".to_owned()] {
        assert_eq!(http(a, &format!("GET / HTTP/1.1\r\nHost: {host}\r\n\r\n")).0, 403, "{host}");
    }
    let upgrade = |path: &str, host: &str, origin: &str| {
        format!(
            "GET {path} HTTP/1.1\r\nHost: {host}\r\nOrigin: {origin}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
             Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"
        )
    };
    let evil = format!("evil.example:{port}");
    assert_eq!(http(a, &upgrade("/input", &evil, &format!("http://{evil}"))).0, 403, "the input socket too");
    for origin in [format!("https://{a}"), "null".to_owned(), format!("http://{a}.evil.example")] {
        assert_eq!(http(a, &upgrade("/stream", a, &origin)).0, 403, "{origin}");
    }
}

#[test]
fn streams_hello_topology_and_frames_and_applies_edits() {
    let server = start("stream", &[]);
    let mut ws = connect(&server);
    let hello = text(&mut ws);
    assert_eq!(hello["type"], "hello");
    assert_eq!(hello["joint_model"], "full");
    assert!(hello["scene"].is_null(), "no scene without --scene: {}", hello["scene"]);
    let vertices = hello["vertices"].as_u64().unwrap() as u32;
    let Message::Binary(topology) = ws.read().unwrap() else { panic!("topology expected") };
    let topology = Topology::parse(&topology).unwrap();
    assert_eq!(topology.vertex_count, vertices);
    let f = next_frame(&mut ws);
    assert_eq!(f.header.vertex_count, vertices);
    assert_eq!(f.header.methods, MethodSet::DQB);
    assert!(f.header.state & 1 != 0, "the default scene plays the gesture sequence");
    ws.send(Message::text(r#"{"type":"view","methods":["lb","qb","dqb"]}"#)).unwrap();
    ws.send(Message::text(r#"{"type":"angle","dof":"index-finger-phalanx-intermediate.flex","deg":90}"#)).unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let f = next_frame(&mut ws);
        if f.header.mesh_count() == 3 && (f.angles[9].to_degrees() - 90.0).abs() < 1e-3 {
            assert_eq!(f.header.state & 1, 0, "an edit pauses the timeline");
            break;
        }
        assert!(Instant::now() < deadline, "edits never showed in the frames");
    }
    ws.send(Message::text(r#"{"type":"joint_model","name":"paper"}"#)).unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        if let Message::Text(t) = ws.read().unwrap() {
            let v: Value = serde_json::from_str(&t).unwrap();
            assert_eq!(v["type"], "hello");
            assert_eq!(v["dofs"].as_array().unwrap().len(), 18);
            break;
        }
        assert!(Instant::now() < deadline);
    }
}

#[test]
fn bad_messages_get_an_error_and_the_server_keeps_serving() {
    let server = start("bad", &[]);
    let mut watcher = connect(&server);
    next_frame(&mut watcher);
    let mut ws = connect(&server);
    next_frame(&mut ws);
    for (message, expect) in [
        (Message::text("{not json"), "not a valid command"),
        (Message::text(r#"{"type":"teleport"}"#), "unknown variant"),
        (Message::text(r#"{"type":"angle","dof":"nose.flex","deg":3}"#), "unknown degree of freedom"),
        (Message::binary(vec![1u8, 2, 3]), "binary messages are not commands"),
        (Message::text(format!(r#"{{"type":"rest","pad":"{}"}}"#, "x".repeat(10_000))), "at most 4096"),
    ] {
        ws.send(message).unwrap();
        let e = next_error(&mut ws);
        assert!(e.contains(expect), "{e:?} should mention {expect:?}");
    }
    next_frame(&mut ws); // the same connection goes on
    // Larger than any message the server reads: an error, then the connection is closed.
    ws.send(Message::text("x".repeat(200_000))).unwrap();
    let e = next_error(&mut ws);
    assert!(e.contains("closing"), "{e}");
    let closed = loop {
        match ws.read() {
            Ok(Message::Close(_)) | Err(tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed) => break true,
            Err(tungstenite::Error::Io(e)) => break !matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut),
            Err(tungstenite::Error::Protocol(_)) => break true,
            Ok(_) => {}
            Err(e) => panic!("{e}"),
        }
    };
    assert!(closed, "the connection is closed after an oversized message");
    // The other viewer never noticed.
    let before = next_frame(&mut watcher).header.sequence;
    for _ in 0..10 {
        next_frame(&mut watcher);
    }
    assert_eq!(next_frame(&mut watcher).header.sequence, before + 11);
    assert_eq!(get(&server.address, "/").0, 200);
}

#[test]
fn clients_that_vanish_or_stall_do_not_stall_the_others() {
    let server = start("vanish", &["--fps", "200"]);
    let mut watcher = connect(&server);
    next_frame(&mut watcher);
    // One client leaves in the middle of a frame, one never reads, one sends half a message.
    {
        let mut ws = connect(&server);
        text(&mut ws);
        if let MaybeTlsStream::Plain(s) = ws.get_mut() {
            let mut partial = [0u8; 1000];
            let _ = s.read(&mut partial);
            s.shutdown(std::net::Shutdown::Both).unwrap();
        }
    }
    let _stalled = connect(&server);
    let mut half = TcpStream::connect(&server.address).unwrap();
    let a = &server.address;
    write!(half, "GET /stream HTTP/1.1\r\nHost: {a}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n").unwrap();
    half.write_all(&[0x81, 0xfe, 0x10]).unwrap(); // a masked text frame header, cut short
    drop(half);
    let start = Instant::now();
    let first = next_frame(&mut watcher).header.sequence;
    let mut last = first;
    while start.elapsed() < Duration::from_millis(1500) {
        last = next_frame(&mut watcher).header.sequence;
    }
    let rate = f64::from(last - first) / start.elapsed().as_secs_f64();
    assert!(rate > 20.0, "the watcher kept receiving frames ({rate:.0}/s)");
}

#[test]
fn refuses_a_port_in_use_and_a_missing_viewer() {
    let server = start("port", &[]);
    let port = server.address.rsplit(':').next().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand"))
        .args(["demo", "--no-open", "--port", port, "--viewer"])
        .arg(site("port2").join("site"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("cannot listen on 127.0.0.1:{port}")), "{err}");
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["demo", "--no-open", "--viewer", "/nonexistent/dist"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/dist: no index.html"));
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["demo", "--fps", "0"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

/// A synthetic, labelled recording (`dqhand synthesize`) in the test's directory: its path
/// and labels.
fn synthesize(test: &str, format: &str, extension: &str) -> (PathBuf, Value) {
    let path = site(test).join(format!("rec.{extension}"));
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["synthesize", "--format", format, "--seed", "3", "--out"]).arg(&path).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let labels = serde_json::from_str(&std::fs::read_to_string(path.with_extension("labels.json")).unwrap()).unwrap();
    (path, labels)
}

/// A joints recording's lines and labels.
fn recording(test: &str) -> (Vec<String>, Value) {
    let (path, labels) = synthesize(test, "joints", "jsonl");
    (std::fs::read_to_string(&path).unwrap().lines().map(str::to_owned).collect(), labels)
}

/// The stream's next message that is not a frame (frames are acknowledged on the way).
fn next_text(ws: &mut Client) -> Value {
    loop {
        match ws.read().unwrap() {
            Message::Text(t) => return serde_json::from_str(&t).unwrap(),
            Message::Binary(b) if b.starts_with(b"DQHF") => {
                let seq = FrameView::parse(&b).unwrap().header.sequence;
                ws.send(Message::text(format!(r#"{{"type":"ack","seq":{seq}}}"#))).unwrap();
            }
            _ => {}
        }
    }
}

/// Without a recording or UDP port the demo still takes records on its `/input` WebSocket:
/// a viewer is told of the input with its first record, follows the hand, sees the
/// recognised gestures, and the held gestures of the command table change its view. A bad
/// record is answered with an error naming it, and the stream goes on.
#[test]
fn the_input_socket_drives_the_viewers_and_gestures_act_as_commands() {
    // Generous grace and latency: a stalled thread on a loaded machine is not a dropout here.
    let config = site("input-socket-config").join("config.json");
    std::fs::write(&config, r#"{"grace_s": 2.0, "max_latency_s": 5.0}"#).unwrap();
    let server = start("input-socket", &["--config", config.to_str().unwrap()]);
    let (lines, labels) = recording("input-socket-rec");
    let mut viewer = connect(&server);
    let hello = text(&mut viewer);
    assert!(hello["input"].is_null(), "no input until a record comes: {hello}");
    let (mut input, _) = tungstenite::connect(format!("ws://{}/input", server.address)).unwrap();
    input.send(Message::text("{\"t\": 0.1, \"joints\": {\"wrist\"")).unwrap();
    let Message::Text(reply) = input.read().unwrap() else { panic!("an error reply expected") };
    assert!(reply.contains("\"error\"") && reply.contains("truncated record"), "{reply}");
    input.send(Message::text("x".repeat(20_000))).unwrap();
    let Message::Text(reply) = input.read().unwrap() else { panic!("an error reply expected") };
    assert!(reply.contains("20000 bytes (at most 16384)"), "{reply}");
    let sender = std::thread::spawn(move || {
        for line in &lines {
            input.send(Message::text(line.as_str())).unwrap();
            std::thread::sleep(Duration::from_millis(1));
        }
        input
    });
    let again = next_text(&mut viewer);
    assert_eq!(again["type"], "hello", "the hello again, announcing the input: {again}");
    assert_eq!(again["input"]["source"], "WebSocket /input");
    assert!(again["input"]["gestures"].as_array().unwrap().len() >= 12);
    let (mut events, mut actions, mut states) = (Vec::new(), Vec::new(), Vec::new());
    let deadline = Instant::now() + Duration::from_secs(120);
    while states.last() != Some(&"lost".to_owned()) {
        let m = next_text(&mut viewer);
        assert_eq!(m["type"], "input", "{m}");
        assert!(Instant::now() < deadline, "the input never ended: {states:?}");
        events.extend(m["events"].as_array().unwrap().iter().filter(|e| e["event"] == "start").map(|e| e["gesture"].as_str().unwrap().to_owned()));
        actions.extend(m["actions"].as_array().unwrap().iter().map(|a| a["action"].as_str().unwrap().to_owned()));
        states.push(m["tracking"].as_str().unwrap().to_owned());
        if states.last().unwrap() == "lost" {
            assert!(m["accepted"].as_u64().unwrap() > 1000 && m["rejected"] == 2, "{m}");
        }
    }
    drop(sender.join().unwrap());
    let labelled: Vec<&str> = labels["holds"].as_array().unwrap().iter().map(|h| h["gesture"].as_str().unwrap()).collect();
    let mut expected_events = labelled.clone();
    expected_events.dedup();
    assert_eq!(events, expected_events, "each labelled gesture starts once, in order");
    let expected_actions: Vec<&str> = labelled
        .iter()
        .filter_map(|g| match *g {
            "thumbs_up" => Some("next_method"),
            "victory" => Some("split_view"),
            "rock" => Some("toggle_heatmap"),
            _ => None,
        })
        .collect();
    assert_eq!(actions, expected_actions, "the default command table, once per hold");
    // The view the commands left (DQB → …): the frames show it, with the hand where the input left it.
    let mut methods = vec!["dqb"]; // a viewer's first view
    for a in &expected_actions {
        match *a {
            "next_method" => methods = vec![["qb", "dqb", "cor", "lb"][["lb", "qb", "dqb", "cor"].iter().position(|m| *m == methods[0]).unwrap()]],
            "split_view" => methods = vec!["lb", "qb", "dqb", "cor"],
            _ => {}
        }
    }
    let heatmap = expected_actions.iter().filter(|a| **a == "toggle_heatmap").count() % 2 == 1;
    let f = next_frame(&mut viewer);
    assert_eq!(f.header.methods.as_slice().iter().map(|m| m.as_str()).collect::<Vec<_>>(), methods);
    assert_eq!(f.header.distortion, heatmap);
    assert!(f.angles.iter().any(|a| a.abs() > 0.1), "the hand holds the input's last pose, not the rest pose");
    assert_eq!(f.header.state & 1, 0, "the input stopped the timeline");
    // A viewer arriving now is told of the input at once.
    let mut late = connect(&server);
    assert_eq!(text(&mut late)["input"]["source"], "WebSocket /input");
}

/// `--udp` and `--input`: the viewers are told of the input from the start and follow it.
#[test]
fn udp_and_recorded_inputs_are_announced_and_followed() {
    let (lines, _) = recording("udp-rec");
    let server = start("udp", &["--udp", "0"]);
    let address = server.banner.lines().find_map(|l| l.strip_prefix("input: udp ")).and_then(|l| l.split(',').next()).unwrap_or_else(|| panic!("{}", server.banner)).to_owned();
    let mut viewer = connect(&server);
    assert_eq!(text(&mut viewer)["input"]["source"], format!("udp {address}"));
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    for line in lines.iter().take(300) {
        socket.send_to(line.as_bytes(), &address).unwrap();
        std::thread::sleep(Duration::from_millis(1));
    }
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let m = next_text(&mut viewer);
        if m["tracking"] == "lost" && m["accepted"].as_u64().unwrap() >= 250 {
            break;
        }
        assert!(Instant::now() < deadline, "{m}");
    }
}

/// A glove, a joints and a landmarks recording each drive the viewer: announced, tracking,
/// a labelled gesture recognised, the frames showing the hand bent.
#[test]
fn every_recording_format_drives_the_viewer() {
    for (format, extension) in [("glove", "csv"), ("joints", "jsonl"), ("landmarks", "jsonl")] {
        let (path, labels) = synthesize(&format!("recorded-{format}-rec"), format, extension);
        let labelled: Vec<&str> = labels["holds"].as_array().unwrap().iter().map(|h| h["gesture"].as_str().unwrap()).collect();
        let server = start(&format!("recorded-{format}"), &["--input", path.to_str().unwrap()]);
        let mut viewer = connect(&server);
        assert_eq!(text(&mut viewer)["input"]["source"], path.display().to_string());
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let m = next_text(&mut viewer);
            if m["tracking"] == "tracking" && m["gesture"].as_str().is_some_and(|g| labelled.contains(&g) && g != "open_palm") {
                break;
            }
            assert!(Instant::now() < deadline, "{format}: none of {labelled:?} recognised: {m}");
        }
        let f = next_frame(&mut viewer);
        assert!(f.angles.iter().any(|a| a.to_degrees() > 30.0), "{format}: the hand follows the recording");
    }
}

/// The input socket is a WebSocket of this server: a page of another site is refused, and
/// so is a fifth sender at once.
#[test]
fn the_input_socket_refuses_other_origins() {
    let server = start("input-origin", &[]);
    let a = &server.address;
    let (status, _) = http(
        a,
        &format!(
            "GET /input HTTP/1.1\r\nHost: {a}\r\nOrigin: http://evil.example\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
             Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n"
        ),
    );
    assert_eq!(status, 403);
    assert_eq!(get(a, "/input").0, 426, "a plain GET is not an upgrade");
    // Senders are few: the fifth at once is refused, the viewers' connections stay free.
    let senders: Vec<_> = (0..4).map(|_| tungstenite::connect(format!("ws://{a}/input")).unwrap()).collect();
    match tungstenite::connect(format!("ws://{a}/input")) {
        Err(tungstenite::Error::Http(response)) => assert_eq!(response.status(), 503),
        other => panic!("a fifth sender was not refused: {:?}", other.map(|(_, r)| r.status())),
    }
    drop(senders);
    let mut viewer = connect(&server);
    assert_eq!(text(&mut viewer)["type"], "hello");
}

/// `--scene grasp` without an input plays a scripted grasp of each object, made at start:
/// the hello carries the table and the objects' shapes, and scene messages follow the objects
/// and the contacts until the hand holds the ball.
#[test]
fn a_scene_is_in_the_hello_and_streamed_until_the_ball_is_held() {
    let server = start("scene", &["--scene", "grasp"]);
    assert!(server.banner.contains("scene: grasp, 2 objects (ball, teapot)"), "{}", server.banner);
    let mut ws = connect(&server);
    let hello = text(&mut ws);
    assert_eq!(hello["input"]["source"], "scripted grasps in scene grasp (synthetic)", "{}", hello["input"]);
    let scene = &hello["scene"];
    assert_eq!(scene["table"]["height"], 0.75);
    assert!(scene["table"]["half"][0].as_f64().unwrap() >= 0.6, "{}", scene["table"]);
    let objects = scene["objects"].as_array().unwrap();
    assert_eq!(objects[0]["name"], "ball");
    assert_eq!(objects[0]["shape"], "sphere");
    assert!((objects[0]["radius"].as_f64().unwrap() - 0.04).abs() < 1e-6);
    assert_eq!((&objects[1]["name"], &objects[1]["shape"], &objects[1]["simplified"]), (&"teapot".into(), &"mesh".into(), &false.into()));
    let (positions, indices) = (objects[1]["positions"].as_array().unwrap(), objects[1]["indices"].as_array().unwrap());
    assert!(indices.len() > 300 && indices.len() % 3 == 0 && positions.len() % 3 == 0, "{} indices, {} coordinates", indices.len(), positions.len());
    assert!(indices.iter().all(|i| (i.as_u64().unwrap() as usize) < positions.len() / 3));
    // The teapot is scaled 0.6 in the scene file: about 0.6 × 0.3 m wide.
    let xs: Vec<f64> = positions.iter().step_by(3).map(|x| x.as_f64().unwrap()).collect();
    let width = xs.iter().copied().fold(f64::MIN, f64::max) - xs.iter().copied().fold(f64::MAX, f64::min);
    assert!((0.1..0.3).contains(&width), "teapot {width} m wide");
    let (mut scenes, mut contacts, mut ball_moved) = (0, 0, false);
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        assert!(Instant::now() < deadline, "the ball was never held: {scenes} scene messages, {contacts} with contacts");
        let m = next_text(&mut ws);
        if m["type"] != "scene" {
            assert_eq!(m["type"], "input", "{m}");
            continue;
        }
        scenes += 1;
        assert!(m["objects"]["teapot"]["q"].as_array().unwrap().len() == 4, "{m}");
        let ball = m["objects"]["ball"]["p"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect::<Vec<_>>();
        ball_moved |= (ball[1] - 0.79).abs() > 0.01;
        let c = m["contacts"].as_array().unwrap();
        assert!(c.len() <= 64);
        if let Some(c) = c.first() {
            contacts += 1;
            assert!(c["bone"].as_str().is_some() && c["p"].as_array().unwrap().len() == 3 && c["n"].as_array().unwrap().len() == 3, "{c}");
        }
        if m["held"] == "ball" {
            break;
        }
        assert!(m["held"].is_null(), "{m}");
    }
    assert!(contacts > 0, "the hand touched the ball before holding it");
    assert!(!ball_moved, "the ball rested on the table until it was held");
    // Held, it is lifted with the hand.
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let m = next_text(&mut ws);
        if m["type"] == "scene" && m["objects"]["ball"]["p"][1].as_f64().unwrap() > 0.85 {
            assert_eq!(m["held"], "ball");
            break;
        }
        assert!(Instant::now() < deadline, "the held ball was never lifted");
    }
}

#[test]
fn a_bad_scene_file_is_refused_naming_it() {
    let dir = site("bad-scene");
    let path = dir.join("scene.json");
    std::fs::write(&path, r#"{"objects": [{"name": "ball", "shape": "sphere", "radius": -1, "position": [0, 1, 0], "mass": 1}]}"#).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["demo", "--no-open", "--port", "0", "--viewer"]).arg(dir.join("site")).arg("--scene").arg(&path).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&path.display().to_string()) && err.contains("radius"), "{err}");
}

/// Issue 15: a text message that is not UTF-8 gets the error line and the close RFC 6455 asks
/// for (1007), not a dropped connection; the server goes on serving.
#[test]
fn a_text_message_that_is_not_utf8_is_answered_and_closed_with_1007() {
    let server = start("not-utf8", &[]);
    let mut ws = connect(&server);
    // A masked text frame (mask 0: the payload as is) of two bytes that are not UTF-8.
    if let MaybeTlsStream::Plain(s) = ws.get_mut() {
        s.write_all(&[0x81, 0x82, 0, 0, 0, 0, 0xff, 0xfe]).unwrap();
    }
    let (mut error, mut close) = (None, None);
    while close.is_none() {
        match ws.read() {
            Ok(Message::Text(t)) => {
                let v: Value = serde_json::from_str(&t).unwrap();
                if v["type"] == "error" {
                    error = Some(v["message"].as_str().unwrap().to_owned());
                }
            }
            Ok(Message::Close(frame)) => close = Some(frame.map(|f| u16::from(f.code))),
            Ok(_) => {}
            Err(e) => panic!("the connection ended without a close frame: {e}"),
        }
    }
    assert!(error.as_deref().is_some_and(|m| m.contains("not UTF-8")), "{error:?}");
    assert_eq!(close, Some(Some(1007)));
    assert_eq!(get(&server.address, "/").0, 200, "still serving");
}

/// Issue 15: slowloris. 200 sockets that drip a request head hold only their own places
/// among the heads still arriving: a page GET and a new viewer are served meanwhile (before,
/// 64 such sockets took every connection and everyone got 503), and a dripped head gets 408
/// once its deadline (5 s for the whole head) is past, however steadily it drips.
#[test]
fn clients_dripping_request_heads_lock_nobody_out() {
    let server = start("slowloris", &[]);
    let a = server.address.clone();
    let mut drippers: Vec<TcpStream> = (0..200)
        .map(|_| {
            let mut s = TcpStream::connect(&a).unwrap();
            s.write_all(b"G").unwrap();
            s
        })
        .collect();
    assert_eq!(get(&a, "/").0, 200, "the page is served while 200 heads drip");
    let mut viewer = connect(&server);
    assert_eq!(text(&mut viewer)["type"], "hello", "a new viewer is served too");
    // One keeps dripping a byte every 400 ms: refused once its 5 s are up.
    let slow = &mut drippers[0];
    slow.set_read_timeout(Some(Duration::from_millis(400))).unwrap();
    let mut answer = Vec::new();
    for _ in 0..25 {
        if slow.write_all(b"E").is_err() {
            break;
        }
        let mut buf = [0u8; 512];
        match slow.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => answer.extend_from_slice(&buf[..n]),
            Err(_) => {}
        }
    }
    let answer = String::from_utf8_lossy(&answer);
    assert!(answer.starts_with("HTTP/1.1 408"), "{answer:?}");
}

/// Issue 15: a refused request still being sent (a 16 MiB header, far past the 8 KiB bound and
/// what the sockets buffer) gets its status: the server reads and drops the rest before it
/// closes. (Over loopback Linux kept the answer readable even when the server closed on unread
/// data, so this guards the answer, not the reset a slower network can cause.)
#[test]
fn a_refusal_reaches_a_client_still_sending() {
    let server = start("linger", &[]);
    let mut s = TcpStream::connect(&server.address).unwrap();
    let mut writer = s.try_clone().unwrap();
    let head = format!("GET / HTTP/1.1\r\nHost: {}\r\nX-Big: {}\r\n\r\n", server.address, "a".repeat(16 << 20));
    let sending = std::thread::spawn(move || {
        let _ = writer.write_all(head.as_bytes());
    });
    // Read only once everything is sent (or refused): the answer must still be there.
    sending.join().unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let mut response = Vec::new();
    let read = s.read_to_end(&mut response);
    let response = String::from_utf8_lossy(&response);
    assert!(response.starts_with("HTTP/1.1 431"), "{read:?}: {response:?}");
}

/// Issue 15 (found writing the request-head fuzz target): the 8 KiB bound holds however a
/// head arrives. Read 1 KiB at a time, a head of 8193 to 9215 bytes was taken when the reads
/// did not end at 8 KiB exactly (here 100 bytes, then the rest); a head of 8 KiB is served.
#[test]
fn a_head_over_8_kib_is_refused_however_it_arrives() {
    let server = start("head-bound", &[]);
    let a = &server.address;
    for (len, status) in [(8192, "200"), (8193, "431"), (8250, "431")] {
        let start = format!("GET / HTTP/1.1\r\nHost: {a}\r\nX-Pad: ");
        let head = format!("{start}{}\r\n\r\n", "a".repeat(len - start.len() - 4));
        let mut s = TcpStream::connect(a).unwrap();
        s.write_all(&head.as_bytes()[..100]).unwrap();
        std::thread::sleep(Duration::from_millis(300));
        s.write_all(&head.as_bytes()[100..]).unwrap();
        let mut response = String::new();
        let _ = s.read_to_string(&mut response);
        assert!(response.starts_with(&format!("HTTP/1.1 {status}")), "{len} bytes: {response:?}");
    }
}

/// Issue 15: a viewer that neither reads nor acknowledges is pinged, then closed with an
/// error after 15 s of silence, instead of holding one of the server's places for ever.
#[test]
fn a_viewer_that_never_acknowledges_is_closed() {
    let server = start("silent", &[]);
    let mut silent = connect(&server);
    std::thread::sleep(Duration::from_secs(17));
    let (mut pinged, mut error, mut closed) = (false, None, false);
    while !closed {
        match silent.read() {
            Ok(Message::Ping(_)) => pinged = true,
            Ok(Message::Text(t)) => {
                let v: Value = serde_json::from_str(&t).unwrap();
                if v["type"] == "error" {
                    error = Some(v["message"].as_str().unwrap().to_owned());
                }
            }
            Ok(Message::Close(_)) | Err(_) => closed = true,
            Ok(_) => {}
        }
    }
    assert!(pinged, "pinged before it was closed");
    assert!(error.as_deref().is_some_and(|m| m.contains("no acknowledgement for 15 s")), "{error:?}");
    assert_eq!(get(&server.address, "/").0, 200, "still serving");
}

/// A viewer that acknowledges late (every 3 s, its window full in between) is not closed: it
/// is heard from well within the 15 s.
#[test]
fn a_viewer_that_acknowledges_slowly_stays() {
    let server = start("slow-ack", &[]);
    let mut slow = connect(&server);
    for _ in 0..6 {
        std::thread::sleep(Duration::from_secs(3));
        next_frame(&mut slow);
    }
    // Still streaming after 18 s: frames keep coming once acknowledged, and no error came.
    for _ in 0..3 {
        next_frame(&mut slow);
    }
}

/// The page's Record button: `record` on the stream starts a new file in `--recordings` (or
/// joins the one being written), every viewer is told, every record `/input` takes is written
/// whole as it is taken, and stopping says how many; the file reads back as a recording, and
/// `--record` goes on beside it. The input messages say which side is tracked and whether our
/// hand shows it mirrored.
#[test]
fn record_writes_the_live_input_to_a_new_file_and_input_messages_name_the_side() {
    let dir = site("record");
    let config = dir.join("config.json");
    std::fs::write(&config, r#"{"grace_s": 5.0, "max_latency_s": 5.0}"#).unwrap();
    let recordings = dir.join("recordings");
    let fixed = dir.join("fixed.jsonl");
    let server = start("record-server", &["--config", config.to_str().unwrap(), "--recordings", recordings.to_str().unwrap(), "--record", fixed.to_str().unwrap()]);
    let (lines, _) = recording("record-rec");
    let mut viewer = connect(&server);
    text(&mut viewer);
    viewer.send(Message::text(r#"{"type":"record","on":false}"#)).unwrap();
    assert_eq!(next_text(&mut viewer), serde_json::json!({"type": "recording", "on": false, "path": null, "records": 0, "failed": false}), "a stop with no recording");
    viewer.send(Message::text(r#"{"type":"record","on":true}"#)).unwrap();
    let started = next_text(&mut viewer);
    assert_eq!((&started["type"], &started["on"], &started["records"]), (&"recording".into(), &true.into(), &0.into()), "{started}");
    // Another viewer is told at once, and its Record joins the same file.
    let mut other = connect(&server);
    text(&mut other);
    assert_eq!(next_text(&mut other), started, "a viewer arriving is told of the recording");
    other.send(Message::text(r#"{"type":"record","on":true}"#)).unwrap();
    assert_eq!(next_text(&mut other)["path"], started["path"], "no second file");
    assert_eq!(next_text(&mut viewer)["path"], started["path"], "every viewer is told");
    drop(other);
    let path = PathBuf::from(started["path"].as_str().unwrap());
    assert_eq!(path.parent(), Some(recordings.as_path()), "{started}");
    assert!(path.file_name().unwrap().to_str().unwrap().starts_with("live-"));
    // 200 right-hand records, then 50 of the same hand labelled left, one refused between.
    let (mut input, _) = tungstenite::connect(format!("ws://{}/input", server.address)).unwrap();
    let sent: Vec<String> = lines[..250].iter().enumerate().map(|(i, l)| if i < 200 { l.clone() } else { l.replacen("\"hand\":\"right\"", "\"hand\":\"left\"", 1) }).collect();
    assert!(sent[249].contains("\"left\""), "the synthetic records name their hand: {}", sent[249]);
    // The side and mirroring the viewer is told once the records up to `taken` are in.
    let mut told = |taken: u64| {
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let m = next_text(&mut viewer);
            assert!(Instant::now() < deadline, "{taken} records were never all taken");
            if m["type"] == "input" && m["accepted"] == taken {
                return (m["side"].as_str().unwrap_or("none").to_owned(), m["mirrored"] == true);
            }
        }
    };
    for (i, line) in sent.iter().enumerate() {
        input.send(Message::text(line.as_str())).unwrap();
        if i == 100 {
            input.send(Message::text(r#"{"t": 0.0, "landmarks": []}"#)).unwrap();
            assert!(matches!(input.read().unwrap(), Message::Text(t) if t.contains("error")));
        }
        if i == 199 {
            assert_eq!(told(200), ("right".to_owned(), false), "our right hand shows a right hand as it is");
        }
    }
    assert_eq!(told(250), ("left".to_owned(), true), "and a left one mirrored");
    viewer.send(Message::text(r#"{"type":"record","on":false}"#)).unwrap();
    let stopped = loop {
        let m = next_text(&mut viewer);
        if m["type"] == "recording" {
            break m;
        }
    };
    assert_eq!(stopped, serde_json::json!({"type": "recording", "on": false, "path": path.display().to_string(), "records": 250, "failed": false}));
    let written: Vec<Value> = std::fs::read_to_string(&path).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(written.len(), 250, "every record taken, none refused");
    assert_eq!(written[0]["t"], serde_json::from_str::<Value>(&sent[0]).unwrap()["t"]);
    assert_eq!((written[199]["hand"].as_str(), written[249]["hand"].as_str()), (Some("right"), Some("left")));
    let replay = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["replay", "--input"]).arg(&path).output().unwrap();
    assert!(replay.status.success() && String::from_utf8_lossy(&replay.stderr).contains("250 records, 250 taken"), "{}", String::from_utf8_lossy(&replay.stderr));
    // A new recording is a new file; the one before is kept.
    viewer.send(Message::text(r#"{"type":"record","on":true}"#)).unwrap();
    let again = loop {
        let m = next_text(&mut viewer);
        if m["type"] == "recording" {
            break m;
        }
    };
    assert_ne!(again["path"], started["path"]);
    assert_eq!(std::fs::read_to_string(&path).unwrap().lines().count(), 250);
    assert_eq!(std::fs::read_to_string(&fixed).unwrap().lines().count(), 250, "--record kept every record, whatever the viewers did");
}

/// `dqhand loadtest` (short): every viewer is streamed to; every relay page gets every record
/// the input took of those sent to `/input` (it answers each one it refuses); a malformed flood is answered
/// with one error per bad command and the page is served after it; 200 dripping heads are
/// all held open, the page and a new viewer are served meanwhile, and every dripping socket is
/// answered 408 and closed by the server; a viewer that never reads is closed by the server
/// between its limits (5 s for a blocked send, 15 s without a sign of life); and the viewer
/// streaming beside each abuse keeps getting frames. No time or rate is asserted beyond those
/// limits, a frame rate floor far below the target (120) and a longest wait for a frame far
/// above a frame's period, which only a stalled stream misses.
#[test]
fn loadtest_serves_every_viewer_and_survives_the_abuse() {
    /// Frames per second a viewer beside an abuse gets at least (the target is 120)...
    const FPS_FLOOR: f64 = 5.0;
    /// ...and the longest it waits for a frame at most, seconds (a stream that stops).
    const LONGEST_WAIT_S: f64 = 3.0;
    let out = Command::new(env!("CARGO_BIN_EXE_dqhand")).args(["loadtest", "--seconds", "1", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    // Every check, then every failure at once: one run says all that went wrong.
    let mut failed = Vec::new();
    let mut check = |ok: bool, what: &str| {
        if !ok {
            failed.push(what.to_owned());
        }
    };
    for row in r["viewers"].as_array().unwrap() {
        check(row["fps_min"].as_f64().unwrap() > 0.0, "every viewer streamed to");
    }
    let statuses: Vec<_> = r["viewers"].as_array().unwrap().iter().map(|row| row["page_status"].as_u64().unwrap()).collect();
    check(statuses == [200, 200, 503], "the page served while 1 and 10 viewers stream, 503 while 64 (every place) do");
    let m = &r["malformed_flood"];
    let sent = m["sent"].as_u64().unwrap();
    check(sent > 0 && m["errors_answered"].as_u64() == Some(sent), "one error answered per bad command of the flood");
    check(m["page_status_after"] == 200, "the page served after the flood");
    check(m["watcher_fps"].as_f64().unwrap() >= FPS_FLOOR && m["watcher_longest_gap_s"].as_f64().unwrap() <= LONGEST_WAIT_S, "a viewer beside the flood keeps getting frames");
    let s = &r["slowloris"];
    check(s["sockets_opened"] == 200 && s["sockets_held"] == 200, "200 dripping heads opened and held open, unanswered, when the page is asked for");
    check(s["page_status"] == 200 && s["page_ms"].is_number(), "the page served while heads drip");
    check(s["new_viewer_first_frame_ms"].is_number(), "a new viewer gets frames while heads drip");
    check(s["answered_408"] == 200 && s["closed_by_server"] == 200, "every dripping head answered 408 (its time is up) and closed by the server");
    check(s["streaming_fps"].as_f64().unwrap() >= FPS_FLOOR && s["streaming_longest_gap_s"].as_f64().unwrap() <= LONGEST_WAIT_S, "a streaming viewer keeps getting frames while heads drip");
    for row in r["relay"].as_array().unwrap() {
        // A record the input refused (late, on a machine that held its thread) is answered to
        // the sender and not relayed; every record it took is owed to every page.
        let (sent, taken) = (row["sent"].as_u64().unwrap(), row["taken"].as_u64().unwrap());
        check(taken > 0 && taken + row["refused"].as_u64().unwrap() == sent, "the input took records sent to /input, and answered each one it refused");
        check(row["received_min"] == row["taken"], "every relay page received every record the input took");
    }
    let w = &r["slow_reader"];
    check(w["closed"] == true, "the viewer that never reads closed by the server");
    check(w["closed_after_s"].as_f64().is_some_and(|t| (4.5..=20.0).contains(&t)), "the viewer that never reads closed between 5 s (a blocked send) and 20 s (15 s without a sign of life, and a margin)");
    check(w["watcher_fps"].as_f64().unwrap() >= FPS_FLOOR && w["watcher_longest_gap_s"].as_f64().unwrap() <= LONGEST_WAIT_S, "a viewer beside the one that never reads keeps getting frames");
    assert!(failed.is_empty(), "failed: {failed:#?}\nthe load test's report: {r:#}");
}

/// A GET's status and body as bytes (a hand's GLB is not text).
fn get_bytes(address: &str, path: &str) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect(address).unwrap();
    s.write_all(format!("GET {path} HTTP/1.1\r\nHost: {address}\r\n\r\n").as_bytes()).unwrap();
    let mut response = Vec::new();
    let _ = s.read_to_end(&mut response);
    let end = response.windows(4).position(|w| w == b"\r\n\r\n").unwrap() + 4;
    let status = String::from_utf8_lossy(&response[..end]).split(' ').nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
    (status, response[end..].to_vec())
}

/// The relay's next text message (records on the way are left out).
fn relay_text(ws: &mut Client) -> Value {
    loop {
        if let Message::Text(t) = ws.read().unwrap() {
            return serde_json::from_str(&t).unwrap();
        }
    }
}

/// The relay: `engine.json` gives a page the demo's engine (its settings, with the glove and
/// joint model given on the command line, and its hand as a file); a page on `/relay` is told
/// the gestures, then gets every record the input takes, as it was
/// sent (a refused one is not relayed); its `record` writes the live input to disk, and
/// anything else it sends is refused with the reason. A scene file gives no relay (its meshes
/// are this machine's files), and says why.
#[test]
fn the_relay_gives_a_page_the_engine_and_every_record_taken() {
    let dir = site("relay");
    let config = dir.join("config.json");
    std::fs::write(&config, r#"{"grace_s": 5.0, "max_latency_s": 5.0}"#).unwrap();
    let recordings = dir.join("recordings");
    let server = start("relay-server", &["--config", config.to_str().unwrap(), "--recordings", recordings.to_str().unwrap(), "--glove", "5dt-5", "--joint-model", "paper"]);
    let (status, body) = get(&server.address, "/engine.json");
    assert_eq!(status, 200);
    let engine: Value = serde_json::from_str(&body).unwrap();
    assert_eq!((&engine["relay"], &engine["why"], &engine["hands"]), (&"/relay".into(), &Value::Null, &serde_json::json!(["/engine/hands/right.glb"])), "{engine}");
    let settings = dqhand_stream::EngineSettings::from_json(&engine["settings"].to_string()).unwrap();
    assert_eq!((settings.hands, settings.scene.as_deref(), settings.glove.as_str(), settings.joint_model.as_str()), (1, None, "5dt-5", "paper"));
    assert_eq!((settings.config.grace_s, settings.config.max_latency_s), (5.0, 5.0), "the configuration given");
    assert_eq!((settings.source.as_str(), settings.announce), ("WebSocket /input", false), "told of the input with its first record");
    assert_eq!(settings.sensors().unwrap().len(), 5, "the 5DT 5-sensor glove's");
    assert!(settings.gesture_set().unwrap().gestures().len() >= 12);
    let (status, glb) = get_bytes(&server.address, "/engine/hands/right.glb");
    assert_eq!(status, 200);
    let hand = dqhand::io::load_gltf_slice(&glb, std::path::Path::new("right.glb")).unwrap();
    let builtin = dqhand::hand::build(&Default::default()).unwrap();
    assert_eq!((hand.mesh.positions().len(), hand.skeleton.joints().len()), (builtin.mesh.positions().len(), builtin.skeleton.joints().len()), "the server's hand");
    assert_eq!(get(&server.address, "/engine/hands/left.glb").0, 404, "one hand here");

    let (mut page, _) = tungstenite::connect(format!("ws://{}/relay", server.address)).unwrap();
    if let MaybeTlsStream::Plain(s) = page.get_mut() {
        s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    }
    let gestures = relay_text(&mut page);
    assert_eq!(gestures["type"], "gestures");
    assert_eq!(gestures["gestures"], settings.gestures, "the gestures of engine.json");
    page.send(Message::text(r#"{"type":"heatmap","on":true}"#)).unwrap();
    let refused = relay_text(&mut page);
    assert!(refused["message"].as_str().unwrap().starts_with("relay: only record and learn"), "{refused}");
    page.send(Message::text("{")).unwrap();
    assert!(relay_text(&mut page)["message"].as_str().unwrap().starts_with("not a valid command"));

    let (lines, _) = recording("relay-rec");
    let (mut input, _) = tungstenite::connect(format!("ws://{}/input", server.address)).unwrap();
    page.send(Message::text(r#"{"type":"record","on":true}"#)).unwrap();
    let started = relay_text(&mut page);
    assert_eq!((&started["type"], &started["on"]), (&"recording".into(), &true.into()), "{started}");
    for (i, line) in lines[..100].iter().enumerate() {
        input.send(Message::text(line.as_str())).unwrap();
        if i == 50 {
            input.send(Message::text(r#"{"t": 0.0, "landmarks": []}"#)).unwrap();
            assert!(matches!(input.read().unwrap(), Message::Text(t) if t.contains("error")));
        }
    }
    let mut relayed = Vec::new();
    while relayed.len() < 100 {
        match page.read().unwrap() {
            Message::Binary(b) => relayed.push(serde_json::from_slice::<Value>(&b).unwrap()),
            Message::Text(t) => panic!("only records now: {t}"),
            _ => {}
        }
    }
    for (sent, got) in lines[..100].iter().zip(&relayed) {
        let sent: Value = serde_json::from_str(sent).unwrap();
        assert_eq!((&got["t"], &got["hand"]), (&sent["t"], &sent["hand"]));
        let joints = sent["joints"].as_object().unwrap();
        assert_eq!(got["joints"].as_object().unwrap().len(), joints.len(), "every joint");
        for (name, joint) in joints {
            for key in ["p", "q"] {
                let numbers = |v: &Value| v.as_array().map(|a| a.iter().map(|x| x.as_f64().unwrap()).collect::<Vec<_>>()).unwrap_or_default();
                let (a, b) = (numbers(&joint[key]), numbers(&got["joints"][name][key]));
                assert!(a.len() == b.len() && a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-6), "{name} {key}: sent {a:?}, relayed {b:?}");
            }
        }
    }
    page.send(Message::text(r#"{"type":"record","on":false}"#)).unwrap();
    let stopped = relay_text(&mut page);
    assert_eq!((&stopped["on"], &stopped["records"]), (&false.into(), &100.into()), "{stopped}");
    let path = PathBuf::from(stopped["path"].as_str().unwrap());
    assert_eq!(std::fs::read_to_string(&path).unwrap().lines().count(), 100);

    // A scene played from a recording starts over with each pass: the relay says so, in its
    // place among the records (the page's engine puts the objects back then).
    let short = dir.join("short.jsonl");
    std::fs::write(&short, lines[..30].join("\n") + "\n").unwrap();
    let server = start("relay-scene", &["--scene", "grasp", "--input", short.to_str().unwrap()]);
    let (mut page, _) = tungstenite::connect(format!("ws://{}/relay", server.address)).unwrap();
    if let MaybeTlsStream::Plain(s) = page.get_mut() {
        s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    }
    let (mut records, mut resets) = (0, 0);
    while resets < 2 {
        match page.read().unwrap() {
            Message::Binary(_) => records += 1,
            Message::Text(t) if t.contains("reset_scene") => {
                assert!(resets == 0 || records >= 30, "a whole pass of 30 records between two resets ({records})");
                (resets, records) = (resets + 1, 0);
            }
            _ => {}
        }
    }

    let scene = dir.join("scene.json");
    std::fs::write(&scene, r#"{"objects": [{"name": "ball", "shape": "sphere", "radius": 0.04, "position": [0, 0.05, 0], "mass": 0.15}]}"#).unwrap();
    let server = start("relay-scene-file", &["--scene", scene.to_str().unwrap()]);
    let engine: Value = serde_json::from_str(&get(&server.address, "/engine.json").1).unwrap();
    assert!(engine["relay"].is_null() && engine["why"].as_str().unwrap().contains("scene file"), "{engine}");
}
