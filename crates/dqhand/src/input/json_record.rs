//! Records as JSON, one object per line (recordings, `.jsonl`) or per message (UDP datagrams,
//! WebSocket messages): the joints format of the hand-tracking sources, and the same object
//! carrying glove values or a tracker pose for live gloves.
//!
//! ```json
//! {"t": 0.016, "hand": "right", "joints": {"wrist": {"p": [0, 1.1, -0.3], "q": [0, 0, 0, 1], "r": 0.02}, …}}
//! {"t": 0.016, "hand": "left", "landmarks": [[0.01, -0.02, 0.03], … 21 points]}
//! {"t": 0.016, "glove": {"thumb_near": 1210, …}, "tracker": {"p": [0, 1, 0], "q": [0, 0, 0, 1]}}
//! ```
//!
//! * `t` seconds; `hand` `"left"` or `"right"` (default: the reader's side);
//! * `joints`: an object keyed by WebXR joint names (or OpenXR `XR_HAND_JOINT_*_EXT` names,
//!   the palm ignored), or an array of 25 joints in WebXR order or 26 in OpenXR order; each
//!   joint `p` position (m), optional `q` orientation `[x, y, z, w]`, optional `r` radius (m);
//!   all 25 joints are needed;
//! * `landmarks`: 21 positions in MediaPipe's order (m);
//! * `glove`: raw sensor values keyed by the glove's sensor names, or an array in its order;
//! * `tracker`: the wrist tracker's pose, `p` and `q`;
//! * `arrival`: written by live recordings, when the live input took the record (seconds on
//!   its clock), so a replay judges lateness and loss of tracking as it did
//!   ([`Record::arrival`]);
//! * at most one of `joints`, `landmarks`, `glove`; glTF axes (+Y up).
//!
//! Parsing checks syntax and names; it borrows the line's strings (no copies) and writes into
//! a caller's [`Record`].

use std::borrow::Cow;
use std::fmt;
use std::io::{BufRead, Read, Write};
use std::marker::PhantomData;

use glam::{Quat, Vec3};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;

use super::record::{unit_as_read, JOINT_COUNT, LANDMARK_COUNT, MAX_GLOVE_SENSORS};
use super::{openxr, GloveSample, HandData, JointSet, RejectKind, Rejection, Record, RigidPose, TrackedJoint};
use crate::kinematics::Side;
use crate::kinematics::webxr;

/// Longest line or message accepted, bytes (a 25-joint record with orientations is ~3 KiB).
pub const MAX_RECORD_BYTES: usize = 16 * 1024;
/// Farthest a position may be from the origin, metres: beyond it the record is out of range.
pub const MAX_DISTANCE: f32 = 100.0;
/// How far a quaternion's length may be from 1 before it is refused rather than normalised.
const UNIT_TOLERANCE: f32 = 0.1;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Line<'a> {
    t: f64,
    #[serde(default, borrow)]
    hand: Option<Name<'a>>,
    #[serde(default, borrow)]
    joints: Option<Entries<'a, JointJson, 26>>,
    #[serde(default)]
    landmarks: Option<[[f32; 3]; LANDMARK_COUNT]>,
    #[serde(default, borrow)]
    glove: Option<Entries<'a, f32, MAX_GLOVE_SENSORS>>,
    #[serde(default)]
    tracker: Option<PoseJson>,
    #[serde(default)]
    arrival: Option<f64>,
}

#[derive(Clone, Copy, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct JointJson {
    p: [f32; 3],
    #[serde(default)]
    q: Option<[f32; 4]>,
    #[serde(default)]
    r: Option<f32>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
struct PoseJson {
    p: [f32; 3],
    q: [f32; 4],
}

/// A key borrowed from the line (serde's `Cow<str>` would copy every one); owned only when
/// the key had escapes.
struct Name<'a>(Cow<'a, str>);

impl<'de: 'a, 'a> Deserialize<'de> for Name<'a> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct NameVisitor;
        impl<'de> Visitor<'de> for NameVisitor {
            type Value = Cow<'de, str>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a name")
            }
            fn visit_borrowed_str<E: de::Error>(self, v: &'de str) -> Result<Self::Value, E> {
                Ok(Cow::Borrowed(v))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
                Ok(Cow::Owned(v.to_owned()))
            }
        }
        deserializer.deserialize_str(NameVisitor).map(Name)
    }
}

