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
    /// The recording being written, if any (`--record`, or a viewer's Record button).
    recorder: Mutex<Option<Recorder>>,
    /// Where a viewer's recordings go (`demo --recordings`); `None`: viewers cannot record.
    directory: Option<PathBuf>,
}

/// A recording that was written: its file and how many records it holds.
pub struct Recorded {
    pub path: PathBuf,
    pub records: u64,
}

impl LiveRecords {
    /// Records of `args`' default side and glove, recorded to `record` if given (a new file,
    /// replacing one that is there); viewers may start recordings in `directory`.
    pub fn new(args: &InputArgs, record: Option<&Path>, directory: Option<PathBuf>) -> anyhow::Result<Self> {
        let sensors = args.table()?.layout().sensors().iter().map(|s| s.name.clone()).collect();
        let recorder = record.map(|path| Recorder::create(path, File::create(path))).transpose()?;
        Ok(Self { side: args.hand, sensors, recorder: Mutex::new(recorder), directory })
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
        if let Some(r) = self.lock().as_mut() {
            r.append(record, &self.sensors);
        }
    }

    /// Starts a new recording in the viewers' directory, named for the time
    /// (`live-<unix seconds>.jsonl`, never replacing a file), ending the one being written.
    ///
    /// # Errors
    /// No directory for viewers' recordings, or the file cannot be created.
    pub fn start(&self) -> anyhow::Result<PathBuf> {
        let Some(directory) = &self.directory else { anyhow::bail!("record: this server does not record (no recordings directory)") };
        std::fs::create_dir_all(directory).with_context(|| format!("{}: cannot create the recordings directory", directory.display()))?;
        let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
        let mut guard = self.lock();
        for n in 1.. {
            let name = if n == 1 { format!("live-{stamp}.jsonl") } else { format!("live-{stamp}-{n}.jsonl") };
            let path = directory.join(name);
            match File::options().write(true).create_new(true).open(&path) {
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
                file => {
                    *guard = Some(Recorder::create(&path, file)?);
                    return Ok(path);
                }
            }
        }
        unreachable!("some name is free")
    }

    /// Ends the recording being written, if any: what it holds.
    pub fn stop(&self) -> Option<Recorded> {
        self.lock().take().map(|r| Recorded { path: r.path, records: r.records })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Recorder>> {
        self.recorder.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
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
    file: Option<(File, Vec<u8>)>,
    /// Records written.
    records: u64,
}

impl Recorder {
    fn create(path: &Path, file: std::io::Result<File>) -> anyhow::Result<Self> {
        let file = file.with_context(|| format!("{}: cannot create the recording", path.display()))?;
        Ok(Self { path: path.into(), file: Some((file, Vec::with_capacity(4096))), records: 0 })
    }

    fn append(&mut self, record: &Record, sensors: &[String]) {
        let Some((file, line)) = self.file.as_mut() else { return };
        line.clear();
        let written = write_record(line, record, sensors).and_then(|()| file.write_all(line));
        match written {
            Ok(()) => self.records += 1,
            Err(e) => {
                eprintln!("dqhand: {}: {e}; recording stopped (the records before are kept)", self.path.display());
                self.file = None;
            }
        }
    }
}
