//! The demo's live input relayed to the pages whose engine runs in them: every record the
//! input takes (a glove's or tracker's datagram, a recording played, a device's `/input`
//! message) as the JSON line a recording holds, for each `/relay` connection to send on.
//! The log is bounded: a page further behind than [`CAPACITY`] records misses the oldest (its
//! engine sees a gap, as after a lost datagram), and the server never grows. A scene started
//! over (a recording played again) is an entry of the log too, in its place among the records.

use std::collections::VecDeque;
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use dqhand::input::json_record::write_record;
use dqhand::input::Record;
use tungstenite::Bytes;

/// Records kept for connections that have not sent them yet (seconds of a 120 Hz glove).
pub const CAPACITY: usize = 1024;
/// The entry of a scene started over: empty (a record never is).
pub const RESET: &[u8] = b"";

/// The records taken, for every page that follows them.
pub struct RecordRelay {
    /// The glove's sensor names: how a glove record's values are named.
    sensors: Vec<String>,
    log: Mutex<Log>,
    arrived: Condvar,
}

/// The latest records, as JSON lines without their newline ([`RESET`] for a scene started over).
#[derive(Default)]
struct Log {
    lines: VecDeque<Bytes>,
    /// Records published so far: the next one's number.
    next: u64,
}

impl RecordRelay {
    /// A relay of records whose glove values are named by `sensors`.
    pub fn new(sensors: Vec<String>) -> Self {
        Self { sensors, log: Mutex::default(), arrived: Condvar::new() }
    }

    /// Adds a record the input took; the oldest goes when the log is full.
    pub fn publish(&self, record: &Record) {
        let mut line = Vec::with_capacity(256);
        // A taken record is finite, and a Vec takes every write.
        if write_record(&mut line, record, &self.sensors).is_ok() {
            line.pop(); // the newline: one record is one message
            self.add(Bytes::from(line));
        }
    }

    /// Adds that the input's scene started over ([`RESET`]).
    pub fn reset_scene(&self) {
        self.add(Bytes::new());
    }

    fn add(&self, line: Bytes) {
        let mut log = lock(&self.log);
        if log.lines.len() == CAPACITY {
            log.lines.pop_front();
        }
        log.lines.push_back(line);
        log.next += 1;
        drop(log);
        self.arrived.notify_all();
    }

    /// The number of records published so far: where a new page starts (it follows the
    /// input from now, not from the backlog).
    pub fn published(&self) -> u64 {
        lock(&self.log).next
    }

    /// Puts into `out` the entries after the first `seen` (those still kept; a clone is a
    /// count, not a copy), waiting up to `wait` for one if there is none yet; `seen` moves past
    /// them.
    pub fn after(&self, seen: &mut u64, wait: Duration, out: &mut Vec<Bytes>) {
        let mut log = lock(&self.log);
        if log.next == *seen {
            log = self.arrived.wait_timeout(log, wait).unwrap_or_else(PoisonError::into_inner).0;
        }
        let first = log.next - log.lines.len() as u64;
        let skip = usize::try_from(seen.saturating_sub(first)).unwrap_or(usize::MAX);
        out.extend(log.lines.iter().skip(skip).cloned());
        *seen = log.next;
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

#[cfg(test)]
mod tests {
    use super::*;
    use dqhand::hand::Side;

    fn record(time: f64) -> Record {
        Record { time, side: Side::Left, hand: None, tracker: None, arrival: None }
    }

    #[test]
    fn a_page_gets_the_records_after_it_came_and_one_far_behind_misses_the_oldest() {
        let relay = RecordRelay::new(Vec::new());
        relay.publish(&record(0.0));
        let mut seen = relay.published();
        let mut out = Vec::new();
        relay.after(&mut seen, Duration::ZERO, &mut out);
        assert!(out.is_empty(), "the backlog is not sent to a new page");
        relay.publish(&record(1.0));
        relay.reset_scene();
        relay.publish(&record(2.0));
        relay.after(&mut seen, Duration::ZERO, &mut out);
        assert_eq!(&out.remove(1)[..], RESET, "the reset in its place");
        let times = |out: &[Bytes]| out.iter().map(|l| serde_json::from_slice::<serde_json::Value>(l).unwrap()["t"].as_f64().unwrap()).collect::<Vec<_>>();
        assert_eq!(times(&out), [1.0, 2.0]);
        assert!(out.iter().all(|l| !l.ends_with(b"\n")), "one record per message, no newline");
        out.clear();
        for k in 0..CAPACITY + 10 {
            relay.publish(&record(3.0 + k as f64));
        }
        relay.after(&mut seen, Duration::ZERO, &mut out);
        assert_eq!(out.len(), CAPACITY, "the kept records, no more");
        assert_eq!(times(&out[..1]), [13.0], "the oldest kept is the 11th published since");
        assert_eq!(seen, relay.published());
    }

    #[test]
    fn a_waiting_page_wakes_for_a_record() {
        let relay = std::sync::Arc::new(RecordRelay::new(Vec::new()));
        let mut seen = relay.published();
        let publisher = std::sync::Arc::clone(&relay);
        let thread = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20));
            publisher.publish(&record(5.0));
        });
        let mut out = Vec::new();
        while out.is_empty() {
            relay.after(&mut seen, Duration::from_secs(5), &mut out);
        }
        thread.join().unwrap();
        assert_eq!(out.len(), 1);
    }
}
