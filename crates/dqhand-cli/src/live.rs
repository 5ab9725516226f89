//! Live records: decoding what arrives (a UDP datagram or a WebSocket message, one JSON record
//! each) and recording the records taken, for `dqhand listen` and the demo server.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
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
    /// `--record FILE`: every record taken, from the start.
    fixed: Option<Mutex<Recorder>>,
    /// The viewers' recording (their Record button): one at a time, shared by every viewer.
    viewers: Mutex<Viewers>,
    /// Changes of the viewers' recording so far: each viewer sends the state on a change.
    version: AtomicU64,
    /// Where the viewers' recordings go (`demo --recordings`); `None`: viewers cannot record.
    directory: Option<PathBuf>,
}

/// The viewers' recording: the one being written, else the last one written.
#[derive(Default)]
struct Viewers {
    current: Option<Recorder>,
    last: Option<(PathBuf, u64, bool)>,
}

impl LiveRecords {
    /// Records of `args`' default side and glove, recorded to `record` if given (a new file,
    /// replacing one that is there); viewers may record in `directory`.
    pub fn new(args: &InputArgs, record: Option<&Path>, directory: Option<PathBuf>) -> anyhow::Result<Self> {
        let sensors = args.table()?.layout().sensors().iter().map(|s| s.name.clone()).collect();
        let fixed = record.map(|path| Recorder::create(path, File::create(path)).map(Mutex::new)).transpose()?;
        Ok(Self { side: args.hand, sensors, fixed, viewers: Mutex::default(), version: AtomicU64::new(0), directory })
    }

    /// The glove's sensor names, in the order of a glove record's values.
    pub fn sensors(&self) -> &[String] {
        &self.sensors
    }

    /// A blank record to decode into.
    pub fn blank(&self) -> Record {
        Record { time: 0.0, side: self.side, hand: None, tracker: None, arrival: None }
    }

    /// Decodes one datagram or message into `out`.
    ///
    /// # Errors
    /// The rejection of a record that is too large, not UTF-8 or not a valid record.
    pub fn decode(&self, bytes: &[u8], out: &mut Record) -> Result<(), Rejection> {
        parse_message(bytes, self.side, &self.sensors, out)
    }

    /// Appends a record the input took to the recordings being written.
    pub fn keep(&self, record: &Record) {
        if let Some(r) = &self.fixed {
            lock(r).append(record, &self.sensors);
        }
        if let Some(r) = lock(&self.viewers).current.as_mut() {
            r.append(record, &self.sensors);
        }
    }

    /// Starts the viewers' recording: a new file in their directory, named for the time
    /// (`live-<unix seconds>.jsonl`, never replacing a file); one already being written goes
    /// on (a second viewer's Record joins it, and files are not made without end).
    ///
    /// # Errors
    /// No directory for viewers' recordings, or the file cannot be created.
    pub fn start(&self) -> anyhow::Result<()> {
        let Some(directory) = &self.directory else { anyhow::bail!("record: this server does not record (no recordings directory)") };
        let mut viewers = lock(&self.viewers);
        self.version.fetch_add(1, Ordering::SeqCst);
        if viewers.current.is_some() {
            return Ok(());
        }
        std::fs::create_dir_all(directory).with_context(|| format!("{}: cannot create the recordings directory", directory.display()))?;
        let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
        for n in 1.. {
            let name = if n == 1 { format!("live-{stamp}.jsonl") } else { format!("live-{stamp}-{n}.jsonl") };
            let path = directory.join(name);
            match File::options().write(true).create_new(true).open(&path) {
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
                file => {
                    viewers.current = Some(Recorder::create(&path, file)?);
                    return Ok(());
                }
            }
        }
        unreachable!("some name is free")
    }

    /// Ends the viewers' recording, if one is being written.
    pub fn stop(&self) {
        let mut viewers = lock(&self.viewers);
        self.version.fetch_add(1, Ordering::SeqCst);
        if let Some(r) = viewers.current.take() {
            viewers.last = Some((r.path, r.records, r.file.is_none()));
        }
    }

    /// The number of changes of the viewers' recording so far (a viewer that has sent the
    /// state of an older one sends [`Self::recording_message`]).
    pub fn version(&self) -> u64 {
        self.version.load(Ordering::SeqCst)
    }

    /// The viewers' recording as a message for every viewer: on (the file being written) or
    /// off (the last file written, `path` null if none), the records in it, and whether
    /// writing failed (a full disk: the records before the failure are kept).
    ///
    /// ```json
    /// {"type": "recording", "on": false, "path": "recordings/live-1795000000.jsonl", "records": 412, "failed": false}
    /// ```
    pub fn recording_message(&self) -> String {
        let viewers = lock(&self.viewers);
        let (on, state) = match &viewers.current {
            Some(r) => (true, Some((&r.path, r.records, r.file.is_none()))),
            None => (false, viewers.last.as_ref().map(|(p, n, f)| (p, *n, *f))),
        };
        let (path, records, failed) = state.map_or((None, 0, false), |(p, n, f)| (Some(p.display().to_string()), n, f));
        serde_json::json!({ "type": "recording", "on": on, "path": path, "records": records, "failed": failed }).to_string()
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
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
