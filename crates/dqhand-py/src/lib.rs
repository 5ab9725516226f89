//! dqhand in Python (`import dqhand`): a hand's mesh, joints and skin as NumPy arrays, in SI
//! units (metres, radians), the batch dimension first.
//!
//! A batch of poses is skinned on every core with the GIL released, each pose into its own slice
//! of the array that is returned (no copy after): per pose, one forward kinematics pass (the
//! paper's kinematics layer) and one deformation (its skin layer: LB, QB, DQB or CoR, Eq. 6–8).

use std::path::PathBuf;
use std::sync::Arc;

use dqhand::glam::{DMat3, DVec3, Quat, Vec3};
use dqhand::hand::{build, HandParams};
use dqhand::input::mediapipe::WEBXR_INDEX;
use dqhand::kinematics::{webxr::JOINT_NAMES, HandKinematics, JointModel, Limits, Pose, Side};
use dqhand::math::DualQuat;
use dqhand::model::Model;
use dqhand::skin::{Deformer, Method, SelfContactPass, VertexBuffers};
use numpy::{Element, PyArray, PyArray2, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyFileNotFoundError, PyIsADirectoryError, PyOSError, PyPermissionError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;

mod export;
mod fit;
mod gestures;
mod metrics;
mod grasp;
mod raster;
mod recording;

/// A library error as the Python exception for it, with the library's one-line message: an
/// operating system's refusal as the matching `OSError`, anything else as `ValueError`.
fn to_py(error: dqhand::Error) -> PyErr {
    let message = error.to_string();
    match &error {
        dqhand::Error::Io { reason, .. } => match reason.kind() {
            std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
            std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
            std::io::ErrorKind::IsADirectory => PyIsADirectoryError::new_err(message),
            _ => PyOSError::new_err(message),
        },
        _ => PyValueError::new_err(message),
    }
}

/// `"left"` or `"right"` (any case) as a side; the message names `argument`.
pub(crate) fn side_of(side: &str, argument: &str) -> PyResult<Side> {
    match side.to_ascii_lowercase().as_str() {
        "right" => Ok(Side::Right),
        "left" => Ok(Side::Left),
        _ => Err(PyValueError::new_err(format!("{argument}: {side:?} is not a side; use \"right\" or \"left\""))),
    }
}

/// `array` read by NumPy as a contiguous float64 array (`numpy.ascontiguousarray`: any
/// array-like, any numeric dtype, any layout), checked to have the shape `shape` (`None` for
/// the batch) and finite values. Messages name `argument` and the shape it must have.
fn numbers<'py>(array: &Bound<'py, PyAny>, argument: &str, shape: &[Option<usize>], what: &str) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    let wanted = shape.iter().map(|s| s.map_or("B".to_owned(), |n| n.to_string())).collect::<Vec<_>>().join(", ");
    let numpy = array.py().import("numpy")?;
    let converted = numpy.call_method1("ascontiguousarray", (array, "float64")).map_err(|e| PyValueError::new_err(format!("{argument}: expected numbers of shape ({wanted}) ({what}): {e}")))?;
    let converted = converted.cast_into::<PyArrayDyn<f64>>().map_err(PyErr::from)?.readonly();
    let got = converted.shape().to_vec();
    if got.len() != shape.len() || got.iter().zip(shape).any(|(g, s)| s.is_some_and(|s| s != *g)) {
        let got = got.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ");
        return Err(PyValueError::new_err(format!("{argument}: expected an array of shape ({wanted}) ({what}), got shape ({got})")));
    }
    let values = converted.as_slice().expect("ascontiguousarray's result is contiguous");
    // The library computes in float32: a finite float64 beyond its range would become infinite.
    if let Some(i) = values.iter().position(|x| !x.is_finite() || x.abs() > f64::from(f32::MAX)) {
        let per_item = got[1..].iter().product::<usize>().max(1);
        let problem = if values[i].is_finite() { "does not fit float32" } else { "is not finite" };
        return Err(PyValueError::new_err(format!("{argument}: value {} of item {} {problem}", values[i], i / per_item)));
    }
    Ok(converted)
}

