//! `dqhand listen`: live input without the viewer. Records arrive on a UDP port, one JSON
//! record per datagram, drive the gesture loop, and gesture events are printed as JSON lines
//! on stdout as they happen; tracking changes and a summary of refused records go to stderr.

use std::io::{ErrorKind, Write};
use std::net::{IpAddr, SocketAddr, UdpSocket};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context;
use dqhand::engine::ModelSource;
use dqhand::input::Tracking;
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointModel;

use crate::live::{LiveRecords, MAX_DATAGRAM_BYTES};
use crate::recording::{GestureArgs, InputArgs};

/// Arguments of `dqhand listen`.
#[derive(clap::Args)]
pub struct Args {
    /// UDP port to receive records on (one JSON record per datagram).
    #[arg(long)]
    udp: u16,
    /// Address to receive on. The default takes datagrams from this machine only.
    #[arg(long, default_value = "127.0.0.1")]
    host: IpAddr,
    /// Record every record taken to this file (JSON lines, replacing the file, each record
    /// written out as it is taken).
    #[arg(long)]
    record: Option<PathBuf>,
    #[command(flatten)]
    common: InputArgs,
    #[command(flatten)]
    recognition: GestureArgs,
    /// Stop after this many seconds (default: run until interrupted; the recording is
    /// complete either way).
    #[arg(long)]
    seconds: Option<f64>,
    /// Joint model of the virtual hand.
    #[arg(long, default_value = "full")]
    joint_model: JointModel,
    /// The hand posed: `builtin` or a skinned glTF with WebXR joint names.
    #[arg(long, default_value = "builtin")]
    model: ModelSource,
}

/// How often the loop wakes without datagrams, to mark the hand lost after the grace time.
const TICK: Duration = Duration::from_millis(20);
/// New refusals are summarised (one line per kind) at most this often.
const REPORT_PERIOD: Duration = Duration::from_secs(5);

pub fn run(args: &Args) -> anyhow::Result<()> {
    let model = Arc::new(args.model.load()?);
    let gestures = args.recognition.set()?;
    let mapper = Some(args.common.mapper(args.joint_model)?);
    let mut gesture_loop = GestureLoop::new(model, args.joint_model, mapper, args.common.config()?, gestures)?;
    let live = LiveRecords::new(&args.common, args.record.as_deref(), None)?;
    let address = SocketAddr::new(args.host, args.udp);
    let socket = UdpSocket::bind(address).with_context(|| format!("cannot receive on udp {address} (try another --udp port)"))?;
    socket.set_read_timeout(Some(TICK))?;
    eprintln!("listening on udp {}{}", socket.local_addr()?, if args.host.is_loopback() { ", this machine only" } else { "" });
    let stdout = std::io::stdout();
    let mut buf = vec![0u8; MAX_DATAGRAM_BYTES];
    let mut record = live.blank();
    let mut tracking = Tracking::Waiting;
    let start = Instant::now();
    let (mut reported, mut last_report) = (0, start);
    while args.seconds.is_none_or(|s| start.elapsed().as_secs_f64() < s) {
        match socket.recv_from(&mut buf) {
            Ok((n, _)) => match live.decode(&buf[..n], &mut record) {
                // A refusal by the loop is counted there.
                Ok(()) => {
                    record.arrival = Some(start.elapsed().as_secs_f64()); // recorded: a replay takes it as it arrived
                    if let Ok(events) = gesture_loop.push(&record) {
                        let mut out = stdout.lock();
                        for event in events {
                            serde_json::to_writer(&mut out, &event)?;
                            out.write_all(b"\n")?;
                        }
                        out.flush()?;
                        live.keep(&record);
                    }
                }
                Err(rejection) => gesture_loop.reject(rejection),
            },
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted) => {}
            Err(e) => return Err(e).context(format!("udp {address}")),
        }
        gesture_loop.advance(start.elapsed().as_secs_f64());
        let state = gesture_loop.pipeline().tracking();
        if state != tracking {
            eprintln!("tracking: {}", state.as_str());
            tracking = state;
        }
        let refused = gesture_loop.pipeline().rejections().total();
        if refused > reported && last_report.elapsed() >= REPORT_PERIOD {
            summarise(&gesture_loop);
            (reported, last_report) = (refused, Instant::now());
        }
    }
    summarise(&gesture_loop);
    Ok(())
}

/// The records taken and refused so far, one line per kind of refusal.
fn summarise(gesture_loop: &GestureLoop) {
    let pipeline = gesture_loop.pipeline();
    let lines: Vec<String> = pipeline.rejections().summary().collect();
    crate::live::log_refusals("udp", pipeline.accepted(), pipeline.rejections().total(), &lines);
}
