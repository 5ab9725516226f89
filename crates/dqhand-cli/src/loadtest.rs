//! `dqhand loadtest`: the viewer server under load and abuse, measured. It starts a real
//! `dqhand demo` (this binary, a page of one file, the built-in hand) on a loopback port and
//! runs, one after the other:
//!
//! * **viewers** — 1, 10 and 64 clients streaming at once: frames per second per client, the
//!   server's CPU (of one core) and memory;
//! * **malformed flood** — one client sending bad commands as fast as it can, another watching:
//!   errors answered, the watcher's frame rate, the page served after;
//! * **slowloris** — 200 sockets dripping a request head: the page's and a new viewer's time
//!   to be served meanwhile, a streaming viewer's frame rate;
//! * **slow reader** — a viewer that never reads: whether the server has closed it after
//!   20 s (its limits: 5 s for a blocked send, 15 s without a sign of life), and another
//!   viewer's frame rate meanwhile.
//!
//! The numbers are the report; `make test` runs a short version whose test asserts only what
//! was served, refused and closed, never a time.

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::Context;
use serde_json::{json, Value};
use tungstenite::{Message, WebSocket};

/// Arguments of `dqhand loadtest`.
#[derive(clap::Args)]
pub struct Args {
    /// Seconds each measurement lasts.
    #[arg(long, default_value_t = 5.0)]
    seconds: f64,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// Viewer counts streamed at once (64: every place the server has).
const VIEWER_COUNTS: [usize; 3] = [1, 10, 64];
/// Sockets dripping a request head during the slowloris stage.
const DRIPPERS: usize = 200;
/// How long a viewer that does not read is left alone before it checks that the server has
/// closed it (the server's limits: a send blocked for 5 s, or 15 s without a sign of life).
const SLOW_READER_WAIT: Duration = Duration::from_secs(20);

pub fn run(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.seconds > 0.0 && args.seconds <= 600.0, "--seconds takes 0 to 600");
    let period = Duration::from_secs_f64(args.seconds);
    let server = Server::start()?;
    let a = server.address;
    let mut report = serde_json::Map::new();

    let mut rows = Vec::new();
    for n in VIEWER_COUNTS {
        let viewers: Vec<Viewer> = (0..n).map(|_| Viewer::start(a)).collect::<anyhow::Result<_>>()?;
        std::thread::sleep(Duration::from_millis(500));
        let cpu = server.cpu_ns();
        let fps = measure(&viewers, period);
        let cpu_share = (server.cpu_ns() - cpu) as f64 / period.as_nanos() as f64;
        let page = get(a, "/")?;
        rows.push(json!({ "viewers": n, "fps_median": quantile(&fps, 0.5), "fps_min": quantile(&fps, 0.0), "server_cpu": cpu_share, "server_rss_mib": server.rss_mib(), "page_status": page }));
        stop(viewers);
    }
    report.insert("viewers".into(), rows.into());

    // Malformed flood: bad commands as fast as they go, a watcher streaming beside them.
    let watcher = Viewer::start(a)?;
    let (mut flood, _) = tungstenite::connect(format!("ws://{a}/stream")).context("the flood's connection")?;
    let answered = AtomicU64::new(0);
    let end = Instant::now() + period;
    let watched = watcher.frames.load(Ordering::Relaxed);
    let mut bad = 0u64;
    while Instant::now() < end {
        // A burst, then what has come back (errors, and frames to acknowledge).
        for _ in 0..100 {
            let message = ["{\"type\":\"angle\",\"dof\":\"no-such\",\"deg\":1}", "not json", "{\"type\":\"play\",\"x\":1}", "{}"][(bad % 4) as usize];
            flood.send(Message::text(message)).context("the flood's connection")?;
            bad += 1;
        }
        drain(&mut flood, &answered)?;
    }
    let watcher_fps = (watcher.frames.load(Ordering::Relaxed) - watched) as f64 / period.as_secs_f64();
    let page = get(a, "/")?;
    report.insert(
        "malformed_flood".into(),
        json!({ "sent": bad, "errors_answered": answered.load(Ordering::Relaxed), "watcher_fps": watcher_fps, "page_status_after": page }),
    );
    drop(flood);
    stop(vec![watcher]);

