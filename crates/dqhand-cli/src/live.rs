//! Live records: decoding what arrives (a UDP datagram or a WebSocket message, one JSON record
//! each) and recording the records taken, for `dqhand listen` and the demo server.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::Context;
use dqhand::hand::Side;
use dqhand::input::json_record::{parse_message, write_record};
use dqhand::input::{Record, Rejection};

use crate::recording::InputArgs;

/// Largest UDP datagram read; one larger than a record is refused as too large, not cut.
pub const MAX_DATAGRAM_BYTES: usize = 64 * 1024;

/// How live bytes become records, and where the taken ones are recorded.
pub struct LiveRecords {
    side: Side,
    sensors: Vec<String>,
    recorder: Option<Recorder>,
}

impl LiveRecords {
    /// Records of `args`' default side and glove, recorded to `record` if given (a new file,
    /// replacing one that is there).
    pub fn new(args: &InputArgs, record: Option<&Path>) -> anyhow::Result<Self> {
        let sensors = args.table()?.layout().sensors().iter().map(|s| s.name.clone()).collect();
        let recorder = record.map(Recorder::create).transpose()?;
        Ok(Self { side: args.hand, sensors, recorder })
    }

    /// A blank record to decode into.
    pub fn blank(&self) -> Record {
        Record { time: 0.0, side: self.side, hand: None, tracker: None }
    }

    /// Decodes one datagram or message into `out`.
    ///
    /// # Errors
    /// The rejection of a record that is too large, not UTF-8 or not a valid record.
    pub fn decode(&self, bytes: &[u8], out: &mut Record) -> Result<(), Rejection> {
        parse_message(bytes, self.side, &self.sensors, out)
    }

    /// Appends a record the input took to the recording, if there is one.
    pub fn keep(&self, record: &Record) {
        if let Some(r) = &self.recorder {
            r.append(record, &self.sensors);
        }
    }
}

/// Logs the records taken and refused so far on stderr, the refusals one line per kind.
pub fn log_refusals(source: &str, taken: u64, refused: u64, lines: &[String]) {
    for line in lines {
        eprintln!("dqhand: {source}: {line}");
    }
    eprintln!("dqhand: {source}: {taken} records taken, {refused} rejected");
}

/// A recording being written: one JSON line per record, each written whole and handed to
/// the operating system at once, so a crash loses at most the record being written and the
/// file always reads back (`dqhand replay`).
struct Recorder {
    path: PathBuf,
    /// The file and a line buffer (reused); `None` once a write has failed.
    file: Mutex<Option<(File, Vec<u8>)>>,
}

impl Recorder {
    fn create(path: &Path) -> anyhow::Result<Self> {
        let file = File::create(path).with_context(|| format!("{}: cannot create the recording", path.display()))?;
        Ok(Self { path: path.into(), file: Mutex::new(Some((file, Vec::with_capacity(4096)))) })
    }

    fn append(&self, record: &Record, sensors: &[String]) {
        let mut guard = self.file.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let Some((file, line)) = guard.as_mut() else { return };
        line.clear();
        let written = write_record(line, record, sensors).and_then(|()| file.write_all(line));
        if let Err(e) = written {
            eprintln!("dqhand: {}: {e}; recording stopped (the records before are kept)", self.path.display());
            *guard = None;
        }
    }
}
