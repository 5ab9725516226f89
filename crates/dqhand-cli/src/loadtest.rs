//! `dqhand loadtest`: the viewer server under load and abuse, measured. It starts a real
//! `dqhand demo` (this binary, a page of one file, the built-in hand) on a loopback port and
//! runs, one after the other:
//!
//! * **viewers** — 1, 10 and 64 clients streaming at once: frames per second per client, the
//!   server's CPU (of one core) and memory;
//! * **malformed flood** — one client sending bad commands as fast as it can, another watching:
//!   errors answered (all of them are waited for, up to a deadline), the watcher's frame rate,
//!   the page served after;
//! * **slowloris** — 200 sockets dripping a request head a byte every 100 ms until the server
//!   closes them: how many were open and unanswered when the page was asked for, the page's
//!   and a new viewer's time to be served meanwhile, what each dripping socket was answered
//!   and how long after it opened the server closed it, a streaming viewer's frame rate;
//! * **relay** — 1, 10 and 60 pages following the live input on `/relay` while a sender gives
//!   `/input` 120 records a second: the records the input refused (answered to the sender, not
//!   relayed), the share of those it took that each page received, and the time
//!   from a record's send to its arrival at a page (median, 99th percentile), the server's CPU;
//! * **slow reader** — a viewer that never reads: when the server closes it (its end of the
//!   connection, watched in the system's socket table, stops being established; the server's
//!   limits: 5 s for a blocked send, 15 s without a sign of life), and another viewer's frame
//!   rate meanwhile.
//!
//! The numbers are the report; `make test` runs a short version whose test asserts what was
//! served, answered, refused and closed, and that every viewer beside an abuse kept getting
//! frames (a floor far below the target rate, not a timing).

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
/// Pages following the relay at once (60: with the sender, within the server's 64 places).
const RELAY_COUNTS: [usize; 3] = [1, 10, 60];
/// Records a second the relay stage sends to `/input` (a headset's hand-tracking rate).
const RELAY_RATE_HZ: f64 = 120.0;
/// Sockets dripping a request head during the slowloris stage.
const DRIPPERS: usize = 200;
/// How long the dripping sockets are given to be answered and closed by the server (its
/// limit: 5 s for a whole request head, then a second's linger).
const DRIP_WAIT: Duration = Duration::from_secs(15);
/// How long a viewer that does not read is watched for the server to close it (the server's
/// limits: a send blocked for 5 s, or 15 s without a sign of life).
const SLOW_READER_WAIT: Duration = Duration::from_secs(30);
/// How long the relay's pages are given to receive the records still on their way once the
/// sender stops.
const DELIVERY_WAIT: Duration = Duration::from_secs(5);
/// How long the flood's client waits for the errors still owed once it stops sending.
const ANSWER_WAIT: Duration = Duration::from_secs(10);

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

    // Relay: pages following the live input, a sender on /input at a headset's rate. Each
    // record's `t` is when it was sent (s since `clock`), so a page's receipt gives its latency.
    let clock = Instant::now();
    let mut rows = Vec::new();
    for n in RELAY_COUNTS {
        let pages: Vec<RelayPage> = (0..n).map(|_| RelayPage::start(a, clock)).collect::<anyhow::Result<_>>()?;
        std::thread::sleep(Duration::from_millis(500));
        let cpu = server.cpu_ns();
        let t = Instant::now();
        let sent = send_records(a, clock, period)?;
        let cpu_share = (server.cpu_ns() - cpu) as f64 / t.elapsed().as_nanos() as f64;
        // The records the input took are what the relay owes each page.
        let taken = sent.records - sent.refused;
        // The last records' way to the pages: until every page has them all, or a record is
        // lost (a machine busy with other work can hold a page's thread for a while).
        let deliver = Instant::now();
        while deliver.elapsed() < DELIVERY_WAIT && pages.iter().any(|p| p.count() < taken) {
            std::thread::sleep(Duration::from_millis(20));
        }
        let (received, latencies) = RelayPage::stop(pages);
        let share = received.iter().map(|&r| r as f64 / taken.max(1) as f64).collect::<Vec<_>>();
        rows.push(json!({
            "pages": n, "sent": sent.records, "refused": sent.refused, "first_refusal": sent.first_refusal, "taken": taken,
            "received_min": received.iter().min(), "received_max": received.iter().max(), "share_min": quantile(&share, 0.0),
            "latency_ms_median": quantile(&latencies, 0.5) * 1e3, "latency_ms_p99": quantile(&latencies, 0.99) * 1e3, "server_cpu": cpu_share,
        }));
    }
    report.insert("relay".into(), rows.into());

    // Malformed flood: bad commands as fast as they go, a watcher streaming beside them; then
    // the errors still owed are waited for.
    let watcher = Viewer::start(a)?;
    let (mut flood, _) = tungstenite::connect(format!("ws://{a}/stream")).context("the flood's connection")?;
    let answered = AtomicU64::new(0);
    let watched = Mark::of(&watcher);
    let end = Instant::now() + period;
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
    let (watcher_fps, watcher_gap) = (watched.fps(&watcher), Mark::longest_gap_s(&watcher));
    let owed = Instant::now() + ANSWER_WAIT;
    while answered.load(Ordering::Relaxed) < bad && Instant::now() < owed {
        drain(&mut flood, &answered)?;
    }
    let page = get(a, "/")?;
    report.insert(
        "malformed_flood".into(),
        json!({ "sent": bad, "errors_answered": answered.load(Ordering::Relaxed), "watcher_fps": watcher_fps, "watcher_longest_gap_s": watcher_gap, "page_status_after": page }),
    );
    drop(flood);
    stop(vec![watcher]);

    // Slowloris: heads dripped a byte at a time while a viewer streams and others come, until
    // the server has answered and closed every dripping socket.
    let streaming = Viewer::start(a)?;
    let streamed = Mark::of(&streaming);
    let drippers = Drippers::start(a, DRIPPERS)?;
    std::thread::sleep(Duration::from_millis(500));
    let held = drippers.held();
    let t = Instant::now();
    let page = get(a, "/")?;
    let page_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let newcomer = Viewer::start(a)?;
    let first_frame = newcomer.first_frame(Duration::from_secs(10));
    let viewer_ms = first_frame.then(|| t.elapsed().as_secs_f64() * 1e3);
    let dripped = drippers.finish(period.max(DRIP_WAIT));
    let (fps, gap) = (streamed.fps(&streaming), Mark::longest_gap_s(&streaming));
    let dripped_closed: Vec<f64> = dripped.iter().filter_map(|d| d.closed_after_s).collect();
    report.insert(
        "slowloris".into(),
        json!({
            "sockets_opened": dripped.len(),
            "sockets_held": held,
            "answered_408": dripped.iter().filter(|d| d.status == Some(408)).count(),
            "closed_by_server": dripped_closed.len(),
            "closed_after_s": { "min": dripped_closed.iter().copied().reduce(f64::min), "max": dripped_closed.iter().copied().reduce(f64::max) },
            "page_status": page,
            "page_ms": page_ms,
            "new_viewer_first_frame_ms": viewer_ms,
            "streaming_fps": fps,
            "streaming_longest_gap_s": gap,
        }),
    );
    stop(vec![streaming, newcomer]);

    // A slow reader: upgraded, then never reads; the server must close it. Its end of the
    // connection is watched in the system's socket table, so the slow reader reads nothing
    // until then; then what is left is read, to its end.
    let watcher = Viewer::start(a)?;
    let watched = Mark::of(&watcher);
    let mut slow = TcpStream::connect(a)?;
    let (client, t) = (slow.local_addr()?, Instant::now());
    slow.write_all(upgrade_request(a).as_bytes())?;
    let closed_after = closed_after(a, client, t, SLOW_READER_WAIT);
    if closed_after.is_none() {
        // Not seen in a socket table (not Linux), or not closed: the limit, then its end read.
        std::thread::sleep(SLOW_READER_WAIT.saturating_sub(t.elapsed()));
    }
    let (fps, gap) = (watched.fps(&watcher), Mark::longest_gap_s(&watcher));
    let closed = closed_by_peer(&mut slow);
    report.insert("slow_reader".into(), json!({ "closed": closed, "closed_after_s": closed_after, "watcher_fps": fps, "watcher_longest_gap_s": gap }));
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
        // (A JSON value's own formatting ignores the width: as text first.)
        println!("{:>8} {:>16} {:>16} {cpu:>14} {:>14} {:>6}", row["viewers"].to_string(), f(&row["fps_median"]), f(&row["fps_min"]), f(&row["server_rss_mib"]), row["page_status"].to_string());
    }
    let ms = |v: &Value| v.as_f64().map_or("—".to_owned(), |x| format!("{:.0} ms", x * 1e3));
    let m = &r["malformed_flood"];
    println!(
        "malformed flood: {} bad commands sent, {} errors answered; a viewer beside it {} fps (longest wait for a frame {}); the page after: {}",
        m["sent"],
        m["errors_answered"],
        f(&m["watcher_fps"]),
        ms(&m["watcher_longest_gap_s"]),
        m["page_status_after"]
    );
    let s = &r["slowloris"];
    println!(
        "slowloris: {} sockets dripping a head, {} of them open and unanswered when the page was asked for; the page {} in {} ms, \
         a new viewer's first frame in {} ms; a streaming viewer {} fps (longest wait for a frame {})",
        s["sockets_opened"],
        s["sockets_held"],
        s["page_status"],
        f(&s["page_ms"]),
        f(&s["new_viewer_first_frame_ms"]),
        f(&s["streaming_fps"]),
        ms(&s["streaming_longest_gap_s"])
    );
    println!(
        "           {} answered 408, {} closed by the server {} to {} s after opening",
        s["answered_408"],
        s["closed_by_server"],
        f(&s["closed_after_s"]["min"]),
        f(&s["closed_after_s"]["max"])
    );
    println!("{:>8} {:>14} {:>14} {:>16} {:>14} {:>14} {:>14}", "relay", "records sent", "refused", "fewest received", "median ms", "p99 ms", "server CPU %");
    for row in r["relay"].as_array().into_iter().flatten() {
        let cpu = row["server_cpu"].as_f64().map_or("—".to_owned(), |c| format!("{:.0}", 100.0 * c));
        println!(
            "{:>8} {:>14} {:>14} {:>16} {:>14} {:>14} {cpu:>14}",
            format!("{} pages", row["pages"]),
            row["sent"].to_string(),
            row["refused"].to_string(),
            row["received_min"].to_string(),
            format!("{:.2}", row["latency_ms_median"].as_f64().unwrap_or(f64::NAN)),
            format!("{:.2}", row["latency_ms_p99"].as_f64().unwrap_or(f64::NAN))
        );
    }
    let w = &r["slow_reader"];
    println!(
        "slow reader (never reads): closed by the server: {}, after {} s; a viewer beside it {} fps (longest wait for a frame {})",
        w["closed"],
        f(&w["closed_after_s"]),
        f(&w["watcher_fps"]),
        ms(&w["watcher_longest_gap_s"])
    );
}

