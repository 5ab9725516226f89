//! Gestures from Python: the engine's recogniser over a recording (the gesture loop
//! `dqhand replay --gestures` runs: read, filter, retarget, pose, features, recognise), over
//! tracked points in arrays (the same loop, records made from the arrays), or over joint
//! angles (the recogniser on this hand posed by them: no tracker, so nothing to retarget or
//! filter); and the gesture library's template poses.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use dqhand::gesture::{EventKind, GestureSet, HandFeatures, Recognizer};
use dqhand::glam::Vec3;
use dqhand::input::{rest_side, HandData, InputConfig, JointSet, Record, TrackedJoint, JOINT_COUNT, LANDMARK_COUNT};
use dqhand::interaction::GestureLoop;
use dqhand::kinematics::JointPositions;
use numpy::PyReadonlyArrayDyn;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::side_of;
use crate::recording::{glove_table, read_records, sensors, sides};
use crate::{numbers, to_py, Hand, PoseSource};

/// One gesture event: its time (s), `"start"` or `"end"`, the gesture's name.
pub(crate) type Event = (f64, &'static str, String);

/// The definitions of `gestures` (a file from `dqhand train-gestures` or `learn-gesture`),
/// else the built-in ones.
pub(crate) fn gesture_set(gestures: Option<&Path>) -> PyResult<GestureSet> {
    gestures.map_or_else(|| Ok(GestureSet::builtin()), |path| GestureSet::load(path).map_err(to_py))
}

/// The input configuration of the file `config`, else the default one.
fn input_config(config: Option<&Path>) -> PyResult<InputConfig> {
    config.map_or_else(|| Ok(InputConfig::default()), |path| InputConfig::load(path).map_err(to_py))
}

/// The gestures the recogniser reports, in its set's order: the built-in definitions, or
/// those of the file `gestures` (from `dqhand train-gestures` or `learn-gesture`). The
/// built-in set has the library's shapes (`Hand.gesture_poses`) and `thumbs_down`.
#[pyfunction]
#[pyo3(signature = (gestures = None))]
pub(crate) fn gesture_names(gestures: Option<PathBuf>) -> PyResult<Vec<String>> {
    Ok(gesture_set(gestures.as_deref())?.gestures().iter().map(|g| g.name().to_owned()).collect())
}

/// The events of one update, owned.
fn owned<'a>(events: impl Iterator<Item = dqhand::gesture::Event<'a>>, out: &mut Vec<Event>) {
    out.extend(events.map(|e| (e.t, if e.event == EventKind::Start { "start" } else { "end" }, e.gesture.to_owned())));
}

/// `records` through a gesture loop of `hand` as `dqhand replay` plays a file: a record the
/// pipeline refuses (out of order, too fast, no palm) is counted and skipped.
fn through_loop(hand: &Hand, config: InputConfig, set: GestureSet, records: impl Iterator<Item = Record>) -> PyResult<Vec<Event>> {
    let mut gesture_loop = GestureLoop::new(Arc::clone(&hand.model), hand.joint_model, None, config, Some(set)).map_err(to_py)?;
    let mut events = Vec::new();
    for record in records {
        if let Ok(e) = gesture_loop.push(&record) {
            owned(e, &mut events);
        }
    }
    Ok(events)
}

/// `Hand.recognize_recording`.
pub(crate) fn of_recording(hand: &Hand, py: Python<'_>, path: PathBuf, side: &str, gestures: Option<PathBuf>, config: Option<PathBuf>, glove_table_name: &str) -> PyResult<Vec<Event>> {
    let side = side_of(side, "side")?;
    let (set, config) = (gesture_set(gestures.as_deref())?, input_config(config.as_deref())?);
    let names = sensors(&glove_table(glove_table_name)?);
    py.detach(|| {
        let records = read_records(&path, side, names)?;
        through_loop(hand, config, set, records.into_iter())
    })
}

/// `Hand.recognize`'s arguments, as Python passes them.
pub(crate) struct RecognizeArgs<'a, 'py> {
    pub times: &'a Bound<'py, PyAny>,
    pub angles: Option<&'a Bound<'py, PyAny>>,
    pub wrist: Option<&'a Bound<'py, PyAny>>,
    pub landmarks: Option<&'a Bound<'py, PyAny>>,
    pub joints: Option<&'a Bound<'py, PyAny>>,
    pub side: Option<&'a Bound<'py, PyAny>>,
    pub gestures: Option<PathBuf>,
    pub config: Option<PathBuf>,
    pub limits: bool,
}

