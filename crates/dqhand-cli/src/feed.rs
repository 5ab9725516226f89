//! What feeds the demo's live input: a recording played in real time (looping), a UDP
//! stream, and the `/input` WebSocket of the server, each from its own thread. Every record
//! taken is also relayed to the pages that run the engine themselves.

use std::io::ErrorKind;
use std::net::UdpSocket;
use std::sync::atomic::AtomicUsize;
use std::time::{Duration, Instant};

use dqhand::input::{Record, Rejection};
use dqhand_stream::LiveInput;

use crate::live::{LiveRecords, MAX_DATAGRAM_BYTES};
use crate::live_learning::LiveLearning;
use crate::relay::RecordRelay;
use crate::recording::RecordingReader;

/// The demo's live input and how bytes reach it.
pub struct Feed {
    pub input: LiveInput,
    pub records: LiveRecords,
    /// Gestures learned from the viewers' Input panel.
    pub learning: LiveLearning,
    /// The records taken, for the pages that run the engine themselves.
    pub relay: RecordRelay,
    /// `/input` connections open now (each holds a thread; see [`MAX_INPUT_CLIENTS`]).
    pub clients: AtomicUsize,
}

/// `/input` connections at once; more are refused (one hand takes one sender at a time).
pub const MAX_INPUT_CLIENTS: usize = 4;
/// The longest pause between two records of a played recording, seconds; a longer one is
/// played as this long (a recording may stop for minutes, or claim a year between records).
const MAX_PAUSE_S: f64 = 5.0;
/// How far a played recording may fall behind its schedule before it plays on from now.
const MAX_BEHIND: Duration = Duration::from_millis(50);
/// How often the demo logs new refusals (one line per kind).
const REPORT_PERIOD: Duration = Duration::from_secs(5);

impl Feed {
    /// Takes one datagram or message: decoded, given to the input, recorded if taken.
    ///
    /// # Errors
    /// The record's refusal (already counted by the input).
    pub fn take(&self, bytes: &[u8], record: &mut Record) -> Result<(), Rejection> {
        if let Err(rejection) = self.records.decode(bytes, record) {
            self.input.reject(rejection.clone());
            return Err(rejection);
        }
        self.input.push(record, |r| {
            self.records.keep(r);
            self.relay.publish(r);
        })
    }

    /// Receives datagrams forever (until the socket fails).
    pub fn receive(&self, socket: &UdpSocket) -> std::io::Result<()> {
        let mut buf = vec![0u8; MAX_DATAGRAM_BYTES];
        let mut record = self.records.blank();
        loop {
            match socket.recv_from(&mut buf) {
                Ok((n, _)) => {
                    let _ = self.take(&buf[..n], &mut record); // refusals are counted and shown
                }
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted) => {}
                Err(e) => return Err(e),
            }
        }
    }

    /// Plays a recording in real time, from its first record's time, over and over: each
    /// pass follows the previous one by its last interval between records, so the input's
    /// clock runs on and the hand does not drop out between passes; a scene starts over with
    /// each pass. Pauses longer than [`MAX_PAUSE_S`] are shortened to it; unreadable records
    /// are counted on the first pass. `open` opens the recording for each pass; `name` names
    /// it in messages.
    pub fn play(&self, name: &str, open: impl Fn() -> anyhow::Result<RecordingReader>) -> anyhow::Result<()> {
        let start = Instant::now();
        let mut record = self.records.blank();
        let (mut shift, mut pass) = (0.0, 0);
        loop {
            if pass > 0 {
                self.input.reset_scene();
                self.relay.reset_scene();
            }
            let mut reader = open()?;
            let (mut first, mut last, mut interval, mut played) = (None::<f64>, None::<f64>, FIRST_INTERVAL, 0.0);
            while let Some(read) = reader.next(&mut record)? {
                if let Err(rejection) = read {
                    if pass == 0 {
                        self.input.reject(rejection.at(name));
                    }
                    continue;
                }
                let t = record.time;
                first.get_or_insert(t);
                // Out of order: played at the time of the one before, and refused by the input.
                if let Some(previous) = last.filter(|&p| t > p) {
                    interval = (t - previous).min(MAX_PAUSE_S);
                    played += interval;
                }
                last = Some(t);
                record.time = shift + played;
                let now = start.elapsed();
                match Duration::try_from_secs_f64(record.time) {
                    Ok(due) if due > now => std::thread::sleep(due - now),
                    // Behind (this thread was not scheduled): play on from now, as a sender
                    // that paused would, rather than send stale records the input refuses.
                    Ok(due) if now - due > MAX_BEHIND => {
                        let behind = (now - due).as_secs_f64();
                        (shift, record.time) = (shift + behind, record.time + behind);
                    }
                    _ => {}
                }
                let _ = self.input.push(&record, |r| self.relay.publish(r)); // refusals are counted and shown
            }
            if first.is_none() {
                anyhow::bail!("{name}: no record to play");
            }
            shift += played + interval;
            pass += 1;
        }
    }

    /// Logs the refusals on stderr, one line per kind, every few seconds when there are new
    /// ones (the viewers show the totals).
    pub fn report(&self) {
        let mut reported = 0;
        loop {
            std::thread::sleep(REPORT_PERIOD);
            let (taken, refused, lines) = self.input.summary();
            if refused > reported {
                crate::live::log_refusals("input", taken, refused, &lines);
                reported = refused;
            }
        }
    }
}

/// The pause between passes of a recording with a single record.
const FIRST_INTERVAL: f64 = 0.1;