/// The wrist of each of `poses` poses: `wrist` as (B, 4, 4) rigid transforms (a rotation, a
/// translation, the last row 0 0 0 1), or the rest wrist for every pose.
fn wrists(wrist: Option<&Bound<'_, PyAny>>, poses: usize) -> PyResult<Vec<Option<DualQuat>>> {
    let Some(wrist) = wrist.filter(|w| !w.is_none()) else { return Ok(vec![None; poses]) };
    let values = numbers(wrist, "wrist", &[Some(poses), Some(4), Some(4)], "one rigid transform per pose, or None")?;
    values
        .as_slice()
        .expect("contiguous")
        .chunks(16)
        .enumerate()
        .map(|(b, m)| {
            // NumPy's rows: m[4 r + c].
            let r = DMat3::from_cols(DVec3::new(m[0], m[4], m[8]), DVec3::new(m[1], m[5], m[9]), DVec3::new(m[2], m[6], m[10]));
            let orthonormal = (r.transpose() * r - DMat3::IDENTITY).to_cols_array().iter().all(|x| x.abs() < 1e-4);
            let last_row = m[12..16].iter().zip([0.0, 0.0, 0.0, 1.0]).all(|(x, y)| (x - y).abs() < 1e-6);
            if !(orthonormal && r.determinant() > 0.0 && last_row) {
                return Err(PyValueError::new_err(format!("wrist[{b}]: not a rigid transform (a rotation, no scale, shear or mirror; a translation; the last row 0 0 0 1)")));
            }
            let rotation = Quat::from_mat3(&r.as_mat3()).normalize();
            Ok(Some(DualQuat::from_rotation_translation(rotation, Vec3::new(m[3] as f32, m[7] as f32, m[11] as f32))))
        })
        .collect()
}

/// `outputs` (1 or 2) new float32 arrays of `shape` made by NumPy (so a batch too large for
/// memory is its `MemoryError`), written pose by pose on every core with the GIL released:
/// `fill` gets each pose's slice of the first (the first axis) and of the second, if asked.
fn batch<'py, D: numpy::ndarray::Dimension, S: Send + Sync + Clone>(
    py: Python<'py>,
    shape: &[usize],
    outputs: usize,
    start: S,
    fill: impl Fn(&mut S, usize, &mut [f32], Option<&mut [f32]>) + Sync,
) -> PyResult<Vec<Bound<'py, PyArray<f32, D>>>> {
    let numpy = py.import("numpy")?;
    let arrays = (0..outputs)
        .map(|_| numpy.call_method1("zeros", (shape.to_vec(), "float32"))?.cast_into::<PyArray<f32, D>>().map_err(PyErr::from))
        .collect::<PyResult<Vec<_>>>()?;
    let per_pose = shape[1..].iter().product::<usize>();
    if per_pose > 0 {
        let mut writable: Vec<_> = arrays.iter().map(|a| a.readwrite()).collect();
        let mut slices: Vec<&mut [f32]> = writable.iter_mut().map(|w| w.as_slice_mut().expect("NumPy's zeros are contiguous")).collect();
        let second = (slices.len() > 1).then(|| slices.pop()).flatten();
        let first = slices.pop().expect("one array at least");
        py.detach(|| match second {
            Some(second) => first.par_chunks_mut(per_pose).zip(second.par_chunks_mut(per_pose)).enumerate().for_each_init(|| start.clone(), |s, (b, (p, n))| fill(s, b, p, Some(n))),
            None => first.par_chunks_mut(per_pose).enumerate().for_each_init(|| start.clone(), |s, (b, p)| fill(s, b, p, None)),
        });
    }
    Ok(arrays)
}

/// [`batch`] of one array.
fn batch_one<'py, D: numpy::ndarray::Dimension, S: Send + Sync + Clone>(py: Python<'py>, shape: &[usize], start: S, fill: impl Fn(&mut S, usize, &mut [f32]) + Sync) -> PyResult<Bound<'py, PyArray<f32, D>>> {
    Ok(batch(py, shape, 1, start, |s, b, out, _| fill(s, b, out))?.remove(0))
}