/// Up to `N` values, keyed by name (a JSON object) or in order (an array), kept on the stack.
struct Entries<'a, V, const N: usize> {
    names: [Option<Cow<'a, str>>; N],
    values: [V; N],
    len: usize,
}

impl<'a, V: Copy + Default, const N: usize> Entries<'a, V, N> {
    fn new() -> Self {
        Self { names: core::array::from_fn(|_| None), values: [V::default(); N], len: 0 }
    }

    fn push<E: de::Error>(&mut self, name: Option<Cow<'a, str>>, value: V) -> Result<(), E> {
        if self.len == N {
            return Err(E::custom(format_args!("more than {N} entries")));
        }
        (self.names[self.len], self.values[self.len]) = (name, value);
        self.len += 1;
        Ok(())
    }

    fn iter(&self) -> impl Iterator<Item = (Option<&str>, V)> + '_ {
        self.names[..self.len].iter().map(Option::as_deref).zip(self.values[..self.len].iter().copied())
    }

    fn is_named(&self) -> bool {
        self.names[..self.len].iter().any(Option::is_some)
    }
}

impl<'de: 'a, 'a, V: Deserialize<'de> + Copy + Default, const N: usize> Deserialize<'de> for Entries<'a, V, N> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct EntriesVisitor<'a, V, const N: usize>(PhantomData<(&'a (), V)>);
        impl<'de: 'a, 'a, V: Deserialize<'de> + Copy + Default, const N: usize> Visitor<'de> for EntriesVisitor<'a, V, N> {
            type Value = Entries<'a, V, N>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "an object keyed by name or an array of at most {N} entries")
            }
            fn visit_map<M: MapAccess<'de>>(self, mut map: M) -> Result<Self::Value, M::Error> {
                let mut out = Entries::new();
                while let Some(Name(name)) = map.next_key()? {
                    let value = map.next_value()?;
                    out.push(Some(name), value)?;
                }
                Ok(out)
            }
            fn visit_seq<S: SeqAccess<'de>>(self, mut seq: S) -> Result<Self::Value, S::Error> {
                let mut out = Entries::new();
                while let Some(value) = seq.next_element()? {
                    out.push(None, value)?;
                }
                Ok(out)
            }
        }
        deserializer.deserialize_any(EntriesVisitor(PhantomData))
    }
}

/// Parses one record received as bytes (a UDP datagram, a WebSocket message, a line of a
/// file): UTF-8 text, surrounding whitespace ignored, then as [`parse_record`].
///
/// # Errors
/// As [`parse_record`]; `TooLarge` beyond [`MAX_RECORD_BYTES`], `Malformed` if not UTF-8.
pub fn parse_message<S: AsRef<str>>(bytes: &[u8], default_side: Side, glove_sensors: &[S], out: &mut Record) -> Result<(), Rejection> {
    let bytes = bytes.trim_ascii();
    if bytes.len() > MAX_RECORD_BYTES {
        return Err(Rejection::new(RejectKind::TooLarge, format!("record of {} bytes (at most {MAX_RECORD_BYTES})", bytes.len())));
    }
    let text = std::str::from_utf8(bytes).map_err(|_| Rejection::new(RejectKind::Malformed, "not UTF-8 text"))?;
    parse_record(text.trim(), default_side, glove_sensors, out)
}

