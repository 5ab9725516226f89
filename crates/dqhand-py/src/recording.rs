//! Recordings from Python: the JSON lines files `dqhand replay`, `listen` and the viewer read
//! and write (joints, landmarks, glove values, a wrist tracker), as NumPy arrays, through the
//! engine's own record reader and writer. A malformed line is the reader's one-line refusal
//! naming the file and line; what is written is read back by that reader before the file is
//! touched, so a refused array leaves no file the reader would choke on.

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use dqhand::glam::{Quat, Vec3};
use dqhand::input::json_record::{parse_message, write_record, JsonRecordReader};
use dqhand::input::{GloveSample, HandData, JointSet, MappingTable, Record, RigidPose, TrackedJoint, JOINT_COUNT, LANDMARK_COUNT};
use dqhand::kinematics::Side;
use numpy::{PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::side_of;
use crate::{numbers, to_py};

/// A glove's mapping table as the command line names it: a built-in name or a JSON file.
pub(crate) fn glove_table(name: &str) -> PyResult<MappingTable> {
    if MappingTable::BUILTIN.contains(&name) { MappingTable::builtin(name) } else { MappingTable::load(Path::new(name)) }.map_err(to_py)
}

/// The sensor names of `table`, in its order (what the JSON glove objects are keyed by).
pub(crate) fn sensors(table: &MappingTable) -> Vec<String> {
    table.layout().sensors().iter().map(|s| s.name.clone()).collect()
}

/// Every record of the JSON lines file `path`: the reader's refusal of a bad line is the
/// error (`<file>: line N: …`), where `dqhand replay` would count it and go on.
pub(crate) fn read_records(path: &Path, side: Side, sensors: Vec<String>) -> PyResult<Vec<Record>> {
    let file = File::open(path).map_err(|e| to_py(dqhand::Error::io(path)(e)))?;
    let mut reader = JsonRecordReader::new(BufReader::new(file), side, sensors);
    let mut record = Record { time: 0.0, side, hand: None, tracker: None, arrival: None };
    let mut records = Vec::new();
    while let Some(read) = reader.next_record(&mut record).map_err(|e| to_py(dqhand::Error::io(path)(e)))? {
        read.map_err(|rejection| PyValueError::new_err(format!("{}: {rejection}", path.display())))?;
        records.push(record);
    }
    Ok(records)
}

/// A float32 array of `shape` from `values` (row after row), NumPy's.
fn array<'py>(py: Python<'py>, values: Vec<f32>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    Ok(numpy::PyArray1::from_vec(py, values).reshape(shape.to_vec())?.into_any())
}