/// A page following the relay: a thread reading the records, each one's latency kept.
struct RelayPage {
    running: Arc<AtomicBool>,
    /// Records received so far.
    received: Arc<AtomicU64>,
    thread: JoinHandle<Vec<f64>>,
}

impl RelayPage {
    /// Connects to `/relay`; a record's latency is its receipt's time since `clock` less its `t`.
    fn start(a: SocketAddr, clock: Instant) -> anyhow::Result<Self> {
        let (mut ws, _) = tungstenite::connect(format!("ws://{a}/relay")).context("a relay page's connection")?;
        if let tungstenite::stream::MaybeTlsStream::Plain(s) = ws.get_mut() {
            s.set_read_timeout(Some(Duration::from_millis(100)))?;
        }
        let running = Arc::new(AtomicBool::new(true));
        let received = Arc::new(AtomicU64::new(0));
        let (run, count) = (Arc::clone(&running), Arc::clone(&received));
        let thread = std::thread::spawn(move || {
            let mut latencies = Vec::new();
            while run.load(Ordering::Relaxed) {
                match ws.read() {
                    Ok(Message::Binary(b)) => {
                        let now = clock.elapsed().as_secs_f64();
                        if let Some(t) = serde_json::from_slice::<Value>(&b).ok().and_then(|v| v["t"].as_f64()) {
                            latencies.push(now - t);
                            count.fetch_add(1, Ordering::Relaxed);
                        }
                    }
                    Ok(_) => {}
                    Err(tungstenite::Error::Io(e)) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                    Err(_) => break,
                }
            }
            latencies
        });
        Ok(Self { running, received, thread })
    }

