//! Retargeting from Python: tracked positions of any hand (MediaPipe's 21 landmarks or the 25
//! WebXR joints) → this hand's joint angles and wrist, by the engine's `Retargeter`, the one
//! the gesture loop runs on webcam and WebXR input (bone directions only, so any hand size or
//! proportion gives the same angles; the other side's hand mirrored onto ours; contacts kept).

use dqhand::glam::Vec3;
use dqhand::input::{Retargeter, JOINT_COUNT, LANDMARK_COUNT};
use dqhand::kinematics::Pose;
use numpy::{PyArray, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::{numbers, side_of, to_py, Hand};

/// What `Hand.fit` returns: the angles (B, D) and the wrists (B, 4, 4).
pub(crate) type Fitted<'py> = (Bound<'py, PyArray<f32, numpy::Ix2>>, Bound<'py, PyArray<f32, numpy::Ix3>>);

/// A pose's wrist as a row-major 4 × 4 rigid transform (the rest wrist where it has none).
pub(crate) fn wrist_matrix(pose: &Pose, rest: dqhand::math::DualQuat) -> [f32; 16] {
    // Row-major: the transpose's columns are the matrix's rows.
    pose.wrist.unwrap_or(rest).to_mat4().transpose().to_cols_array()
}

/// `Hand.fit`: each pose of `points` solved on every core, the GIL released; the first pose
/// the retargeter refuses (a palm that spans no frame, coincident joints) is the error.
pub(crate) fn fit<'py>(hand: &Hand, py: Python<'py>, points: &Bound<'py, PyAny>, kind: &str, side: Option<&str>) -> PyResult<Fitted<'py>> {
    let landmarks = match kind.to_ascii_lowercase().as_str() {
        "mediapipe" => true,
        "webxr" => false,
        _ => return Err(PyValueError::new_err(format!("kind: {kind:?} is not a kind of points; use \"mediapipe\" (21 landmarks) or \"webxr\" (25 joints)"))),
    };
    let (count_per_pose, what) = if landmarks { (LANDMARK_COUNT, "MediaPipe's 21 landmarks in its order, m") } else { (JOINT_COUNT, "the 25 WebXR joints in their order, m") };
    let values = numbers(points, "points", &[None, Some(count_per_pose), Some(3)], what)?;
    let retargeter = Retargeter::new(hand.kinematics.rig()).map_err(to_py)?;
    let side = side.map_or(Ok(retargeter.side()), |s| side_of(s, "side"))?;
    let rest_wrist = hand.kinematics.rig().rest_wrist();
    let (poses, dofs) = (values.shape()[0], hand.joint_model.dof_count());
    let source = values.as_slice().expect("contiguous");
    let (mut angles, mut wrists) = (vec![0f32; poses * dofs], vec![0f32; poses * 16]);
    let refused = py.detach(|| {
        angles
            .par_chunks_mut(dofs.max(1))
            .zip(wrists.par_chunks_mut(16))
            .enumerate()
            .map_init(
                || (retargeter.clone(), Pose::rest(dofs), [Vec3::ZERO; JOINT_COUNT]),
                |(r, pose, joints), (b, (angles, wrist))| {
                    let point = |i: usize| {
                        let p = &source[3 * (b * count_per_pose + i)..];
                        Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)
                    };
                    let solved = if landmarks {
                        let marks: [Vec3; LANDMARK_COUNT] = core::array::from_fn(point);
                        r.landmark_joints(&marks, joints).and_then(|()| r.solve(joints, side, pose))
                    } else {
                        r.solve(&core::array::from_fn(point), side, pose)
                    };
                    solved.map_err(|rejection| (b, rejection))?;
                    angles.copy_from_slice(&pose.angles);
                    wrist.copy_from_slice(&wrist_matrix(pose, rest_wrist));
                    Ok(())
                },
            )
            .find_first(|r: &Result<(), _>| r.is_err())
    });
    if let Some(Err((b, rejection))) = refused {
        return Err(PyValueError::new_err(format!("points[{b}]: {rejection}")));
    }
    Ok((numpy::PyArray1::from_vec(py, angles).reshape([poses, dofs])?, numpy::PyArray1::from_vec(py, wrists).reshape([poses, 4, 4])?))
}