/// `Hand.recognize`: the times checked (not negative), then points through the gesture loop,
/// or angles straight to the recogniser.
pub(crate) fn of_arrays<'py>(hand: &Hand, py: Python<'py>, args: &RecognizeArgs<'_, 'py>) -> PyResult<Vec<Event>> {
    let times = numbers(args.times, "times", &[None], "each record's time, seconds")?;
    let t = times.as_slice().expect("contiguous");
    if let Some(b) = t.iter().position(|&x| x < 0.0) {
        return Err(PyValueError::new_err(format!("times[{b}]: {} is negative", t[b])));
    }
    let given = [args.angles, args.landmarks, args.joints].map(|a| a.filter(|a| !a.is_none()));
    if given.iter().flatten().count() != 1 {
        return Err(PyValueError::new_err("angles, landmarks, joints: give exactly one"));
    }
    let set = gesture_set(args.gestures.as_deref())?;
    let count = Some(t.len());
    if let Some(angles) = given[0] {
        if args.side.is_some_and(|s| !s.is_none()) || args.config.is_some() {
            return Err(PyValueError::new_err("side, config: for landmarks or joints (angles pose this hand itself)"));
        }
        let poses = hand.batch_of(angles, args.wrist)?;
        if poses.count != t.len() {
            return Err(PyValueError::new_err(format!("angles: {} poses for {} times", poses.count, t.len())));
        }
        let (source, limits) = (poses.source(), args.limits);
        return py.detach(|| recognize_angles(hand, t, source, set, limits));
    }
    if args.wrist.is_some_and(|w| !w.is_none()) {
        return Err(PyValueError::new_err("wrist: for angles (tracked points carry their own wrist)"));
    }
    let config = input_config(args.config.as_deref())?;
    let sides = match args.side.filter(|s| !s.is_none()) {
        Some(side) => sides(side, t.len())?,
        None => vec![rest_side(hand.kinematics.skeleton()).map_err(to_py)?; t.len()],
    };
    let landmarks = given[1].is_some();
    let (name, width, what) = if landmarks { ("landmarks", LANDMARK_COUNT, "MediaPipe's 21 landmarks per record, m") } else { ("joints", JOINT_COUNT, "the 25 WebXR joints per record, m") };
    let points: PyReadonlyArrayDyn<'_, f64> = numbers(given[1].or(given[2]).expect("one is given"), name, &[count, Some(width), Some(3)], what)?;
    let p = points.as_slice().expect("contiguous");
    py.detach(|| {
        let records = t.iter().zip(&sides).enumerate().map(|(b, (&time, &side))| {
            let point = |i: usize| {
                let x = &p[3 * (b * width + i)..];
                Vec3::new(x[0] as f32, x[1] as f32, x[2] as f32)
            };
            let hand = if landmarks {
                HandData::Landmarks(core::array::from_fn::<_, LANDMARK_COUNT, _>(point))
            } else {
                let mut set = JointSet::new();
                for i in 0..JOINT_COUNT {
                    set.set(i, TrackedJoint { position: point(i), orientation: None, radius: 0.0 });
                }
                HandData::Joints(set)
            };
            Record { time, side, hand: Some(hand), tracker: None, arrival: None }
        });
        through_loop(hand, config, set, records)
    })
}

/// The recogniser on this hand posed by each of `poses` at its time: the features the
/// gesture loop reads of its virtual hand, of these poses.
fn recognize_angles(hand: &Hand, times: &[f64], poses: PoseSource<'_>, set: GestureSet, limits: bool) -> PyResult<Vec<Event>> {
    let (mut kinematics, mut pose) = hand.kinematics(limits);
    let joints = JointPositions::new(kinematics.skeleton()).map_err(to_py)?;
    let side = rest_side(kinematics.skeleton()).map_err(to_py)?;
    let mut recognizer = Recognizer::new(set);
    let mut events = Vec::new();
    for (b, &t) in times.iter().enumerate() {
        kinematics.pose(poses.read(b, &mut pose));
        let features = HandFeatures::from_positions(&joints.read(kinematics.world()), side);
        owned(recognizer.update(t, &features), &mut events);
    }
    Ok(events)
}
