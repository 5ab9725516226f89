//! dqhand in Python (`import dqhand`): a hand's mesh, joints and skin as NumPy arrays, in SI
//! units (metres, radians), the batch dimension first.
//!
//! A batch of poses is skinned on every core with the GIL released, each pose into its own slice
//! of the array that is returned (no copy after): per pose, one forward kinematics pass (the
//! paper's kinematics layer) and one deformation (its skin layer: LB, QB or DQB, Eq. 6–8).

use std::path::PathBuf;
use std::sync::Arc;

use dqhand::glam::{Mat4, Vec3};
use dqhand::hand::{build, HandParams};
use dqhand::input::mediapipe::WEBXR_INDEX;
use dqhand::kinematics::{webxr::JOINT_NAMES, HandKinematics, JointModel, Limits, Pose, Side};
use dqhand::math::DualQuat;
use dqhand::model::Model;
use dqhand::skin::{Deformer, Method, VertexBuffers};
use numpy::{PyArray1, PyArray2, PyArray3, PyArray4, PyArrayMethods, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;

/// A library error as the Python exception for it, with the library's one-line message.
fn to_py(error: dqhand::Error) -> PyErr {
    match &error {
        dqhand::Error::Io { reason, .. } if reason.kind() == std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(error.to_string()),
        _ => PyValueError::new_err(error.to_string()),
    }
}

/// `array` as float32 values, row-major, checked to be 2-D with `columns` columns: the
/// message names `argument` and the shape it must have.
fn rows(array: &Bound<'_, PyAny>, argument: &str, columns: usize, what: &str) -> PyResult<(usize, Vec<f32>)> {
    let shape_error = |got: String| PyValueError::new_err(format!("{argument}: expected an array of shape (B, {columns}) ({what}), got {got}"));
    // Anything else array-like (lists, other dtypes) as NumPy would read it.
    let converted;
    let array = if array.extract::<PyReadonlyArray2<'_, f32>>().is_ok() || array.extract::<PyReadonlyArray2<'_, f64>>().is_ok() {
        array
    } else {
        converted = array.py().import("numpy")?.call_method1("asarray", (array, "float64")).map_err(|e| PyValueError::new_err(format!("{argument}: not an array of numbers ({e})")))?;
        &converted
    };
    let (shape, values): (Vec<usize>, Vec<f32>) = if let Ok(a) = array.extract::<PyReadonlyArray2<'_, f32>>() {
        (a.shape().to_vec(), a.as_array().iter().copied().collect())
    } else if let Ok(a) = array.extract::<PyReadonlyArray2<'_, f64>>() {
        (a.shape().to_vec(), a.as_array().iter().map(|&x| x as f32).collect())
    } else {
        let got = match array.getattr("shape") {
            Ok(shape) => format!("shape {shape} of dtype {}", array.getattr("dtype").map(|d| d.to_string()).unwrap_or_default()),
            Err(_) => format!("a {}", array.get_type().name()?),
        };
        return Err(shape_error(got));
    };
    if shape[1] != columns {
        return Err(shape_error(format!("shape ({}, {})", shape[0], shape[1])));
    }
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!("{argument}: value {} (row {}, column {}) is not finite", values[i], i / columns, i % columns)));
    }
    Ok((shape[0], values))
}