    /// The records it has received so far.
    fn count(&self) -> u64 {
        self.received.load(Ordering::Relaxed)
    }

    /// Stops the pages: the records each received, and every latency (s).
    fn stop(pages: Vec<Self>) -> (Vec<usize>, Vec<f64>) {
        pages.iter().for_each(|p| p.running.store(false, Ordering::Relaxed));
        let each: Vec<Vec<f64>> = pages.into_iter().map(|p| p.thread.join().unwrap_or_default()).collect();
        (each.iter().map(Vec::len).collect(), each.into_iter().flatten().collect())
    }
}

/// What the relay's sender sent, and what the input refused of it.
struct Sent {
    records: u64,
    /// The server's error answers: one per record its input refused (one that arrived more
    /// than the input's `max_latency_s` late, say, when this machine held the server's input
    /// thread), which it does not relay.
    refused: u64,
    /// The first refusal's message.
    first_refusal: Option<String>,
}

/// Sends `/input` tracker records at [`RELAY_RATE_HZ`] for `period`, each stamped with its send
/// time since `clock`; then closes and reads the server's answers up to its close (a refusal is
/// answered before the close, which comes after every record is taken or refused).
fn send_records(a: SocketAddr, clock: Instant, period: Duration) -> anyhow::Result<Sent> {
    let (mut input, _) = tungstenite::connect(format!("ws://{a}/input")).context("the relay's sender")?;
    let (start, step) = (Instant::now(), Duration::from_secs_f64(1.0 / RELAY_RATE_HZ));
    let mut records = 0u64;
    while start.elapsed() < period {
        let t = clock.elapsed().as_secs_f64();
        let record = json!({ "t": t, "hand": "right", "tracker": { "p": [0.0, 1.2, -0.3], "q": [0.0, 0.0, 0.0, 1.0] } });
        input.send(Message::text(record.to_string())).context("the relay's sender")?;
        records += 1;
        // On schedule, but after a stall (this machine busy) at most twice the rate, as a
        // headset's late records are: back to back, they would be refused as a flood.
        let due = (start + step * u32::try_from(records).unwrap_or(u32::MAX)).max(Instant::now() + step / 2);
        std::thread::sleep(due.saturating_duration_since(Instant::now()));
    }
    if let tungstenite::stream::MaybeTlsStream::Plain(s) = input.get_mut() {
        s.set_read_timeout(Some(ANSWER_WAIT))?;
    }
    input.close(None).context("the relay's sender")?;
    let (mut refused, mut first_refusal) = (0, None);
    loop {
        match input.read() {
            Ok(Message::Text(text)) => {
                let answer: Value = serde_json::from_str(&text).unwrap_or_default();
                if answer["type"] == "error" {
                    refused += 1;
                    first_refusal.get_or_insert_with(|| answer["message"].as_str().unwrap_or_default().to_owned());
                }
            }
            Ok(_) => {}
            // Closed, or no close within the wait: the answers counted are all there are.
            Err(_) => break,
        }
    }
    Ok(Sent { records, refused, first_refusal })
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
    /// When the last frame came (µs since `epoch`), and the longest wait for a frame since
    /// [`Mark::of`] (µs).
    last_frame_us: Arc<AtomicU64>,
    longest_gap_us: Arc<AtomicU64>,
    epoch: Instant,
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
        let (last_frame_us, longest_gap_us, epoch) = (Arc::new(AtomicU64::new(0)), Arc::new(AtomicU64::new(0)), Instant::now());
        let (f, s, last, gap) = (Arc::clone(&frames), Arc::clone(&stop), Arc::clone(&last_frame_us), Arc::clone(&longest_gap_us));
        let thread = std::thread::spawn(move || {
            while !s.load(Ordering::Relaxed) {
                match ws.read() {
                    Ok(Message::Binary(b)) if b.starts_with(b"DQHF") => {
                        let seq = u32::from_le_bytes([b[8], b[9], b[10], b[11]]);
                        f.fetch_add(1, Ordering::Relaxed);
                        let now = epoch.elapsed().as_micros() as u64;
                        gap.fetch_max(now.saturating_sub(last.swap(now, Ordering::Relaxed)), Ordering::Relaxed);
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
        Ok(Self { frames, last_frame_us, longest_gap_us, epoch, stop, thread })
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

/// A viewer's frame count at a moment, to give its frame rate since.
struct Mark {
    frames: u64,
    at: Instant,
}

impl Mark {
    /// Marks now, and starts timing the viewer's longest wait for a frame from here.
    fn of(viewer: &Viewer) -> Self {
        viewer.last_frame_us.store(viewer.epoch.elapsed().as_micros() as u64, Ordering::Relaxed);
        viewer.longest_gap_us.store(0, Ordering::Relaxed);
        Self { frames: viewer.frames.load(Ordering::Relaxed), at: Instant::now() }
    }

    /// The longest the viewer has waited for a frame since the mark (the wait still going on
    /// included), seconds.
    fn longest_gap_s(viewer: &Viewer) -> f64 {
        let waiting = (viewer.epoch.elapsed().as_micros() as u64).saturating_sub(viewer.last_frame_us.load(Ordering::Relaxed));
        viewer.longest_gap_us.load(Ordering::Relaxed).max(waiting) as f64 * 1e-6
    }

    /// Frames per second the viewer has received since the mark.
    fn fps(&self, viewer: &Viewer) -> f64 {
        (viewer.frames.load(Ordering::Relaxed) - self.frames) as f64 / self.at.elapsed().as_secs_f64().max(1e-9)
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

/// Sockets dripping a request head, each a byte every 100 ms from its own place in it, on
/// one thread, and what became of each.
struct Drippers {
    state: Arc<std::sync::Mutex<Vec<Dripped>>>,
    stop: Arc<AtomicBool>,
    thread: JoinHandle<()>,
}

/// What became of one dripping socket.
#[derive(Clone, Default)]
struct Dripped {
    /// The bytes the server answered with.
    answer: Vec<u8>,
    /// The status of the answer, once its first line is in.
    status: Option<u16>,
    /// Seconds from opening to the server's end of the connection (end of stream or reset).
    closed_after_s: Option<f64>,
}

impl Drippers {
    /// Opens `n` sockets to `a` (all of them, or an error) and starts dripping.
    fn start(a: SocketAddr, n: usize) -> anyhow::Result<Self> {
        let opened = Instant::now();
        let mut sockets: Vec<TcpStream> = (0..n).map(|_| TcpStream::connect(a)).collect::<std::io::Result<_>>().context("a dripping socket")?;
        for s in &sockets {
            s.set_nonblocking(true)?;
        }
        let state = Arc::new(std::sync::Mutex::new(vec![Dripped::default(); n]));
        let stop = Arc::new(AtomicBool::new(false));
        let (shared, stopped) = (Arc::clone(&state), Arc::clone(&stop));
        let head = format!("GET / HTTP/1.1\r\nHost: {a}\r\nX-Padding: {}\r\n\r\n", "z".repeat(200));
        let thread = std::thread::spawn(move || {
            let mut at = 0;
            let mut buf = [0u8; 1024];
            while !stopped.load(Ordering::Relaxed) {
                let mut state = shared.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                for (s, d) in sockets.iter_mut().zip(state.iter_mut()).filter(|(_, d)| d.closed_after_s.is_none()) {
                    let ended = loop {
                        match s.read(&mut buf) {
                            Ok(0) => break true,
                            Ok(n) => d.answer.extend_from_slice(&buf[..n]),
                            Err(e) if e.kind() == ErrorKind::WouldBlock => break false,
                            Err(e) if e.kind() == ErrorKind::Interrupted => {}
                            Err(_) => break true,
                        }
                    };
                    if d.status.is_none() && d.answer.contains(&b'\n') {
                        d.status = String::from_utf8_lossy(&d.answer).split_whitespace().nth(1).and_then(|c| c.parse().ok());
                    }
                    // Dripping goes on after an answer, as a client that ignores it would.
                    if ended || s.write_all(&head.as_bytes()[at % head.len()..][..1]).is_err_and(|e| e.kind() != ErrorKind::WouldBlock) {
                        d.closed_after_s = Some(opened.elapsed().as_secs_f64());
                        let _ = s.shutdown(std::net::Shutdown::Both);
                    }
                }
                let open = state.iter().any(|d| d.closed_after_s.is_none());
                drop(state);
                if !open {
                    return;
                }
                at += 1;
                std::thread::sleep(Duration::from_millis(100));
            }
        });
        Ok(Self { state, stop, thread })
    }

    /// How many sockets are open and not answered now.
    fn held(&self) -> usize {
        let state = self.state.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        state.iter().filter(|d| d.closed_after_s.is_none() && d.answer.is_empty()).count()
    }

    /// Waits until the server has closed every socket or `limit` has passed, then stops and
    /// says what became of each.
    fn finish(self, limit: Duration) -> Vec<Dripped> {
        let end = Instant::now() + limit;
        while !self.thread.is_finished() && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(50));
        }
        self.stop.store(true, Ordering::Relaxed);
        let _ = self.thread.join();
        let state = self.state.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        state.clone()
    }
}

/// The state of the server's end of the connection from `client` to the server at `server`
/// in the system's socket table (Linux: `/proc/net/tcp`, `tcp6`; 1 is established): `None`
/// without a table to read, `Some(None)` when the connection is not in it.
fn tcp_state(server: SocketAddr, client: SocketAddr) -> Option<Option<u8>> {
    fn hex(a: SocketAddr) -> String {
        // The kernel prints each 32-bit word of the address as the machine stores it.
        let words: Vec<[u8; 4]> = match a.ip() {
            std::net::IpAddr::V4(ip) => vec![ip.octets()],
            std::net::IpAddr::V6(ip) => ip.octets().chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect(),
        };
        let ip: String = words.into_iter().map(|w| format!("{:08X}", u32::from_ne_bytes(w))).collect();
        format!("{ip}:{:04X}", a.port())
    }
    let table = std::fs::read_to_string(if server.is_ipv4() { "/proc/net/tcp" } else { "/proc/net/tcp6" }).ok()?;
    let (local, remote) = (hex(server), hex(client));
    Some(table.lines().skip(1).find_map(|line| {
        let fields: Vec<&str> = line.split_whitespace().collect();
        (fields.get(1) == Some(&local.as_str()) && fields.get(2) == Some(&remote.as_str())).then(|| u8::from_str_radix(fields.get(3)?, 16).ok())?
    }))
}

/// Seconds from `since` until the server closes its end of the connection from `client`
/// (it leaves the established state, or the table), polled until `limit`; `None` where the
/// connection is not found established in the system's socket table at first (no table).
fn closed_after(server: SocketAddr, client: SocketAddr, since: Instant, limit: Duration) -> Option<f64> {
    const ESTABLISHED: u8 = 1;
    if tcp_state(server, client)?? != ESTABLISHED {
        return None;
    }
    while since.elapsed() < limit {
        if tcp_state(server, client)? != Some(ESTABLISHED) {
            return Some(since.elapsed().as_secs_f64());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    None
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