    // Slowloris: heads dripped a byte at a time while a viewer streams and others come.
    let streaming = Viewer::start(a)?;
    let stop_drip = Arc::new(AtomicBool::new(false));
    let drippers = drip(a, DRIPPERS, &stop_drip)?;
    std::thread::sleep(Duration::from_millis(500));
    let t = Instant::now();
    let page = get(a, "/")?;
    let page_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let newcomer = Viewer::start(a)?;
    let first_frame = newcomer.first_frame(Duration::from_secs(10));
    let viewer_ms = first_frame.then(|| t.elapsed().as_secs_f64() * 1e3);
    let fps = measure(std::slice::from_ref(&streaming), period);
    stop_drip.store(true, Ordering::Relaxed);
    let dripping = drippers.join().unwrap_or(0);
    report.insert(
        "slowloris".into(),
        json!({ "sockets": dripping, "page_status": page, "page_ms": page_ms, "new_viewer_first_frame_ms": viewer_ms, "streaming_fps": fps[0] }),
    );
    stop(vec![streaming, newcomer]);

    // A slow reader: upgraded, then never reads; the server must close it.
    let watcher = Viewer::start(a)?;
    let mut slow = TcpStream::connect(a)?;
    slow.write_all(upgrade_request(a).as_bytes())?;
    let fps = measure(std::slice::from_ref(&watcher), SLOW_READER_WAIT);
    let closed = closed_by_peer(&mut slow);
    report.insert("slow_reader".into(), json!({ "closed_within_s": closed.then_some(SLOW_READER_WAIT.as_secs()), "closed": closed, "watcher_fps": fps[0] }));
    stop(vec![watcher]);
    report.insert("server".into(), json!({ "rss_mib": server.rss_mib(), "fps_target": 120 }));

    let report = Value::Object(report);
    if args.json {
        println!("{report}");
    } else {
        print_table(&report, args.seconds);
    }
    Ok(())
}

fn print_table(r: &Value, seconds: f64) {
    let f = |v: &Value| v.as_f64().map_or("—".to_owned(), |x| format!("{x:.1}"));
    println!("dqhand demo on a loopback port, the built-in hand, {seconds} s per measurement");
    println!("{:>8} {:>16} {:>16} {:>14} {:>14} {:>6}", "viewers", "fps per client", "slowest client", "server CPU %", "server MiB", "page");
    for row in r["viewers"].as_array().into_iter().flatten() {
        let cpu = row["server_cpu"].as_f64().map_or("—".to_owned(), |c| format!("{:.0}", 100.0 * c));
        println!("{:>8} {:>16} {:>16} {cpu:>14} {:>14} {:>6}", row["viewers"], f(&row["fps_median"]), f(&row["fps_min"]), f(&row["server_rss_mib"]), row["page_status"]);
    }
    let m = &r["malformed_flood"];
    println!("malformed flood: {} bad commands sent, {} errors answered; a viewer beside it {} fps; the page after: {}", m["sent"], m["errors_answered"], f(&m["watcher_fps"]), m["page_status_after"]);
    let s = &r["slowloris"];
    println!(
        "slowloris, {} sockets dripping: the page {} in {} ms, a new viewer's first frame in {} ms, a streaming viewer {} fps",
        s["sockets"],
        s["page_status"],
        f(&s["page_ms"]),
        f(&s["new_viewer_first_frame_ms"]),
        f(&s["streaming_fps"])
    );
    let w = &r["slow_reader"];
    println!("slow reader (never reads): closed by the server within {} s: {}; a viewer beside it {} fps", SLOW_READER_WAIT.as_secs(), w["closed"], f(&w["watcher_fps"]));
}