/// A recording (JSON lines, as `dqhand replay` reads) as a dict of arrays, one row per record:
/// `t` (T,) s, `side` (T,) "left"/"right" (`side` for records that do not say), and where any
/// record has them `arrival` (T,) s, `joints` (T, 25, 3) m with `joint_orientations` (T, 25, 4)
/// x y z w and `joint_radii` (T, 25) m, `landmarks` (T, 21, 3) m, `glove` (T, S) raw values of
/// the glove `glove_table`, `tracker_position` (T, 3) m and `tracker_orientation` (T, 4); NaN
/// where a record lacks it. A malformed line raises ValueError naming the file and line.
#[pyfunction]
#[pyo3(signature = (path, *, side = "right", glove_table = "5dt-14"))]
pub(crate) fn read_recording<'py>(py: Python<'py>, path: PathBuf, side: &str, glove_table: &str) -> PyResult<Bound<'py, PyDict>> {
    let side = side_of(side, "side")?;
    let table = self::glove_table(glove_table)?;
    let names = sensors(&table);
    let sensor_count = names.len();
    let records = py.detach(|| read_records(&path, side, names))?;
    let count = records.len();
    let out = PyDict::new(py);
    out.set_item("t", numpy::PyArray1::from_iter(py, records.iter().map(|r| r.time)))?;
    let numpy = py.import("numpy")?;
    out.set_item("side", numpy.call_method1("array", (records.iter().map(|r| r.side.name()).collect::<Vec<_>>(), "<U5"))?)?;
    if records.iter().any(|r| r.arrival.is_some()) {
        out.set_item("arrival", numpy::PyArray1::from_iter(py, records.iter().map(|r| r.arrival.unwrap_or(f64::NAN))))?;
    }
    let nan = f32::NAN;
    if records.iter().any(|r| matches!(r.hand, Some(HandData::Joints(_)))) {
        let (mut positions, mut orientations, mut radii) = (vec![nan; count * JOINT_COUNT * 3], vec![nan; count * JOINT_COUNT * 4], vec![nan; count * JOINT_COUNT]);
        for (b, r) in records.iter().enumerate() {
            let Some(HandData::Joints(set)) = &r.hand else { continue };
            for i in 0..JOINT_COUNT {
                let Some(j) = set.get(i) else { continue };
                let k = b * JOINT_COUNT + i;
                positions[3 * k..3 * k + 3].copy_from_slice(&j.position.to_array());
                if let Some(q) = j.orientation {
                    orientations[4 * k..4 * k + 4].copy_from_slice(&q.to_array());
                }
                radii[k] = j.radius;
            }
        }
        out.set_item("joints", array(py, positions, &[count, JOINT_COUNT, 3])?)?;
        out.set_item("joint_orientations", array(py, orientations, &[count, JOINT_COUNT, 4])?)?;
        out.set_item("joint_radii", array(py, radii, &[count, JOINT_COUNT])?)?;
    }
    if records.iter().any(|r| matches!(r.hand, Some(HandData::Landmarks(_)))) {
        let mut landmarks = vec![nan; count * LANDMARK_COUNT * 3];
        for (r, out) in records.iter().zip(landmarks.chunks_mut(LANDMARK_COUNT * 3)) {
            if let Some(HandData::Landmarks(points)) = &r.hand {
                out.copy_from_slice(points.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>().as_slice());
            }
        }
        out.set_item("landmarks", array(py, landmarks, &[count, LANDMARK_COUNT, 3])?)?;
    }
    if records.iter().any(|r| matches!(r.hand, Some(HandData::Glove(_)))) {
        let mut glove = vec![nan; count * sensor_count];
        for (r, out) in records.iter().zip(glove.chunks_mut(sensor_count.max(1))) {
            if let Some(HandData::Glove(sample)) = &r.hand {
                out.copy_from_slice(sample.values());
            }
        }
        out.set_item("glove", array(py, glove, &[count, sensor_count])?)?;
    }
    if records.iter().any(|r| r.tracker.is_some()) {
        let (mut position, mut orientation) = (vec![nan; count * 3], vec![nan; count * 4]);
        for (b, r) in records.iter().enumerate() {
            if let Some(t) = r.tracker {
                position[3 * b..3 * b + 3].copy_from_slice(&t.position.to_array());
                orientation[4 * b..4 * b + 4].copy_from_slice(&t.orientation.to_array());
            }
        }
        out.set_item("tracker_position", array(py, position, &[count, 3])?)?;
        out.set_item("tracker_orientation", array(py, orientation, &[count, 4])?)?;
    }
    Ok(out)
}

/// The arrays `write_recording` takes, checked, as the threads read them: one row per record.
struct Columns<'a> {
    t: &'a [f64],
    sides: Vec<Side>,
    joints: Option<&'a [f64]>,
    orientations: Option<&'a [f64]>,
    radii: Option<&'a [f64]>,
    landmarks: Option<&'a [f64]>,
    glove: Option<&'a [f64]>,
    tracker: Option<(&'a [f64], &'a [f64])>,
    arrival: Option<&'a [f64]>,
}

/// Row `b` of an optional (T, `width`) array, as f32.
fn row(array: Option<&[f64]>, b: usize, width: usize) -> Option<Vec<f32>> {
    array.map(|a| a[b * width..(b + 1) * width].iter().map(|&x| x as f32).collect())
}

