//! What feeds the demo's live input: a recording played in real time (looping), a UDP
//! stream, and the `/input` WebSocket of the server, each from its own thread.

use std::io::ErrorKind;
use std::net::UdpSocket;
use std::path::Path;
use std::time::{Duration, Instant};

use dqhand::input::{Record, Rejection};
use dqhand::stream::LiveInput;

use crate::live::{LiveRecords, MAX_DATAGRAM_BYTES};
use crate::recording::{Format, InputArgs, RecordingReader};

/// The demo's live input and how bytes reach it.
pub struct Feed {
    pub input: LiveInput,
    pub records: LiveRecords,
}

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
        self.input.push(record)?;
        self.records.keep(record);
        Ok(())
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
    /// clock runs on and the hand does not drop out between passes.
    pub fn play(&self, path: &Path, format: Option<Format>, args: &InputArgs) -> anyhow::Result<()> {
        let start = Instant::now();
        let mut record = self.records.blank();
        let mut shift = 0.0;
        loop {
            let mut reader = RecordingReader::open(path, format, args)?;
            let (mut first, mut last, mut interval) = (None::<f64>, None::<f64>, FIRST_INTERVAL);
            while let Some(read) = reader.next(&mut record)? {
                if let Err(rejection) = read {
                    self.input.reject(rejection.at(path.display()));
                    continue;
                }
                let first = *first.get_or_insert(record.time);
                if let Some(previous) = last.filter(|&p| record.time > p) {
                    interval = record.time - previous;
                }
                last = Some(record.time);
                record.time += shift - first;
                if let Some(wait) = Duration::from_secs_f64(record.time.max(0.0)).checked_sub(start.elapsed()) {
                    std::thread::sleep(wait);
                }
                let _ = self.input.push(&record); // refusals are counted and shown
            }
            let (Some(first), Some(last)) = (first, last) else {
                anyhow::bail!("{}: no record to play", path.display());
            };
            shift += last - first + interval;
        }
    }
}

/// The pause between passes of a recording with a single record.
const FIRST_INTERVAL: f64 = 0.1;