/// The server under test: this binary's `demo`, a page of one file, a port of its own.
struct Server {
    child: Child,
    address: SocketAddr,
    site: PathBuf,
}

impl Server {
    fn start() -> anyhow::Result<Self> {
        let site = std::env::temp_dir().join(format!("dqhand-loadtest-{}", std::process::id()));
        std::fs::create_dir_all(&site)?;
        std::fs::write(site.join("index.html"), "<!doctype html><title>dqhand load test</title>")?;
        let mut child = Command::new(std::env::current_exe()?)
            .args(["demo", "--no-open", "--port", "0", "--viewer"])
            .arg(&site)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .context("cannot start dqhand demo")?;
        let mut out = child.stdout.take().expect("piped");
        let mut text = String::new();
        let mut buf = [0u8; 256];
        let address = loop {
            let n = out.read(&mut buf)?;
            anyhow::ensure!(n > 0, "dqhand demo printed no URL: {text}");
            text.push_str(&String::from_utf8_lossy(&buf[..n]));
            if let Some(url) = text.lines().find_map(|l| l.strip_prefix("viewer: http://")) {
                if text.contains("press Ctrl-C") {
                    break url.trim_end_matches('/').parse()?;
                }
            }
        };
        std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
        Ok(Self { child, address, site })
    }

    /// CPU time the server's threads alive now have used (ns), where the system says (Linux).
    fn cpu_ns(&self) -> u64 {
        let Ok(tasks) = std::fs::read_dir(format!("/proc/{}/task", self.child.id())) else { return 0 };
        tasks
            .flatten()
            .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
            .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
            .sum()
    }

    /// The server's resident memory (MiB), where the system says (Linux).
    fn rss_mib(&self) -> Option<f64> {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).ok()?;
        let kib: f64 = status.lines().find_map(|l| l.strip_prefix("VmRSS:"))?.trim().trim_end_matches("kB").trim().parse().ok()?;
        Some(kib / 1024.0)
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.site);
    }
}

/// A streaming viewer on its own thread: reads frames and acknowledges each, as the page does.
struct Viewer {
    frames: Arc<AtomicU64>,
    stop: Arc<AtomicBool>,
    thread: JoinHandle<()>,
}

impl Viewer {
    fn start(a: SocketAddr) -> anyhow::Result<Self> {
        let (mut ws, _) = tungstenite::connect(format!("ws://{a}/stream")).with_context(|| format!("a viewer of {a}"))?;
        if let tungstenite::stream::MaybeTlsStream::Plain(s) = ws.get_ref() {
            s.set_read_timeout(Some(Duration::from_millis(200)))?;
        }
        let (frames, stop) = (Arc::new(AtomicU64::new(0)), Arc::new(AtomicBool::new(false)));
        let (f, s) = (Arc::clone(&frames), Arc::clone(&stop));
        let thread = std::thread::spawn(move || {
            while !s.load(Ordering::Relaxed) {
                match ws.read() {
                    Ok(Message::Binary(b)) if b.starts_with(b"DQHF") => {
                        let seq = u32::from_le_bytes([b[8], b[9], b[10], b[11]]);
                        f.fetch_add(1, Ordering::Relaxed);
                        if ws.send(Message::text(format!("{{\"type\":\"ack\",\"seq\":{seq}}}"))).is_err() {
                            return;
                        }
                    }
                    Ok(_) => {}
                    Err(tungstenite::Error::Io(e)) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                    Err(_) => return,
                }
            }
            let _ = ws.close(None);
        });
        Ok(Self { frames, stop, thread })
    }

    /// Whether a frame came within `limit`.
    fn first_frame(&self, limit: Duration) -> bool {
        let end = Instant::now() + limit;
        while self.frames.load(Ordering::Relaxed) == 0 && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(5));
        }
        self.frames.load(Ordering::Relaxed) > 0
    }
}

fn stop(viewers: Vec<Viewer>) {
    for v in &viewers {
        v.stop.store(true, Ordering::Relaxed);
    }
    for v in viewers {
        let _ = v.thread.join();
    }
}