/// The skin's joint indices and weights, each (V, K).
type Influences<'py> = (Bound<'py, PyArray2<u32>>, Bound<'py, PyArray2<f32>>);

/// A checked batch of poses: the angles as NumPy holds them, and each pose's wrist.
struct Poses<'py> {
    angles: PyReadonlyArrayDyn<'py, f64>,
    wrists: Vec<Option<DualQuat>>,
    dofs: usize,
    count: usize,
}

impl Poses<'_> {
    /// What the threads read the poses from.
    fn source(&self) -> PoseSource<'_> {
        PoseSource { values: self.angles.as_slice().expect("contiguous"), wrists: &self.wrists, dofs: self.dofs }
    }
}

/// A batch's angles (pose after pose) and wrists, shared by the threads that skin it.
#[derive(Clone, Copy)]
struct PoseSource<'a> {
    values: &'a [f64],
    wrists: &'a [Option<DualQuat>],
    dofs: usize,
}

impl PoseSource<'_> {
    /// Pose `b` written into `pose` (whose buffer is reused: nothing allocated per pose).
    fn read<'p>(&self, b: usize, pose: &'p mut Pose) -> &'p Pose {
        for (a, &x) in pose.angles.iter_mut().zip(&self.values[b * self.dofs..(b + 1) * self.dofs]) {
            *a = x as f32;
        }
        pose.wrist = self.wrists[b];
        pose
    }
}

/// A hand: a skinned mesh on a skeleton with WebXR joints, posed by joint angles.
#[pyclass(frozen, module = "dqhand")]
struct Hand {
    model: Arc<Model>,
    joint_model: JointModel,
    /// Posed per call (each thread its own copy).
    kinematics: HandKinematics,
    /// The skeleton index of each of the 25 WebXR joints the skeleton has.
    webxr: Vec<Option<usize>>,
}

impl Hand {
    fn new(model: Model, joint_model: JointModel, path: Option<&PathBuf>) -> PyResult<Self> {
        let model = Arc::new(model);
        let kinematics = model.hand_kinematics(joint_model).map_err(|e| to_py(if let Some(path) = path { e.in_file(path) } else { e }))?;
        let names = kinematics.skeleton().joints();
        let webxr = JOINT_NAMES.iter().map(|name| names.iter().position(|j| j.name == *name)).collect();
        Ok(Self { model, joint_model, kinematics, webxr })
    }

    /// The batch of poses of `angles` (B × D) and `wrist`, checked: their angles stay in the
    /// NumPy array, read pose by pose while the output is written.
    fn batch_of<'py>(&self, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>) -> PyResult<Poses<'py>> {
        let dofs = self.joint_model.dof_count();
        let angles = numbers(angles, "angles", &[None, Some(dofs)], &format!("joint angles in radians, in the order of dof_names, {} model", self.joint_model))?;
        let count = angles.shape()[0];
        Ok(Poses { wrists: wrists(wrist, count)?, angles, dofs, count })
    }

    /// The kinematics every thread starts from (these limits) and the pose it fills in.
    fn kinematics(&self, limits: bool) -> (HandKinematics, Pose) {
        let mut k = self.kinematics.clone();
        k.set_limits(if limits { Limits::Anatomical } else { Limits::Off });
        (k, Pose::rest(self.joint_model.dof_count()))
    }

    /// World positions of the WebXR joints `joints` (indices into `JOINT_NAMES`) in each pose,
    /// (B, #joints, 3).
    fn positions_of<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, limits: bool, joints: &[usize]) -> PyResult<Bound<'py, PyArray<f32, numpy::Ix3>>> {
        let joints: Vec<usize> = joints
            .iter()
            .map(|&i| self.webxr[i].ok_or_else(|| PyValueError::new_err(format!("this hand's skeleton has no WebXR joint {:?}", JOINT_NAMES[i]))))
            .collect::<PyResult<_>>()?;
        let poses = self.batch_of(angles, wrist)?;
        let source = poses.source();
        batch_one(py, &[poses.count, joints.len(), 3], self.kinematics(limits), |(k, pose), b, out| {
            k.pose(source.read(b, pose));
            for (&j, out) in joints.iter().zip(out.chunks_mut(3)) {
                out.copy_from_slice(&Vec3::from(k.world()[j].translation).to_array());
            }
        })
    }
}

