//! Glove recordings as CSV: what 5DT and CyberGlove tools export, spreadsheets open, and the
//! live-session recorder appends.
//!
//! ```text
//! t,thumb_near,thumb_far,…,little_far,px,py,pz,qx,qy,qz,qw,hand
//! 0.000,812,1020,…,640,0.1,1.2,-0.3,0,0,0,1,right
//! ```
//! A header row names the columns, in any order: `t` (seconds, ≥ 0), every sensor of the
//! glove's [`MappingTable`] (raw values, 0–4095), optionally the wrist tracker's pose
//! `px,py,pz` (m) and `qx,qy,qz,qw` (all seven or none; the quaternion is normalised when
//! its length is within 1 % of 1 and refused otherwise), and optionally `hand` (`left` or
//! `right`). Blank lines are skipped.
//!
//! The fields are numbers and two words, so the format has no quoting and a line splits at
//! its commas; a hand-written splitter over one reused line buffer reads a row without
//! allocating, which the `csv` crate would also do but at the price of a dependency for no
//! feature we use. A quoted field is therefore just a field that is not a number.

use std::io::{self, BufRead, Write};

use glam::{Quat, Vec3};

use super::glove_layout::check_raw;
use super::record::unit_as_read;
use super::{GloveSample, HandData, MappingTable, Record, RejectKind, Rejection, RigidPose, MAX_GLOVE_SENSORS};
use crate::kinematics::Side;
use crate::{Error, Result};

/// The tracker's columns, in record order (position, then quaternion `x, y, z, w`).
const TRACKER_COLUMNS: [&str; 7] = ["px", "py", "pz", "qx", "qy", "qz", "qw"];

/// Largest difference of a tracker quaternion's length from 1 that is taken as rounding in
/// the file (and normalised away) rather than a wrong value.
const QUAT_LENGTH_TOLERANCE: f32 = 0.01;

/// What one CSV column holds.
#[derive(Clone, Copy, Debug)]
enum Column {
    Time,
    Sensor(usize),
    Tracker(usize),
    Hand,
}

/// A header, resolved: what each column holds, and the names for messages.
#[derive(Clone, Debug)]
struct Header {
    columns: Vec<Column>,
    sensor_names: Vec<String>,
    has_tracker: bool,
}

/// Reads a glove CSV one record at a time; a bad row is refused and reading goes on.
#[derive(Debug)]
pub struct GloveCsvReader<R> {
    input: R,
    header: Header,
    default_side: Side,
    line: Vec<u8>,
    line_number: usize,
    finished: bool,
}

impl<R: BufRead> GloveCsvReader<R> {
    /// Reads and checks the header of a CSV of the glove of `table`; rows without a `hand`
    /// column are of `default_side`.
    ///
    /// # Errors
    /// [`Error::Glove`] when the header cannot be read or is wrong: missing (empty input),
    /// not UTF-8, a column repeated, unknown columns or missing sensors (naming them), no
    /// `t`, or only some of the tracker columns. The whole file is then unusable.
    pub fn new(mut input: R, table: &MappingTable, default_side: Side) -> Result<Self> {
        let mut line = Vec::new();
        input.read_until(b'\n', &mut line).map_err(|e| Error::Glove(format!("glove csv header: {e}")))?;
        let text = std::str::from_utf8(&line).map_err(|_| Error::Glove("glove csv header: not UTF-8 text".into()))?;
        let text = text.trim_start_matches('\u{feff}').trim_end_matches(['\n', '\r']);
        if text.trim().is_empty() {
            return Err(Error::Glove(format!("glove csv header: missing; expected t, {} and optionally the tracker and hand columns", table.layout().names())));
        }
        let header = Header::parse(text, table)?;
        Ok(Self { input, header, default_side, line, line_number: 1, finished: false })
    }

    /// Reads the next row into `out`; `None` at the end of the input.
    ///
    /// A bad row gives a [`Rejection`] whose message starts with `line N:` and leaves `out`
    /// unchanged; the next call reads on. Kinds: [`RejectKind::ColumnCount`] for another
    /// number of columns than the header, [`RejectKind::Malformed`] for a last line cut
    /// short (no newline, too few columns), an empty field, a value that is not a number
    /// or a `hand` that is not `left`/`right`, [`RejectKind::NonFinite`],
    /// [`RejectKind::OutOfRange`] for a raw value outside 0–4095, a negative time or a
    /// quaternion far from unit length. An input error is reported once as
    /// [`RejectKind::Malformed`] and ends the reading. Allocates nothing for a good row.
    pub fn next_record(&mut self, out: &mut Record) -> Option<Result<(), Rejection>> {
        while !self.finished {
            self.line.clear();
            let read = self.input.read_until(b'\n', &mut self.line);
            self.line_number += 1;
            let row = match read {
                Ok(0) => {
                    self.finished = true;
                    return None;
                }
                Err(e) => {
                    self.finished = true;
                    Err(Rejection::new(RejectKind::Malformed, format!("read failed: {e}")))
                }
                Ok(_) => match std::str::from_utf8(&self.line) {
                    Err(_) => Err(Rejection::new(RejectKind::Malformed, "not UTF-8 text")),
                    Ok(text) => {
                        let terminated = text.ends_with('\n');
                        let text = text.trim_end_matches(['\n', '\r']);
                        if text.trim().is_empty() {
                            continue;
                        }
                        self.header.parse_row(text, terminated, self.default_side, out)
                    }
                },
            };
            return Some(row.map_err(|r| r.at(format!("line {}", self.line_number))));
        }
        None
    }
}