impl Columns<'_> {
    /// Record `b`.
    fn record(&self, b: usize, sensor_count: usize) -> Record {
        let hand = if let Some(p) = row(self.joints, b, 3 * JOINT_COUNT) {
            let q = row(self.orientations, b, 4 * JOINT_COUNT);
            let r = row(self.radii, b, JOINT_COUNT);
            let mut set = JointSet::new();
            for i in 0..JOINT_COUNT {
                let orientation = q.as_ref().map(|q| Quat::from_slice(&q[4 * i..]));
                let radius = r.as_ref().map_or(0.0, |r| r[i]);
                set.set(i, TrackedJoint { position: Vec3::from_slice(&p[3 * i..]), orientation, radius });
            }
            Some(HandData::Joints(set))
        } else if let Some(l) = row(self.landmarks, b, 3 * LANDMARK_COUNT) {
            Some(HandData::Landmarks(core::array::from_fn(|i| Vec3::from_slice(&l[3 * i..]))))
        } else {
            row(self.glove, b, sensor_count).map(|g| HandData::Glove(GloveSample::new(&g)))
        };
        let tracker = self.tracker.map(|(p, q)| {
            let (p, q) = (row(Some(p), b, 3).expect("given"), row(Some(q), b, 4).expect("given"));
            RigidPose { position: Vec3::from_slice(&p), orientation: Quat::from_slice(&q) }
        });
        Record { time: self.t[b], side: self.sides[b], hand, tracker, arrival: self.arrival.map(|a| a[b]) }
    }
}

/// The sides of `count` records: one side for all, or one per record.
pub(crate) fn sides(side: &Bound<'_, PyAny>, count: usize) -> PyResult<Vec<Side>> {
    if let Ok(one) = side.cast::<PyString>() {
        return Ok(vec![side_of(&one.to_cow()?, "side")?; count]);
    }
    let each: Vec<String> = side.extract().map_err(|_| PyValueError::new_err("side: expected \"right\", \"left\" or a sequence of them, one per record"))?;
    if each.len() != count {
        return Err(PyValueError::new_err(format!("side: {} sides for {count} records", each.len())));
    }
    each.iter().enumerate().map(|(b, s)| side_of(s, &format!("side[{b}]"))).collect()
}

/// `write_recording`'s arguments, as Python passes them.
struct WriteArgs<'a, 'py> {
    t: &'a Bound<'py, PyAny>,
    joints: Option<&'a Bound<'py, PyAny>>,
    joint_orientations: Option<&'a Bound<'py, PyAny>>,
    joint_radii: Option<&'a Bound<'py, PyAny>>,
    landmarks: Option<&'a Bound<'py, PyAny>>,
    glove: Option<&'a Bound<'py, PyAny>>,
    tracker_position: Option<&'a Bound<'py, PyAny>>,
    tracker_orientation: Option<&'a Bound<'py, PyAny>>,
    side: &'a Bound<'py, PyAny>,
    arrival: Option<&'a Bound<'py, PyAny>>,
    glove_table: &'a str,
}

/// Writes a recording that `dqhand replay` and `read_recording` read: one record per row of
/// `t` (T,) s, each carrying the arrays given (at most one of `joints` (T, 25, 3) m, with
/// `joint_orientations` (T, 25, 4) x y z w and `joint_radii` (T, 25) m if known, `landmarks`
/// (T, 21, 3) m or `glove` (T, S) raw values of the glove `glove_table`; and/or
/// `tracker_position` (T, 3) m with `tracker_orientation` (T, 4)); `side` one side or one per
/// record; `arrival` (T,) s a live input's clock. Each record is read back by the engine's
/// reader before the file is written (its refusal, naming the record, is a ValueError).
#[pyfunction]
#[pyo3(signature = (path, t, *, joints = None, joint_orientations = None, joint_radii = None, landmarks = None, glove = None, tracker_position = None, tracker_orientation = None, side = None, arrival = None, glove_table = "5dt-14"))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_recording<'py>(
    py: Python<'py>,
    path: PathBuf,
    t: &Bound<'py, PyAny>,
    joints: Option<&Bound<'py, PyAny>>,
    joint_orientations: Option<&Bound<'py, PyAny>>,
    joint_radii: Option<&Bound<'py, PyAny>>,
    landmarks: Option<&Bound<'py, PyAny>>,
    glove: Option<&Bound<'py, PyAny>>,
    tracker_position: Option<&Bound<'py, PyAny>>,
    tracker_orientation: Option<&Bound<'py, PyAny>>,
    side: Option<&Bound<'py, PyAny>>,
    arrival: Option<&Bound<'py, PyAny>>,
    glove_table: &str,
) -> PyResult<()> {
    let right = PyString::new(py, "right").into_any();
    let side = side.filter(|s| !s.is_none()).unwrap_or(&right);
    let args = WriteArgs { t, joints, joint_orientations, joint_radii, landmarks, glove, tracker_position, tracker_orientation, side, arrival, glove_table };
    write(py, path, &args)
}