/// A NumPy array of the rows `rows` (each `N` long).
fn array_of<'py, T: Element + Copy, const N: usize>(py: Python<'py>, rows: impl ExactSizeIterator<Item = [T; N]>) -> PyResult<Bound<'py, PyArray2<T>>> {
    let count = rows.len();
    numpy::PyArray1::from_iter(py, rows.flatten()).reshape([count, N])
}

#[pymethods]
impl Hand {
    /// The built-in anatomical hand: `length` wrist crease to middle fingertip (m), `breadth`
    /// across the knuckles (m), `side` "right" or "left" (built as itself, not mirrored),
    /// `vertices` of its mesh; posed by the joint model `model` ("full", 23 angles, or the
    /// paper's 18).
    #[staticmethod]
    #[pyo3(signature = (length = 0.19, breadth = 0.085, side = "right", vertices = None, model = "full"))]
    fn builtin(py: Python<'_>, length: f32, breadth: f32, side: &str, vertices: Option<usize>, model: &str) -> PyResult<Self> {
        let joint_model: JointModel = model.parse().map_err(to_py)?;
        let side = side_of(side, "side")?;
        let params = HandParams { length, breadth, side, vertices: vertices.unwrap_or(HandParams::default().vertices) };
        let built = py.detach(|| build(&params)).map_err(to_py)?;
        Self::new(built, joint_model, None)
    }

    /// A skinned hand from a glTF 2.0 file (.glb or .gltf) whose joints carry the WebXR names.
    #[staticmethod]
    #[pyo3(signature = (path, model = "full"))]
    fn load(py: Python<'_>, path: PathBuf, model: &str) -> PyResult<Self> {
        let joint_model: JointModel = model.parse().map_err(to_py)?;
        let loaded = py.detach(|| dqhand::io::load_gltf(&path)).map_err(to_py)?;
        Self::new(loaded, joint_model, Some(&path))
    }