impl Header {
    fn parse(text: &str, table: &MappingTable) -> Result<Self> {
        let layout = table.layout();
        let mut columns = Vec::new();
        let mut unknown = Vec::new();
        let names: Vec<&str> = text.split(',').map(str::trim).collect();
        for (i, &name) in names.iter().enumerate() {
            if names[..i].contains(&name) {
                return Err(Error::Glove(format!("glove csv header: column {name:?} appears twice")));
            }
            let column = match name {
                "t" => Column::Time,
                "hand" => Column::Hand,
                _ => match (layout.index_of(name), TRACKER_COLUMNS.iter().position(|c| *c == name)) {
                    (Some(s), _) => Column::Sensor(s),
                    (None, Some(k)) => Column::Tracker(k),
                    (None, None) => {
                        unknown.push(format!("{name:?}"));
                        continue;
                    }
                },
            };
            columns.push(column);
        }
        if !unknown.is_empty() {
            return Err(Error::Glove(format!(
                "glove csv header: unknown columns {}; valid: t, {}, {}, hand",
                unknown.join(", "),
                layout.names(),
                TRACKER_COLUMNS.join(", ")
            )));
        }
        if !names.contains(&"t") {
            return Err(Error::Glove("glove csv header: no time column t".into()));
        }
        let missing: Vec<&str> = layout.sensors().iter().map(|s| s.name.as_str()).filter(|s| !names.contains(s)).collect();
        if !missing.is_empty() {
            return Err(Error::Glove(format!("glove csv header: no column for sensors {} of glove {}", missing.join(", "), table.name())));
        }
        let tracker_missing: Vec<&str> = TRACKER_COLUMNS.into_iter().filter(|c| !names.contains(c)).collect();
        if !tracker_missing.is_empty() && tracker_missing.len() < TRACKER_COLUMNS.len() {
            return Err(Error::Glove(format!(
                "glove csv header: tracker columns {} missing; the tracker needs all of {} or none",
                tracker_missing.join(", "),
                TRACKER_COLUMNS.join(", ")
            )));
        }
        Ok(Self {
            columns,
            sensor_names: layout.sensors().iter().map(|s| s.name.clone()).collect(),
            has_tracker: tracker_missing.is_empty(),
        })
    }

    /// Parses one non-blank row (without its line end) into `out`, or leaves `out` alone.
    fn parse_row(&self, text: &str, terminated: bool, default_side: Side, out: &mut Record) -> Result<(), Rejection> {
        let count = text.split(',').count();
        let expected = self.columns.len();
        if count < expected && !terminated {
            return Err(Rejection::new(RejectKind::Malformed, format!("truncated: {count} of {expected} columns and no line end")));
        }
        if count != expected {
            return Err(Rejection::new(RejectKind::ColumnCount, format!("{count} columns; the header has {expected}")));
        }
        let mut time = 0.0;
        let mut values = [0.0; MAX_GLOVE_SENSORS];
        let mut tracker = [0.0; TRACKER_COLUMNS.len()];
        let mut side = default_side;
        for (field, column) in text.split(',').map(str::trim).zip(&self.columns) {
            match *column {
                Column::Time => {
                    time = number(field, "t")?;
                    check_time(time)?;
                }
                Column::Sensor(i) => {
                    let name = &self.sensor_names[i];
                    values[i] = number(field, name)?;
                    check_raw(name, values[i])?;
                }
                Column::Tracker(k) => tracker[k] = number(field, TRACKER_COLUMNS[k])?,
                Column::Hand => {
                    side = match field {
                        "left" => Side::Left,
                        "right" => Side::Right,
                        _ => return Err(Rejection::new(RejectKind::Malformed, format!("hand {field:?} is not left or right"))),
                    }
                }
            }
        }
        let tracker = if self.has_tracker { Some(tracker_pose(tracker)?) } else { None };
        *out = Record {
            time,
            side,
            hand: Some(HandData::Glove(GloveSample::new(&values[..self.sensor_names.len()]))),
            tracker,
            arrival: None,
        };
        Ok(())
    }
}

/// Parses column `name`'s `field` (trimmed).
fn number<T: core::str::FromStr>(field: &str, name: &str) -> Result<T, Rejection> {
    if field.is_empty() {
        return Err(Rejection::new(RejectKind::Malformed, format!("{name} is empty")));
    }
    field.parse().map_err(|_| Rejection::new(RejectKind::Malformed, format!("{name} {field:?} is not a number")))
}