/// [`write_recording`]: every record written by the engine's writer and read back by its
/// reader before the file is written at once.
fn write<'py>(py: Python<'py>, path: PathBuf, args: &WriteArgs<'_, 'py>) -> PyResult<()> {
    let given = |a: Option<&Bound<'py, PyAny>>| a.filter(|a| !a.is_none()).cloned();
    let t = numbers(args.t, "t", &[None], "capture times, seconds")?;
    let count = t.shape()[0];
    let (joints, landmarks, glove) = (given(args.joints), given(args.landmarks), given(args.glove));
    if usize::from(joints.is_some()) + usize::from(landmarks.is_some()) + usize::from(glove.is_some()) > 1 {
        return Err(PyValueError::new_err("joints, landmarks, glove: a record carries one of them; give at most one"));
    }
    if joints.is_none() && (given(args.joint_orientations).is_some() || given(args.joint_radii).is_some()) {
        return Err(PyValueError::new_err("joint_orientations, joint_radii: only with joints"));
    }
    let table = glove_table(args.glove_table)?;
    let names = sensors(&table);
    let n = Some(count);
    let check = |a: Option<Bound<'py, PyAny>>, name: &str, rest: &[usize], what: &str| -> PyResult<Option<PyReadonlyArrayDyn<'py, f64>>> {
        let shape: Vec<Option<usize>> = std::iter::once(n).chain(rest.iter().map(|&s| Some(s))).collect();
        a.map(|a| numbers(&a, name, &shape, what)).transpose()
    };
    let tracker = match (given(args.tracker_position), given(args.tracker_orientation)) {
        (Some(p), Some(q)) => Some((
            check(Some(p), "tracker_position", &[3], "the wrist tracker's position per record, m")?.expect("given"),
            check(Some(q), "tracker_orientation", &[4], "the wrist tracker's orientation per record, a unit quaternion x y z w")?.expect("given"),
        )),
        (None, None) => None,
        _ => return Err(PyValueError::new_err("tracker_position, tracker_orientation: give both or neither")),
    };
    if joints.is_none() && landmarks.is_none() && glove.is_none() && tracker.is_none() {
        return Err(PyValueError::new_err("joints, landmarks, glove, tracker_position: a record needs one of them"));
    }
    let (joints, orientations, radii) = (
        check(joints, "joints", &[JOINT_COUNT, 3], "the 25 WebXR joints' positions per record, m")?,
        check(given(args.joint_orientations), "joint_orientations", &[JOINT_COUNT, 4], "each joint's orientation per record, a unit quaternion x y z w")?,
        check(given(args.joint_radii), "joint_radii", &[JOINT_COUNT], "each joint's radius per record, m")?,
    );
    let landmarks = check(landmarks, "landmarks", &[LANDMARK_COUNT, 3], "MediaPipe's 21 landmarks per record, m")?;
    let glove = check(glove, "glove", &[names.len()], &format!("the {} glove's raw sensor values per record, in its order", table.name()))?;
    let arrival = check(given(args.arrival), "arrival", &[], "the live input's arrival time per record, seconds")?;
    fn slice<'a>(a: &'a Option<PyReadonlyArrayDyn<'_, f64>>) -> Option<&'a [f64]> {
        a.as_ref().map(|a| a.as_slice().expect("contiguous"))
    }
    let columns = Columns {
        t: t.as_slice().expect("contiguous"),
        sides: sides(args.side, count)?,
        joints: slice(&joints),
        orientations: slice(&orientations),
        radii: slice(&radii),
        landmarks: slice(&landmarks),
        glove: slice(&glove),
        tracker: tracker.as_ref().map(|(p, q)| (p.as_slice().expect("contiguous"), q.as_slice().expect("contiguous"))),
        arrival: slice(&arrival),
    };
    let text = py.detach(|| -> Result<Vec<u8>, String> {
        let (mut text, mut line) = (Vec::new(), Vec::new());
        let mut back = Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None };
        for b in 0..count {
            line.clear();
            write_record(&mut line, &columns.record(b, names.len()), &names).expect("writing to memory cannot fail");
            parse_message(&line, Side::Right, &names, &mut back).map_err(|rejection| format!("record {b}: {rejection}"))?;
            text.extend_from_slice(&line);
        }
        Ok(text)
    });
    let text = text.map_err(PyValueError::new_err)?;
    py.detach(|| std::fs::write(&path, text)).map_err(|e| to_py(dqhand::Error::io(&path)(e)))
}