/// Parses one JSON record into `out`.
///
/// * `default_side` — the hand when the record does not say;
/// * `glove_sensors` — the sensor names of the glove in use, in its order (empty: no glove;
///   a glove record is then refused).
///
/// # Errors
/// A [`Rejection`] of the kind of problem: `Malformed` (JSON, missing joints, two finger
/// sources), `UnknownName` (joint, sensor, side), `ColumnCount` (array lengths), `NonFinite`,
/// `OutOfRange` (negative time, far positions, quaternions far from unit length).
pub fn parse_record<S: AsRef<str>>(line: &str, default_side: Side, glove_sensors: &[S], out: &mut Record) -> Result<(), Rejection> {
    if line.len() > MAX_RECORD_BYTES {
        return Err(Rejection::new(RejectKind::TooLarge, format!("record of {} bytes (at most {MAX_RECORD_BYTES})", line.len())));
    }
    let parsed: Line = serde_json::from_str(line).map_err(|e| {
        let what = if e.is_eof() { "truncated record" } else { "malformed record" };
        Rejection::new(RejectKind::Malformed, format!("{what}: {e}"))
    })?;
    let time = seconds("t", parsed.t)?;
    let arrival = parsed.arrival.map(|a| seconds("arrival", a)).transpose()?;
    let side = match parsed.hand.as_ref().map(|h| h.0.as_ref()) {
        None => default_side,
        Some("left") => Side::Left,
        Some("right") => Side::Right,
        Some(other) => return Err(Rejection::new(RejectKind::UnknownName, format!("hand: {other:?} is neither \"left\" nor \"right\""))),
    };
    let sources = usize::from(parsed.joints.is_some()) + usize::from(parsed.landmarks.is_some()) + usize::from(parsed.glove.is_some());
    if sources > 1 {
        return Err(Rejection::new(RejectKind::Malformed, "a record carries one of joints, landmarks, glove"));
    }
    let hand = if let Some(joints) = &parsed.joints {
        Some(HandData::Joints(joint_set(joints)?))
    } else if let Some(landmarks) = &parsed.landmarks {
        let mut points = [Vec3::ZERO; LANDMARK_COUNT];
        for (i, (p, l)) in points.iter_mut().zip(landmarks).enumerate() {
            *p = position(*l, || format!("landmark {i}"))?;
        }
        Some(HandData::Landmarks(points))
    } else if let Some(glove) = &parsed.glove {
        Some(HandData::Glove(glove_sample(glove, glove_sensors)?))
    } else {
        None
    };
    let tracker = match parsed.tracker {
        Some(t) => Some(RigidPose { position: position(t.p, || "tracker".into())?, orientation: orientation(t.q, || "tracker".into())? }),
        None => None,
    };
    if hand.is_none() && tracker.is_none() {
        return Err(Rejection::new(RejectKind::Malformed, "a record needs joints, landmarks, glove or tracker"));
    }
    *out = Record { time, side, hand, tracker, arrival };
    Ok(())
}

fn joint_set(joints: &Entries<JointJson, 26>) -> Result<JointSet, Rejection> {
    let mut set = JointSet::new();
    let named = joints.is_named();
    let order: fn(usize) -> Option<usize> = match (named, joints.len) {
        (true, _) => |_| None,
        (false, JOINT_COUNT) => Some,
        (false, 26) => openxr::webxr_index,
        (false, n) => {
            return Err(Rejection::new(RejectKind::ColumnCount, format!("joints: {n} entries; 25 in WebXR order or 26 in OpenXR order")))
        }
    };
    for (k, (name, j)) in joints.iter().enumerate() {
        let index = match name {
            Some(name) => match webxr::JOINT_NAMES.iter().position(|&n| n == name) {
                Some(i) => Some(i),
                None => match openxr::JOINT_NAMES.iter().position(|&n| n == name) {
                    Some(o) => openxr::webxr_index(o),
                    None => {
                        return Err(Rejection::new(RejectKind::UnknownName, format!("joints: unknown joint {name:?} (WebXR or OpenXR joint names)")))
                    }
                },
            },
            None => order(k),
        };
        let Some(i) = index else { continue };
        let label = || format!("joint {}", webxr::JOINT_NAMES[i]);
        let orientation = match j.q {
            Some(q) => Some(orientation(q, label)?),
            None => None,
        };
        let radius = j.r.unwrap_or(0.0);
        if !radius.is_finite() {
            return Err(Rejection::new(RejectKind::NonFinite, format!("{}: radius {radius}", label())));
        }
        set.set(i, TrackedJoint { position: position(j.p, label)?, orientation, radius });
    }
    if let Some(missing) = (0..JOINT_COUNT).find(|&i| set.get(i).is_none()) {
        return Err(Rejection::new(RejectKind::Malformed, format!("joints: {} is missing (all 25 are needed)", webxr::JOINT_NAMES[missing])));
    }
    Ok(set)
}