/// Frames per second each viewer received over `period`.
fn measure(viewers: &[Viewer], period: Duration) -> Vec<f64> {
    let before: Vec<u64> = viewers.iter().map(|v| v.frames.load(Ordering::Relaxed)).collect();
    std::thread::sleep(period);
    let seconds = period.as_secs_f64().max(1e-9);
    viewers.iter().zip(before).map(|(v, b)| (v.frames.load(Ordering::Relaxed) - b) as f64 / seconds).collect()
}

fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v = values.to_vec();
    dqhand::math::quantile(&mut v, q).unwrap_or(0.0)
}

/// Reads what the flood's connection has received so far: counts error answers, acknowledges
/// frames (so the server keeps streaming to it), and waits at most a moment.
fn drain(ws: &mut WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>>, answered: &AtomicU64) -> anyhow::Result<()> {
    if let tungstenite::stream::MaybeTlsStream::Plain(s) = ws.get_ref() {
        s.set_read_timeout(Some(Duration::from_micros(200)))?;
    }
    loop {
        match ws.read() {
            Ok(Message::Text(t)) if t.contains("\"error\"") => {
                answered.fetch_add(1, Ordering::Relaxed);
            }
            Ok(Message::Binary(b)) if b.starts_with(b"DQHF") => {
                let seq = u32::from_le_bytes([b[8], b[9], b[10], b[11]]);
                ws.send(Message::text(format!("{{\"type\":\"ack\",\"seq\":{seq}}}")))?;
            }
            Ok(_) => {}
            Err(tungstenite::Error::Io(e)) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => return Ok(()),
            Err(e) => return Err(e.into()),
        }
    }
}

/// `n` sockets, each dripping a request head a byte every 100 ms from its own place in one
/// thread, until `stop`; returns how many were connected.
fn drip(a: SocketAddr, n: usize, stop: &Arc<AtomicBool>) -> anyhow::Result<JoinHandle<usize>> {
    let mut sockets: Vec<TcpStream> = (0..n).map(|_| TcpStream::connect(a)).collect::<std::io::Result<_>>()?;
    let stop = Arc::clone(stop);
    let head = format!("GET / HTTP/1.1\r\nHost: {a}\r\nX-Padding: {}\r\n\r\n", "z".repeat(200));
    Ok(std::thread::spawn(move || {
        let connected = sockets.len();
        let mut at = 0;
        while !stop.load(Ordering::Relaxed) {
            for s in &mut sockets {
                let _ = s.write_all(&head.as_bytes()[at % head.len()..][..1]);
            }
            at += 1;
            std::thread::sleep(Duration::from_millis(100));
        }
        connected
    }))
}

fn upgrade_request(a: SocketAddr) -> String {
    format!("GET /stream HTTP/1.1\r\nHost: {a}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n")
}

/// Whether the other end has closed the connection: reads what is left, expecting its end.
fn closed_by_peer(stream: &mut TcpStream) -> bool {
    let _ = stream.set_read_timeout(Some(Duration::from_secs(2)));
    let mut buf = vec![0u8; 1 << 20];
    loop {
        match stream.read(&mut buf) {
            Ok(0) => return true,
            Ok(_) => {}
            Err(e) => return !matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut),
        }
    }
}

/// A plain GET: the response's status.
fn get(a: SocketAddr, path: &str) -> anyhow::Result<u16> {
    let mut s = TcpStream::connect(a)?;
    s.set_read_timeout(Some(Duration::from_secs(10)))?;
    s.write_all(format!("GET {path} HTTP/1.1\r\nHost: {a}\r\nConnection: close\r\n\r\n").as_bytes())?;
    let mut response = Vec::new();
    let _ = s.read_to_end(&mut response);
    Ok(String::from_utf8_lossy(&response).split_whitespace().nth(1).and_then(|c| c.parse().ok()).unwrap_or(0))
}