    /// Triangles, (F, 3) vertex indices.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        array_of(py, self.model.mesh.indices().chunks_exact(3).map(|t| [t[0], t[1], t[2]]))
    }

    /// Rest vertex positions (the bind pose), (V, 3), m.
    #[getter]
    fn rest_vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        array_of(py, self.model.mesh.positions().into_iter())
    }

    /// The skeleton's joint names (the 25 WebXR hand joints, for the built-in hand).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.kinematics.skeleton().joints().iter().map(|j| j.name.clone()).collect()
    }

    /// The joint angles' names, in the order `angles` takes them: `<WebXR bone>.flex` or `.abd`.
    #[getter]
    fn dof_names(&self) -> Vec<String> {
        self.joint_model.dofs().map(|d| d.name()).collect()
    }

    /// Each angle's anatomical range, (D, 2), radians.
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let ranges: Vec<[f32; 2]> = self.joint_model.dofs().map(|d| [d.min_deg.to_radians(), d.max_deg.to_radians()]).collect();
        array_of(py, ranges.into_iter())
    }

    /// Each vertex's optimized centre of rotation (Le and Hodgins 2016), the rest-pose point its
    /// skin turns about under `method="cor"`, (V, 3), m: computed once per hand, when first
    /// asked for (by this or by a `cor` skin), or read from the glTF file that stored them.
    #[getter]
    fn centres_of_rotation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let mesh = &self.model.mesh;
        // (The first one asked computes them all: without the interpreter's lock.)
        py.detach(|| (mesh.vertex_count() > 0).then(|| mesh.centre_of_rotation(0)));
        array_of(py, (0..mesh.vertex_count()).map(|v| mesh.centre_of_rotation(v).to_array()))
    }

    /// The skin's influences: joint indices (into `joint_names`) and weights, each (V, K),
    /// heaviest first, unused slots (0, 0).
    #[getter]
    fn influences<'py>(&self, py: Python<'py>) -> PyResult<Influences<'py>> {
        let mesh = &self.model.mesh;
        let k = mesh.max_influences().max(1);
        let (mut joints, mut weights) = (vec![0u32; k * mesh.vertex_count()], vec![0f32; k * mesh.vertex_count()]);
        for v in 0..mesh.vertex_count() {
            for (slot, (j, w)) in mesh.influences(v).enumerate() {
                joints[k * v + slot] = j as u32;
                weights[k * v + slot] = w;
            }
        }
        let shape = [mesh.vertex_count(), k];
        Ok((numpy::PyArray1::from_vec(py, joints).reshape(shape)?, numpy::PyArray1::from_vec(py, weights).reshape(shape)?))
    }

    /// The posed hands' skin: `angles` (B, D) radians, `wrist` (B, 4, 4) rigid transforms or
    /// None (the rest wrist), `method` "dqb", "qb", "lb" or "cor", `limits` whether angles are clamped
    /// to their anatomical ranges. Returns the positions (B, V, 3), m, or with `normals` the
    /// positions and the unit normals. Each pose is skinned alone: a joint twisted past 180°
    /// is blended the shortest way, as no previous frame says which way it turned. With
    /// `contact_pass`, skin of one part of the hand inside another's (a fist's fingertips in
    /// the palm) is then moved out onto it (the engine's `SelfContactPass`).
    #[pyo3(signature = (angles, wrist = None, method = "dqb", *, normals = false, limits = true, contact_pass = false))]
    fn skin<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, method: &str, normals: bool, limits: bool, contact_pass: bool) -> PyResult<Bound<'py, PyAny>> {
        let method: Method = method.parse().map_err(to_py)?;
        let poses = self.batch_of(angles, wrist)?;
        let source = poses.source();
        let mesh = &self.model.mesh;
        let v = mesh.vertex_count();
        let pass = contact_pass.then(|| SelfContactPass::new(mesh, &self.model.skeleton));
        let start = (self.kinematics(limits), Deformer::new(method, mesh), pass);
        let mut skinned = batch::<numpy::Ix3, _>(py, &[poses.count, v, 3], if normals { 2 } else { 1 }, start, |((k, pose), d, pass), b, positions, mut normals| {
            k.pose(source.read(b, pose));
            // Each pose alone, whichever thread took the one before it.
            d.forget_previous_frame();
            d.deform_into(mesh, k.layer(), VertexBuffers::Separate { positions: &mut *positions, normals: normals.as_deref_mut() });
            if let Some(pass) = pass {
                pass.apply_to(k.layer().skinning(), positions.as_chunks_mut::<3>().0, normals.map(|n| n.as_chunks_mut::<3>().0));
            }
        })?;
        let positions = skinned.remove(0);
        Ok(match skinned.pop() {
            Some(normals) => (positions, normals).into_pyobject(py)?.into_any(),
            None => positions.into_any(),
        })
    }

    /// The 25 WebXR joints' world positions of each pose, (B, 25, 3), m (as `skin`'s `angles`,
    /// `wrist`, `limits`).
    #[pyo3(signature = (angles, wrist = None, limits = true))]
    fn joints<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, limits: bool) -> PyResult<Bound<'py, PyArray<f32, numpy::Ix3>>> {
        self.positions_of(py, angles, wrist, limits, &(0..JOINT_NAMES.len()).collect::<Vec<_>>())
    }

    /// MediaPipe Hands' 21 keypoints of each pose, in its order (the wrist, then each finger
    /// from its base to its tip), (B, 21, 3), m.
    #[pyo3(signature = (angles, wrist = None, limits = true))]
    fn keypoints<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, limits: bool) -> PyResult<Bound<'py, PyArray<f32, numpy::Ix3>>> {
        self.positions_of(py, angles, wrist, limits, &WEBXR_INDEX)
    }

    /// Each joint's skinning transform (its world transform times its inverse bind matrix) of
    /// each pose, (B, J, 4, 4), row-major as NumPy multiplies them: what the skin blends.
    #[pyo3(signature = (angles, wrist = None, limits = true))]
    fn skinning_transforms<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, limits: bool) -> PyResult<Bound<'py, PyArray<f32, numpy::Ix4>>> {
        let poses = self.batch_of(angles, wrist)?;
        let source = poses.source();
        let joints = self.model.mesh.inverse_bind().len();
        batch_one(py, &[poses.count, joints, 4, 4], self.kinematics(limits), |(k, pose), b, out| {
            k.pose(source.read(b, pose));
            for (m, out) in k.skinning().iter().zip(out.chunks_mut(16)) {
                // Row-major: the transpose's columns are the matrix's rows.
                out.copy_from_slice(&dqhand::glam::Mat4::from(*m).transpose().to_cols_array());
            }
        })
    }

    /// Retargeting: this hand's joint angles (B, D) radians and wrists (B, 4, 4) from tracked
    /// `points` of any hand, m: `kind` "mediapipe", (B, 21, 3) landmarks in MediaPipe's order,
    /// or "webxr", (B, 25, 3) WebXR joints; `side` the tracked hand's (default this hand's; the
    /// other side is mirrored). The engine's retargeter, which the viewer runs on webcam and
    /// WebXR input: bone directions only (any hand size gives the same angles), each angle in
    /// its range, a thumb touching a fingertip kept touching.
    #[pyo3(signature = (points, kind = "mediapipe", *, side = None))]
    fn fit<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>, kind: &str, side: Option<&str>) -> PyResult<fit::Fitted<'py>> {
        fit::fit(self, py, points, kind, side)
    }

    /// Gesture events, (t, "start" | "end", gesture), of a recording (JSON lines) played
    /// through the gesture loop with this hand, as `dqhand replay --gestures` prints them:
    /// `side` for records that do not say, `gestures` a definitions file (else the built-in
    /// ones), `config` an input configuration file, `glove_table` the glove of glove records.
    #[pyo3(signature = (path, *, side = "right", gestures = None, config = None, glove_table = "5dt-14"))]
    fn recognize_recording(&self, py: Python<'_>, path: PathBuf, side: &str, gestures: Option<PathBuf>, config: Option<PathBuf>, glove_table: &str) -> PyResult<Vec<gestures::Event>> {
        gestures::of_recording(self, py, path, side, gestures, config, glove_table)
    }

    /// Gesture events, (t, "start" | "end", gesture), of a sequence at `times` (T,) s: tracked
    /// `landmarks` (T, 21, 3) or `joints` (T, 25, 3), m, through the gesture loop as a recording
    /// of them would go (`side` one or one per record, default this hand's; `config` as there);
    /// or this hand's `angles` (T, D) and `wrist` (T, 4, 4) straight to the recogniser (nothing
    /// tracked, so nothing to retarget or filter).
    #[pyo3(signature = (times, angles = None, wrist = None, *, landmarks = None, joints = None, side = None, gestures = None, config = None, limits = true))]
    #[allow(clippy::too_many_arguments)]
    fn recognize<'py>(
        &self,
        py: Python<'py>,
        times: &Bound<'py, PyAny>,
        angles: Option<&Bound<'py, PyAny>>,
        wrist: Option<&Bound<'py, PyAny>>,
        landmarks: Option<&Bound<'py, PyAny>>,
        joints: Option<&Bound<'py, PyAny>>,
        side: Option<&Bound<'py, PyAny>>,
        gestures: Option<PathBuf>,
        config: Option<PathBuf>,
        limits: bool,
    ) -> PyResult<Vec<gestures::Event>> {
        gestures::of_arrays(self, py, &gestures::RecognizeArgs { times, angles, wrist, landmarks, joints, side, gestures, config, limits })
    }

    /// The realism measures of `dqhand metrics`, for each pose under `method` (as `skin`'s
    /// arguments): name → (B,): `volume` against rest (NaN for an open mesh), `min_distance`
    /// and `max_distance` skin-to-bone against bind around `joint` (< 1 collapse, > 1 bulge),
    /// `section_radius` there (< 1 the candy wrapper), `distortion_mean`/`_max` of its edges'
    /// lengths, and with `self_intersections` the crossing triangle pairs.
    #[pyo3(signature = (angles, wrist = None, method = "dqb", *, joint = "index-finger-phalanx-intermediate", next = None, self_intersections = false, limits = true))]
    #[allow(clippy::too_many_arguments)]
    fn realism<'py>(
        &self,
        py: Python<'py>,
        angles: &Bound<'py, PyAny>,
        wrist: Option<&Bound<'py, PyAny>>,
        method: &str,
        joint: &str,
        next: Option<&str>,
        self_intersections: bool,
        limits: bool,
    ) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        metrics::realism(self, py, &metrics::RealismArgs { angles, wrist, method, joint, next, self_intersections, limits })
    }

    /// The skin `realism` measures around `joint`: `vertices` (N,), `joints` (parent, joint,
    /// next) into `joint_names`, the skin's `radius` there and its smallest, m (bind pose).
    #[pyo3(signature = (joint, next = None))]
    fn joint_region<'py>(&self, py: Python<'py>, joint: &str, next: Option<&str>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        metrics::joint_region(self, py, joint, next)
    }

    /// `dqhand metrics --json` of this hand: LB, QB, DQB and CoR on the sweeps, self-intersections
    /// in gestures and the headline numbers, as dicts and lists.
    fn realism_report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        metrics::report(self, py)
    }

    /// Writes this hand as the rigged, skinned GLB `dqhand hand` writes (rest pose; joints,
    /// inverse bind matrices, weights, collision proxies), which `Hand.load` reads back.
    fn export_gltf(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        export::gltf(self, py, path)
    }

    /// Writes one posed mesh with normals as `dqhand skin` does, by the name's extension
    /// (.ply, .obj or a static .glb): `angles` (D,) radians, `wrist` (4, 4) or None.
    #[pyo3(signature = (path, angles, wrist = None, method = "dqb", *, limits = true))]
    fn export_posed(&self, py: Python<'_>, path: PathBuf, angles: &Bound<'_, PyAny>, wrist: Option<&Bound<'_, PyAny>>, method: &str, limits: bool) -> PyResult<()> {
        export::posed(self, py, path, angles, wrist, method, limits)
    }

    /// The hand, its wrist at rest, closing from open towards `angles` (B, D) radians on a
    /// ball at `centres` (B, 3), m, of `radii` (B,), m: the rendered angles (B, D) of the
    /// engine's contact-constrained hand, each finger stopped where it touches the ball, and
    /// (B,) whether the open hand was clear of the ball (else a finger touching it open
    /// cannot close on it).
    #[pyo3(signature = (angles, centres, radii, *, limits = true))]
    fn close_on_ball<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, centres: &Bound<'py, PyAny>, radii: &Bound<'py, PyAny>, limits: bool) -> PyResult<grasp::Grasps<'py>> {
        grasp::close_on_ball(self, py, angles, centres, radii, limits)
    }

    /// The gesture library's shapes (the paper's Figure 7 and common VR gestures) as this
    /// hand's joint angles: name → (D,) radians, the wrist at rest. DOFs the joint model lacks
    /// stay at rest.
    fn gesture_poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let poses = pyo3::types::PyDict::new(py);
        for g in &dqhand::gesture::GESTURES {
            poses.set_item(g.name, numpy::PyArray1::from_vec(py, g.pose(self.joint_model).angles))?;
        }
        Ok(poses)
    }

    fn __repr__(&self) -> String {
        let (vertices, joints, angles) = (self.model.mesh.vertex_count(), self.kinematics.skeleton().joints().len(), self.joint_model.dof_count());
        format!("<dqhand.Hand of {vertices} vertices, {joints} joints, {angles} angles ({} model): {}>", self.joint_model, self.model.description)
    }
}

/// The module `dqhand._dqhand`, which `dqhand` re-exports.
#[pymodule]
fn _dqhand(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Hand>()?;
    m.add_function(wrap_pyfunction!(raster::render_depth, m)?)?;
    m.add_function(wrap_pyfunction!(recording::read_recording, m)?)?;
    m.add_function(wrap_pyfunction!(recording::write_recording, m)?)?;
    m.add_function(wrap_pyfunction!(gestures::gesture_names, m)?)?;
    m.add("WEBXR_JOINTS", JOINT_NAMES.to_vec())?;
    m.add("MEDIAPIPE_KEYPOINTS", dqhand::input::mediapipe::LANDMARK_NAMES.to_vec())?;
    Ok(())
}