fn glove_sample<S: AsRef<str>>(glove: &Entries<f32, MAX_GLOVE_SENSORS>, sensors: &[S]) -> Result<GloveSample, Rejection> {
    if sensors.is_empty() {
        return Err(Rejection::new(RejectKind::Malformed, "glove: no glove is configured for this stream"));
    }
    let mut values = [f32::NAN; MAX_GLOVE_SENSORS];
    if glove.is_named() {
        for (name, v) in glove.iter() {
            let name = name.unwrap_or_default();
            let i = sensors.iter().position(|s| s.as_ref() == name).ok_or_else(|| {
                Rejection::new(RejectKind::UnknownName, format!("glove: unknown sensor {name:?}"))
            })?;
            values[i] = v;
        }
        if let Some(missing) = sensors.iter().zip(&values).find(|(_, v)| v.is_nan()) {
            return Err(Rejection::new(RejectKind::Malformed, format!("glove: sensor {:?} is missing", missing.0.as_ref())));
        }
    } else if glove.len == sensors.len() {
        for (v, (_, g)) in values.iter_mut().zip(glove.iter()) {
            *v = g;
        }
    } else {
        return Err(Rejection::new(RejectKind::ColumnCount, format!("glove: {} values, the glove has {} sensors", glove.len, sensors.len())));
    }
    if let Some((s, v)) = sensors.iter().zip(&values).find(|(_, v)| !v.is_finite()) {
        return Err(Rejection::new(RejectKind::NonFinite, format!("glove: sensor {:?} is {v}", s.as_ref())));
    }
    Ok(GloveSample::new(&values[..sensors.len()]))
}

/// A time field: finite and not negative.
pub(super) fn seconds(field: &str, t: f64) -> Result<f64, Rejection> {
    if !t.is_finite() {
        return Err(Rejection::new(RejectKind::NonFinite, format!("{field}: {t} is not a finite time")));
    }
    if t < 0.0 {
        return Err(Rejection::new(RejectKind::OutOfRange, format!("{field}: {t} is negative")));
    }
    Ok(t)
}

/// A position: finite and within [`MAX_DISTANCE`] of the origin.
pub(super) fn position(p: [f32; 3], label: impl Fn() -> String) -> Result<Vec3, Rejection> {
    let v = Vec3::from(p);
    if !v.is_finite() {
        return Err(Rejection::new(RejectKind::NonFinite, format!("{}: position {p:?} is not finite", label())));
    }
    if v.length() > MAX_DISTANCE {
        return Err(Rejection::new(RejectKind::OutOfRange, format!("{}: position {p:?} is more than {MAX_DISTANCE} m away", label())));
    }
    Ok(v)
}

/// An orientation: finite and of about unit length (made unit).
pub(super) fn orientation(q: [f32; 4], label: impl Fn() -> String) -> Result<Quat, Rejection> {
    let v = Quat::from_array(q);
    if !v.is_finite() {
        return Err(Rejection::new(RejectKind::NonFinite, format!("{}: orientation {q:?} is not finite", label())));
    }
    let length = v.length();
    if (length - 1.0).abs() > UNIT_TOLERANCE {
        return Err(Rejection::new(RejectKind::OutOfRange, format!("{}: orientation {q:?} is not a unit quaternion", label())));
    }
    Ok(unit_as_read(v, length))
}

