//! The `/relay` WebSocket: the demo's live input for a page that runs the engine itself
//! ([`super::page_engine`]). The server sends each record its input takes as a binary message
//! (one JSON record, as a recording's line), `{"type": "reset_scene"}` in its place among them
//! when the scene starts over (a recording played again), the gestures recognised
//! (`{"type": "gestures", "gestures": "<gesture file text>"}`: at once, and again after one is
//! learned), and the `recording` and `learning` messages of the stream. The page sends only what needs this
//! machine: `record` (to disk, [`crate::live::LiveRecords`]) and `learn`; anything else is
//! answered with an error, since the page's own engine does the rest. The page's camera or
//! headset input goes to `/input` as before and comes back here like any other record.

use std::net::TcpStream;
use std::sync::Arc;
use std::time::{Duration, Instant};

use dqhand_stream::{Command, LearnRequest};
use serde_json::json;
use tungstenite::{Message, WebSocket};

use super::messages::Incoming;
use super::request::Request;
use super::socket::{read_failure, send_error, upgrade, PING_AFTER};
use crate::feed::Feed;
use crate::live_learning;
use crate::relay::RESET;

/// The path of the relay.
pub const PATH: &str = "/relay";
/// Longest wait for a record before the page's messages are read again.
const WAIT: Duration = Duration::from_millis(10);

/// Completes the handshake and relays until the page leaves.
pub fn run(stream: TcpStream, request: Request, accept: &str, feed: &Arc<Feed>) -> std::io::Result<()> {
    // Where the page starts, taken before the handshake completes: a record published once
    // the page knows it is connected is one it gets, however late this thread runs (in the
    // load test, 60 pages on a busy 2-core machine, one got 119 of 120 records).
    let mut seen = feed.relay.published();
    let mut ws = upgrade(stream, request, accept)?;
    // Reads only look whether the page said something; the waiting is for records.
    ws.get_ref().set_read_timeout(Some(Duration::from_millis(1)))?;
    // The versions of the recording and learning this page was last told of (as the stream's
    // viewers, it is told of them once they have changed).
    let (mut recording_seen, mut learning_seen) = (0, 0);
    let mut gestures_sent = String::new();
    send_gestures(&mut ws, feed, &mut gestures_sent)?;
    let mut lines = Vec::new();
    let mut heard = Instant::now();
    loop {
        let read = ws.read();
        if read.is_ok() {
            heard = Instant::now();
        }
        match read.map(Incoming::of) {
            Ok(Incoming::Command(command)) => {
                if let Err(e) = apply(feed, command) {
                    send_error(&mut ws, &format!("{e:#}")).map_err(super::socket::io)?;
                }
            }
            Ok(Incoming::Refused(e)) => send_error(&mut ws, &e).map_err(super::socket::io)?,
            Ok(Incoming::Close) => return Ok(()),
            Ok(Incoming::Nothing) => {}
            Err(e) => {
                if let Some(end) = read_failure(&mut ws, e) {
                    return end;
                }
            }
        }
        // A page silent this long is pinged (a peer gone fails the send); a busy page whose
        // pong comes late is not closed: it takes only its own thread.
        if Instant::now() - heard > PING_AFTER {
            ws.send(Message::Ping(Default::default())).map_err(super::socket::io)?;
            heard = Instant::now();
        }
        if feed.records.version() != recording_seen {
            recording_seen = feed.records.version();
            ws.send(Message::text(feed.records.recording_message())).map_err(super::socket::io)?;
        }
        if feed.learning.version() != learning_seen {
            learning_seen = feed.learning.version();
            send_gestures(&mut ws, feed, &mut gestures_sent)?;
            ws.send(Message::text(feed.learning.message())).map_err(super::socket::io)?;
        }
        feed.relay.after(&mut seen, WAIT, &mut lines);
        for line in lines.drain(..) {
            let message = if line == RESET { Message::text(r#"{"type": "reset_scene"}"#) } else { Message::binary(line) };
            ws.send(message).map_err(super::socket::io)?;
        }
    }
}

/// Sends the gestures recognised now, if they are not what the page has.
fn send_gestures(ws: &mut WebSocket<TcpStream>, feed: &Feed, sent: &mut String) -> std::io::Result<()> {
    let Some(set) = feed.input.gesture_set() else { return Ok(()) };
    let gestures = set.to_json();
    if gestures != *sent {
        ws.send(Message::text(json!({ "type": "gestures", "gestures": gestures }).to_string())).map_err(super::socket::io)?;
        *sent = gestures;
    }
    Ok(())
}

/// Carries out a page's command: a recording to disk, or a gesture to learn.
fn apply(feed: &Arc<Feed>, command: Command) -> anyhow::Result<()> {
    match command {
        Command::Record { on } => super::socket::record(Some(feed), on),
        Command::Learn { name, seconds, not } => live_learning::start(feed, LearnRequest::new(&name, seconds, not).map_err(anyhow::Error::msg)?),
        _ => anyhow::bail!("relay: only record and learn go to the server (the page's engine does the rest)"),
    }
}