/// Refuses a time that is not finite or negative.
fn check_time(time: f64) -> Result<(), Rejection> {
    if !time.is_finite() {
        return Err(Rejection::new(RejectKind::NonFinite, format!("t = {time} is not finite")));
    }
    if time < 0.0 {
        return Err(Rejection::new(RejectKind::OutOfRange, format!("t = {time} is negative")));
    }
    Ok(())
}

/// The tracker pose of `px, py, pz, qx, qy, qz, qw`, its quaternion made unit
/// ([`unit_as_read`]).
fn tracker_pose(v: [f32; 7]) -> Result<RigidPose, Rejection> {
    if let Some(k) = v.iter().position(|x| !x.is_finite()) {
        return Err(Rejection::new(RejectKind::NonFinite, format!("{} = {} is not finite", TRACKER_COLUMNS[k], v[k])));
    }
    let q = Quat::from_xyzw(v[3], v[4], v[5], v[6]);
    let length = q.length();
    if (length - 1.0).abs() > QUAT_LENGTH_TOLERANCE {
        return Err(Rejection::new(RejectKind::OutOfRange, format!("tracker quaternion {:?} has length {length}, not 1", q.to_array())));
    }
    Ok(RigidPose { position: Vec3::new(v[0], v[1], v[2]), orientation: unit_as_read(q, length) })
}

/// Appends records to a glove CSV, one flushed row each, so a recording survives a crash
/// of the session that writes it; [`GloveCsvReader`] reads back exactly what was written.
#[derive(Debug)]
pub struct GloveCsvWriter<W: Write> {
    out: W,
    sensor_names: Vec<String>,
    tracker: bool,
    hand: bool,
    line: String,
}

impl<W: Write> GloveCsvWriter<W> {
    /// Writes the header for the glove of `table`: `t`, its sensors in layout order, the
    /// tracker columns when `tracker`, and `hand` when `hand` (without it, the reader gives
    /// every row its default side).
    ///
    /// # Errors
    /// Those of `out`.
    pub fn new(mut out: W, table: &MappingTable, tracker: bool, hand: bool) -> io::Result<Self> {
        let sensor_names: Vec<String> = table.layout().sensors().iter().map(|s| s.name.clone()).collect();
        let mut header = format!("t,{}", sensor_names.join(","));
        if tracker {
            header += ",";
            header += &TRACKER_COLUMNS.join(",");
        }
        if hand {
            header += ",hand";
        }
        header.push('\n');
        out.write_all(header.as_bytes())?;
        out.flush()?;
        Ok(Self { out, sensor_names, tracker, hand, line: String::new() })
    }

    /// Appends `record` as a row and flushes. Values are written in Rust's shortest
    /// round-trip form, so they read back bit for bit.
    ///
    /// # Errors
    /// [`io::ErrorKind::InvalidInput`] for a record the reader would refuse or the columns
    /// cannot hold: no glove sample or one of another glove, a tracker pose present or
    /// absent against the columns, a bad time, raw value or tracker pose (the message is
    /// the rejection's); otherwise those of the output.
    pub fn write(&mut self, record: &Record) -> io::Result<()> {
        use core::fmt::Write as _;
        let invalid = |message: String| io::Error::new(io::ErrorKind::InvalidInput, message);
        let Some(HandData::Glove(sample)) = &record.hand else {
            return Err(invalid("record has no glove sample".into()));
        };
        let values = sample.values();
        if values.len() != self.sensor_names.len() {
            return Err(invalid(format!("glove sample of {} values; the columns hold {}", values.len(), self.sensor_names.len())));
        }
        match (record.tracker.is_some(), self.tracker) {
            (true, false) => return Err(invalid("record has a tracker pose; the writer has no tracker columns".into())),
            (false, true) => return Err(invalid("record has no tracker pose; the writer's tracker columns need one".into())),
            _ => {}
        }
        check_time(record.time).map_err(|r| invalid(r.message))?;
        for (name, &v) in self.sensor_names.iter().zip(values) {
            check_raw(name, v).map_err(|r| invalid(r.message))?;
        }
        self.line.clear();
        // Writing into a String cannot fail.
        let _ = write!(self.line, "{}", record.time);
        for v in values {
            let _ = write!(self.line, ",{v}");
        }
        if let Some(pose) = record.tracker {
            let (p, q) = (pose.position, pose.orientation);
            let v = [p.x, p.y, p.z, q.x, q.y, q.z, q.w];
            tracker_pose(v).map_err(|r| invalid(r.message))?;
            for x in v {
                let _ = write!(self.line, ",{x}");
            }
        }
        if self.hand {
            let _ = write!(self.line, ",{}", record.side.name());
        }
        self.line.push('\n');
        self.out.write_all(self.line.as_bytes())?;
        self.out.flush()
    }
}