/// Writes `record` as one JSON line (joints keyed by WebXR name; glove keyed by
/// `glove_sensors`), the inverse of [`parse_record`].
///
/// # Errors
/// The writer's.
pub fn write_record<S: AsRef<str>>(out: &mut impl Write, record: &Record, glove_sensors: &[S]) -> std::io::Result<()> {
    use serde_json::{json, Map, Value};
    let mut object = Map::new();
    object.insert("t".into(), json!(record.time));
    object.insert("hand".into(), json!(record.side.name()));
    match &record.hand {
        Some(HandData::Joints(set)) => {
            let joints: Map<String, Value> = (0..JOINT_COUNT)
                .filter_map(|i| set.get(i).map(|j| (i, j)))
                .map(|(i, j)| {
                    let mut o = Map::new();
                    o.insert("p".into(), json!(j.position.to_array()));
                    if let Some(q) = j.orientation {
                        o.insert("q".into(), json!(q.to_array()));
                    }
                    if j.radius != 0.0 {
                        o.insert("r".into(), json!(j.radius));
                    }
                    (webxr::JOINT_NAMES[i].to_owned(), Value::Object(o))
                })
                .collect();
            object.insert("joints".into(), Value::Object(joints));
        }
        Some(HandData::Landmarks(points)) => {
            object.insert("landmarks".into(), json!(points.iter().map(|p| p.to_array()).collect::<Vec<_>>()));
        }
        Some(HandData::Glove(sample)) => {
            let glove: Map<String, Value> = glove_sensors.iter().zip(sample.values()).map(|(s, v)| (s.as_ref().to_owned(), json!(v))).collect();
            object.insert("glove".into(), Value::Object(glove));
        }
        None => {}
    }
    if let Some(t) = record.tracker {
        object.insert("tracker".into(), json!({ "p": t.position.to_array(), "q": t.orientation.to_array() }));
    }
    if let Some(a) = record.arrival {
        object.insert("arrival".into(), json!(a));
    }
    serde_json::to_writer(&mut *out, &Value::Object(object))?;
    out.write_all(b"\n")
}

/// Reads JSON records line by line from a file or pipe; each line is parsed on its own, so a
/// bad line is one rejection and the next line goes on.
pub struct JsonRecordReader<R> {
    reader: R,
    line: Vec<u8>,
    number: usize,
    default_side: Side,
    glove_sensors: Vec<String>,
}

impl<R: BufRead> JsonRecordReader<R> {
    /// A reader of `reader`; see [`parse_record`] for the arguments.
    pub fn new(reader: R, default_side: Side, glove_sensors: Vec<String>) -> Self {
        Self { reader, line: Vec::with_capacity(MAX_RECORD_BYTES + 1), number: 0, default_side, glove_sensors }
    }

    /// The next record into `out`: `None` at the end, else `Ok` or the line's rejection
    /// (`line N: …`). Blank lines are skipped.
    ///
    /// # Errors
    /// An I/O error of the underlying reader (not a bad record: those are rejections).
    pub fn next_record(&mut self, out: &mut Record) -> std::io::Result<Option<Result<(), Rejection>>> {
        loop {
            self.line.clear();
            let limit = MAX_RECORD_BYTES as u64 + 1;
            let read = (&mut self.reader).take(limit).read_until(b'\n', &mut self.line)?;
            if read == 0 {
                return Ok(None);
            }
            self.number += 1;
            let number = self.number; // named in a refusal only: a good line allocates nothing
            if self.line.len() as u64 >= limit && self.line.last() != Some(&b'\n') {
                let bytes = self.line.len() + skip_line(&mut self.reader)?;
                return Ok(Some(Err(Rejection::new(RejectKind::TooLarge, format!("line {number}: {bytes} bytes (at most {MAX_RECORD_BYTES})")))));
            }
            if std::str::from_utf8(&self.line).is_ok_and(|text| text.trim().is_empty()) {
                continue;
            }
            return Ok(Some(parse_message(&self.line, self.default_side, &self.glove_sensors, out).map_err(|r| r.at(format_args!("line {number}")))));
        }
    }
}

/// Consumes the rest of an over-long line without holding it; returns its length.
fn skip_line(reader: &mut impl BufRead) -> std::io::Result<usize> {
    let mut skipped = 0;
    loop {
        let buffer = reader.fill_buf()?;
        if buffer.is_empty() {
            return Ok(skipped);
        }
        match buffer.iter().position(|&b| b == b'\n') {
            Some(end) => {
                reader.consume(end + 1);
                return Ok(skipped + end + 1);
            }
            None => {
                let n = buffer.len();
                reader.consume(n);
                skipped += n;
            }
        }
    }
}