/// The wrist of each pose: `wrist` as (B, 4, 4) rigid transforms (rotation and translation,
/// the last row 0 0 0 1), or the rest wrist for every pose.
fn wrists(wrist: Option<&Bound<'_, PyAny>>, poses: usize) -> PyResult<Vec<Option<DualQuat>>> {
    let Some(wrist) = wrist.filter(|w| !w.is_none()) else { return Ok(vec![None; poses]) };
    let values: Vec<f64> = if let Ok(a) = wrist.extract::<PyReadonlyArray3<'_, f64>>() {
        check_wrist_shape(a.shape(), poses)?;
        a.as_array().iter().copied().collect()
    } else if let Ok(a) = wrist.extract::<PyReadonlyArray3<'_, f32>>() {
        check_wrist_shape(a.shape(), poses)?;
        a.as_array().iter().map(|&x| f64::from(x)).collect()
    } else {
        return Err(PyValueError::new_err(format!("wrist: expected a float array of shape ({poses}, 4, 4) or None")));
    };
    values
        .chunks(16)
        .enumerate()
        .map(|(b, m)| {
            // NumPy's rows read as columns, transposed: the matrix itself.
            let matrix = Mat4::from_cols_array(&std::array::from_fn(|k| m[k] as f32)).transpose();
            let (scale, rotation, translation) = matrix.to_scale_rotation_translation();
            let last_row = m[12..16].iter().zip([0.0, 0.0, 0.0, 1.0]).all(|(x, y)| (x - y).abs() < 1e-6);
            let rigid = last_row && (scale - Vec3::ONE).abs().max_element() < 1e-3 && rotation.is_finite() && translation.is_finite();
            if !rigid {
                return Err(PyValueError::new_err(format!("wrist[{b}]: not a rigid transform (a rotation, a translation and the last row 0 0 0 1)")));
            }
            Ok(Some(DualQuat::from_rotation_translation(rotation.normalize(), translation)))
        })
        .collect()
}

fn check_wrist_shape(shape: &[usize], poses: usize) -> PyResult<()> {
    if shape != [poses, 4, 4] {
        return Err(PyValueError::new_err(format!("wrist: expected shape ({poses}, 4, 4), one rigid transform per pose, got {shape:?}")));
    }
    Ok(())
}

/// A hand: a skinned mesh on a skeleton with WebXR joints, posed by joint angles.
#[pyclass(frozen, module = "dqhand")]
struct Hand {
    model: Arc<Model>,
    joint_model: JointModel,
    /// Posed per call (each thread its own copy).
    kinematics: HandKinematics,
    /// The skeleton index of each of the 25 WebXR joints.
    webxr: Vec<usize>,
}

impl Hand {
    fn new(model: Model, joint_model: &str) -> PyResult<Self> {
        let joint_model: JointModel = joint_model.parse().map_err(to_py)?;
        let model = Arc::new(model);
        let kinematics = model.hand_kinematics(joint_model).map_err(to_py)?;
        let names = kinematics.skeleton().joints();
        let webxr = JOINT_NAMES
            .iter()
            .map(|name| names.iter().position(|j| j.name == *name).ok_or_else(|| PyValueError::new_err(format!("skeleton has no WebXR joint {name:?}"))))
            .collect::<PyResult<_>>()?;
        Ok(Self { model, joint_model, kinematics, webxr })
    }

    /// The poses of `angles` (B × D) with their wrists.
    fn poses(&self, angles: &Bound<'_, PyAny>, wrist: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Pose>> {
        let dofs = self.joint_model.dof_count();
        let (count, values) = rows(angles, "angles", dofs, &format!("joint angles in radians, in the order of dof_names, {} model", self.joint_model))?;
        let wrists = wrists(wrist, count)?;
        Ok(values.chunks(dofs.max(1)).take(count).zip(wrists).map(|(a, wrist)| Pose { wrist, angles: a.to_vec() }).collect())
    }

