//! The engine stream of one viewer: hello and topology, then frames at the configured rate,
//! with user edits read in between. Flow control keeps at most [`WINDOW`] frames of each hand
//! unacknowledged, so a browser that falls behind gets fewer frames instead of a growing queue.

use std::io::{ErrorKind, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use dqhand_stream::{Applied, Command, FrameRate, LiveInput, Session};
use tungstenite::protocol::frame::coding::CloseCode;
use tungstenite::protocol::CloseFrame;
use tungstenite::{Message, WebSocket};

use super::messages::{server_socket, Incoming, MAX_COMMAND_BYTES};
use super::request::{linger, Request};
use super::Shared;
use crate::feed::Feed;
use crate::live_learning;

/// The path of the stream.
pub const PATH: &str = "/stream";
/// Frames of each hand sent but not yet acknowledged, at most.
const WINDOW: u32 = 3;
/// A send that cannot complete in this time (the client stopped reading) ends the connection,
/// a file's or a stream's.
pub(super) const WRITE_TIMEOUT: Duration = Duration::from_secs(5);
/// A viewer that sends nothing this long while frames wait for its acknowledgement is pinged
/// (a live page answers with a pong, or acknowledges)...
pub(super) const PING_AFTER: Duration = Duration::from_secs(5);
/// ...and one silent this long is closed: it would hold one of the server's places for ever.
const SILENT_LIMIT: Duration = Duration::from_secs(15);

/// Completes the WebSocket handshake (the server's answer to a checked upgrade request).
pub(super) fn upgrade(mut stream: TcpStream, request: Request, accept: &str) -> std::io::Result<WebSocket<TcpStream>> {
    let response = format!(
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
    );
    stream.write_all(response.as_bytes())?;
    Ok(server_socket(stream, request.rest))
}

/// Completes the handshake and streams until the client leaves.
pub fn run(stream: TcpStream, request: Request, accept: &str, shared: &Shared) -> std::io::Result<()> {
    let mut ws = upgrade(stream, request, accept)?;
    let mut session = match Session::new(shared.model.clone(), shared.second.clone(), shared.joint_model) {
        Ok(s) => s,
        Err(e) => return send_error(&mut ws, &e.to_string()).map_err(io),
    };
    let input = shared.feed.as_deref().map(|f| &f.input);
    let mut view = input.map(LiveInput::view);
    ws.send(Message::text(session.hello(MAX_COMMAND_BYTES, input))).map_err(io)?;
    for topology in session.topologies() {
        ws.send(Message::binary(topology.encode())).map_err(io)?;
    }

    let period = Duration::from_secs_f64(1.0 / shared.fps);
    // Frames a step sends: one per hand.
    let per_step = 1 + u32::from(shared.second.is_some());
    let (mut sent, mut acked) = (0u32, 0u32);
    let started = Instant::now();
    let mut last_frame = started;
    let mut next_frame = last_frame;
    let mut rate = FrameRate::default();
    let mut frame = Vec::new();
    let (mut heard, mut pinged) = (Instant::now(), false);
    // The versions of the viewers' recording and learning this viewer was last told of.
    let (mut recording_seen, mut learning_seen) = (0, 0);
    loop {
        // Read edits until the next frame is due (or, with the window full, until an ack).
        loop {
            let now = Instant::now();
            let window_open = sent.wrapping_sub(acked) + per_step <= WINDOW * per_step;
            if window_open && now >= next_frame {
                break;
            }
            if !window_open && now - heard > SILENT_LIMIT {
                return refuse_and_close(&mut ws, &format!("no acknowledgement for {} s; closing", SILENT_LIMIT.as_secs()), None);
            }
            if !window_open && !pinged && now - heard > PING_AFTER {
                ws.send(Message::Ping(Default::default())).map_err(io)?;
                pinged = true;
            }
            let wait = if window_open { next_frame - now } else { Duration::from_millis(50) };
            ws.get_ref().set_read_timeout(Some(wait.max(Duration::from_millis(1))))?;
            let read = ws.read();
            if read.is_ok() {
                (heard, pinged) = (Instant::now(), false);
            }
            match read.map(Incoming::of) {
                Ok(Incoming::Command(Command::Ack { seq })) => acked = seq.wrapping_add(1),
                Ok(Incoming::Command(command)) => match session.apply(&command) {
                    Ok(Applied::Frame) => {}
                    Ok(Applied::Hello) => ws.send(Message::text(session.hello(MAX_COMMAND_BYTES, input))).map_err(io)?,
                    Ok(Applied::Record(on)) => {
                        if let Err(e) = record(shared.feed.as_deref(), on) {
                            send_error(&mut ws, &format!("{e:#}")).map_err(io)?;
                        }
                    }
                    Ok(Applied::Learn(request)) => {
                        let started = match &shared.feed {
                            Some(feed) => live_learning::start(feed, request),
                            None => Err(anyhow::anyhow!("learn: this server has no live input")),
                        };
                        if let Err(e) = started {
                            send_error(&mut ws, &format!("{e:#}")).map_err(io)?;
                        }
                    }
                    Err(e) => send_error(&mut ws, &e.to_string()).map_err(io)?,
                },
                Ok(Incoming::Refused(e)) => send_error(&mut ws, &e).map_err(io)?,
                Ok(Incoming::Close) => return Ok(()),
                Ok(Incoming::Nothing) => {}
                Err(e) => {
                    if let Some(end) = read_failure(&mut ws, e) {
                        return end;
                    }
                }
            }
        }
        let now = Instant::now();
        session.advance((now - last_frame).as_secs_f32().min(0.1));
        last_frame = now;
        if let Some(records) = shared.feed.as_deref().map(|f| &f.records).filter(|r| r.version() != recording_seen) {
            recording_seen = records.version();
            ws.send(Message::text(records.recording_message())).map_err(io)?;
        }
        if let Some(learning) = shared.feed.as_deref().map(|f| &f.learning).filter(|l| l.version() != learning_seen) {
            learning_seen = learning.version();
            ws.send(Message::text(learning.message())).map_err(io)?;
        }
        if let (Some(input), Some(view)) = (input, &mut view) {
            let update = input.update(&mut session, view);
            if update.hello {
                ws.send(Message::text(session.hello(MAX_COMMAND_BYTES, Some(input)))).map_err(io)?;
            }
            for message in [update.message, update.scene].into_iter().flatten() {
                ws.send(Message::text(message)).map_err(io)?;
            }
        }
        let fps = rate.tick((now - started).as_secs_f64());
        session.render(fps, &mut frame);
        // tungstenite takes ownership of each message: one buffer per frame is the transport's
        // cost (the engine's own buffers are reused).
        ws.send(Message::binary(std::mem::take(&mut frame))).map_err(io)?;
        sent = sent.wrapping_add(1);
        if session.render_second(fps, &mut frame) {
            ws.send(Message::binary(std::mem::take(&mut frame))).map_err(io)?;
            sent = sent.wrapping_add(1);
        }
        next_frame += period;
        if next_frame < now {
            next_frame = now; // after a stall, resume the rate instead of bursting to catch up
        }
    }
}

/// Starts (`on`) or stops the viewers' recording of the live input; every viewer then sends
/// the new state ([`crate::live::LiveRecords::recording_message`]).
pub(super) fn record(feed: Option<&Feed>, on: bool) -> anyhow::Result<()> {
    let Some(feed) = feed else { anyhow::bail!("record: this server has no live input") };
    if on {
        feed.records.start()
    } else {
        feed.records.stop();
        Ok(())
    }
}

/// What a failed read means: `None` to read on (a timeout), else how the connection ends
/// (a message over the size bound is answered with an error before closing).
pub(super) fn read_failure(ws: &mut WebSocket<TcpStream>, e: tungstenite::Error) -> Option<std::io::Result<()>> {
    match e {
        tungstenite::Error::Io(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => None,
        tungstenite::Error::Capacity(e) => Some(refuse_and_close(ws, &format!("message refused: {e}; closing"), None)),
        // A text message that is not UTF-8: the error line, then the close RFC 6455 asks for
        // (1007); no log line, so a client cannot fill the log with them.
        tungstenite::Error::Utf8(e) => {
            let invalid = CloseFrame { code: CloseCode::Invalid, reason: "text message not UTF-8".into() };
            Some(refuse_and_close(ws, &format!("a text message that is not UTF-8 ({e}); closing"), Some(invalid)))
        }
        tungstenite::Error::ConnectionClosed
        | tungstenite::Error::AlreadyClosed
        | tungstenite::Error::Protocol(tungstenite::error::ProtocolError::ResetWithoutClosingHandshake) => Some(Ok(())),
        e => Some(Err(io(e))),
    }
}

/// Sends `message` as an error, closes (with `frame`, if any) and lingers: the end of a
/// connection whose client broke the protocol.
fn refuse_and_close(ws: &mut WebSocket<TcpStream>, message: &str, frame: Option<CloseFrame>) -> std::io::Result<()> {
    let _ = send_error(ws, message);
    let _ = ws.close(frame);
    let _ = ws.flush();
    linger(ws.get_ref());
    Ok(())
}

pub(super) fn send_error(ws: &mut WebSocket<TcpStream>, message: &str) -> tungstenite::Result<()> {
    ws.send(Message::text(serde_json::json!({ "type": "error", "message": message }).to_string()))
}

/// A failed send as an I/O error; one that timed out says what happened (reads that time out
/// never get here: [`read_failure`] reads on).
pub(super) fn io(e: tungstenite::Error) -> std::io::Error {
    match e {
        tungstenite::Error::Io(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
            std::io::Error::new(ErrorKind::TimedOut, format!("the client stopped reading: nothing could be sent for {} s; closed", WRITE_TIMEOUT.as_secs()))
        }
        tungstenite::Error::Io(e) => e,
        e => std::io::Error::other(e),
    }
}