    /// The kinematics every thread starts from: these limits.
    fn kinematics(&self, limits: bool) -> HandKinematics {
        let mut k = self.kinematics.clone();
        k.set_limits(if limits { Limits::Anatomical } else { Limits::Off });
        k
    }
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
        let side = match side {
            "right" => Side::Right,
            "left" => Side::Left,
            other => return Err(PyValueError::new_err(format!("side: {other:?} is not a side; use \"right\" or \"left\""))),
        };
        let params = HandParams { length, breadth, side, vertices: vertices.unwrap_or(HandParams::default().vertices) };
        let built = py.detach(|| build(&params)).map_err(to_py)?;
        Self::new(built, model)
    }

    /// A skinned hand from a glTF 2.0 file (.glb or .gltf) whose skeleton has the WebXR hand
    /// joints.
    #[staticmethod]
    #[pyo3(signature = (path, model = "full"))]
    fn load(py: Python<'_>, path: PathBuf, model: &str) -> PyResult<Self> {
        let loaded = py.detach(|| dqhand::io::load_gltf(&path)).map_err(to_py)?;
        Self::new(loaded, model)
    }

    /// Triangles, (F, 3) vertex indices.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let indices = self.model.mesh.indices();
        PyArray1::from_slice(py, indices).reshape([indices.len() / 3, 3])
    }

    /// Rest vertex positions (the bind pose), (V, 3), m.
    #[getter]
    fn rest_vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        PyArray2::from_vec2(py, &self.model.mesh.positions().iter().map(|p| p.to_vec()).collect::<Vec<_>>()).expect("rows of 3")
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
    fn limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        let rows: Vec<Vec<f32>> = self.joint_model.dofs().map(|d| vec![d.min_deg.to_radians(), d.max_deg.to_radians()]).collect();
        PyArray2::from_vec2(py, &rows).expect("rows of 2")
    }

    /// The skin's influences: joint indices (into `joint_names`) and weights, each (V, K),
    /// heaviest first, unused slots (0, 0).
    #[getter]
    fn influences<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray2<u32>>, Bound<'py, PyArray2<f32>>) {
        let mesh = &self.model.mesh;
        let k = mesh.max_influences().max(1);
        let (mut joints, mut weights) = (vec![vec![0u32; k]; mesh.vertex_count()], vec![vec![0f32; k]; mesh.vertex_count()]);
        for v in 0..mesh.vertex_count() {
            for (slot, (j, w)) in mesh.influences(v).enumerate() {
                joints[v][slot] = j as u32;
                weights[v][slot] = w;
            }
        }
        (PyArray2::from_vec2(py, &joints).expect("rows of k"), PyArray2::from_vec2(py, &weights).expect("rows of k"))
    }

    /// The posed hands' skin: `angles` (B, D) radians, `wrist` (B, 4, 4) rigid transforms or
    /// None (the rest wrist), `method` "dqb", "qb" or "lb", `limits` whether angles are clamped
    /// to their anatomical ranges. Returns the positions (B, V, 3), m, or with `normals` the
    /// positions and the unit normals.
    #[pyo3(signature = (angles, wrist = None, method = "dqb", normals = false, limits = true))]
    fn skin<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, method: &str, normals: bool, limits: bool) -> PyResult<Bound<'py, PyAny>> {
        let method: Method = method.parse().map_err(to_py)?;
        let poses = self.poses(angles, wrist)?;
        let mesh = &self.model.mesh;
        let v = mesh.vertex_count();
        let positions = PyArray3::<f32>::zeros(py, [poses.len(), v, 3], false);
        let normal_array = normals.then(|| PyArray3::<f32>::zeros(py, [poses.len(), v, 3], false));
        {
            let mut p = positions.readwrite();
            let mut n = normal_array.as_ref().map(|a| a.readwrite());
            let p = p.as_slice_mut().expect("a new array is contiguous");
            let n = n.as_mut().map(|n| n.as_slice_mut().expect("a new array is contiguous"));
            let start = (self.kinematics(limits), Deformer::new(method, mesh));
            let skin_one = |(k, d): &mut (HandKinematics, Deformer), pose: &Pose, p: &mut [f32], n: Option<&mut [f32]>| {
                k.pose(pose);
                d.deform_into(mesh, k.layer(), VertexBuffers::Separate { positions: p, normals: n });
            };
            py.detach(|| match n {
                Some(n) => poses.par_iter().zip(p.par_chunks_mut(3 * v)).zip(n.par_chunks_mut(3 * v)).for_each_init(|| start.clone(), |s, ((pose, p), n)| skin_one(s, pose, p, Some(n))),
                None => poses.par_iter().zip(p.par_chunks_mut(3 * v)).for_each_init(|| start.clone(), |s, (pose, p)| skin_one(s, pose, p, None)),
            });
        }
        Ok(match normal_array {
            Some(n) => (positions, n).into_pyobject(py)?.into_any(),
            None => positions.into_any(),
        })
    }

    /// The 25 WebXR joints' world positions of each pose, (B, 25, 3), m (as `skin`'s `angles`,
    /// `wrist`, `limits`).
    #[pyo3(signature = (angles, wrist = None, limits = true))]
    fn joints<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, limits: bool) -> PyResult<Bound<'py, PyArray3<f32>>> {
        self.positions_of(py, angles, wrist, limits, &self.webxr)
    }

    /// MediaPipe Hands' 21 keypoints of each pose, in its order (the wrist, then each finger
    /// from its base to its tip), (B, 21, 3), m.
    #[pyo3(signature = (angles, wrist = None, limits = true))]
    fn keypoints<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, limits: bool) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let joints: Vec<usize> = WEBXR_INDEX.iter().map(|&i| self.webxr[i]).collect();
        self.positions_of(py, angles, wrist, limits, &joints)
    }

    /// Each joint's skinning transform (its world transform times its inverse bind matrix) of
    /// each pose, (B, J, 4, 4), row-major as NumPy multiplies them: what the skin blends.
    #[pyo3(signature = (angles, wrist = None, limits = true))]
    fn skinning_transforms<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, limits: bool) -> PyResult<Bound<'py, PyArray4<f32>>> {
        let poses = self.poses(angles, wrist)?;
        let joints = self.model.mesh.inverse_bind().len();
        let out = PyArray4::<f32>::zeros(py, [poses.len(), joints, 4, 4], false);
        {
            let mut w = out.readwrite();
            let w = w.as_slice_mut().expect("a new array is contiguous");
            let start = self.kinematics(limits);
            py.detach(|| {
                poses.par_iter().zip(w.par_chunks_mut(16 * joints)).for_each_init(
                    || start.clone(),
                    |k, (pose, w)| {
                        k.pose(pose);
                        for (m, w) in k.skinning().iter().zip(w.chunks_mut(16)) {
                            // Row-major: Mat4's columns written as the rows of the transpose.
                            w.copy_from_slice(&Mat4::from(*m).transpose().to_cols_array());
                        }
                    },
                )
            });
        }
        Ok(out)
    }

    fn __repr__(&self) -> String {
        let (vertices, joints, angles) = (self.model.mesh.vertex_count(), self.kinematics.skeleton().joints().len(), self.joint_model.dof_count());
        format!("<dqhand.Hand of {vertices} vertices, {joints} joints, {angles} angles ({} model): {}>", self.joint_model, self.model.description)
    }
}

impl Hand {
    /// World positions of `joints` (skeleton indices) in each pose, (B, #joints, 3).
    fn positions_of<'py>(&self, py: Python<'py>, angles: &Bound<'py, PyAny>, wrist: Option<&Bound<'py, PyAny>>, limits: bool, joints: &[usize]) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let poses = self.poses(angles, wrist)?;
        let out = PyArray3::<f32>::zeros(py, [poses.len(), joints.len(), 3], false);
        {
            let mut w = out.readwrite();
            let w = w.as_slice_mut().expect("a new array is contiguous");
            let start = self.kinematics(limits);
            py.detach(|| {
                poses.par_iter().zip(w.par_chunks_mut(3 * joints.len())).for_each_init(
                    || start.clone(),
                    |k, (pose, w)| {
                        k.pose(pose);
                        for (&j, w) in joints.iter().zip(w.chunks_mut(3)) {
                            w.copy_from_slice(&Vec3::from(k.world()[j].translation).to_array());
                        }
                    },
                )
            });
        }
        Ok(out)
    }
}

/// The module `dqhand._dqhand`, which `dqhand` re-exports.
#[pymodule]
fn _dqhand(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Hand>()?;
    m.add("WEBXR_JOINTS", JOINT_NAMES.to_vec())?;
    m.add("MEDIAPIPE_KEYPOINTS", dqhand::input::mediapipe::LANDMARK_NAMES.to_vec())?;
    Ok(())
}
