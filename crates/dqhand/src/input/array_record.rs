//! Records from flat arrays of numbers: what a browser holds of a tracked hand without writing
//! JSON. WebXR's `XRFrame.fillPoses` writes each joint's pose as a 4 × 4 column-major matrix
//! and `fillJointRadii` its radius; MediaPipe gives 21 world landmarks, x y z each. Reading those
//! arrays straight into a [`Record`] lets a page feed the engine every frame with nothing
//! allocated, checked as a JSON record is ([`super::json_record`]): the same one-line problems.

use glam::{Mat3, Quat, Vec3};

use super::json_record::{orientation, position, seconds};
use super::record::{JOINT_COUNT, LANDMARK_COUNT};
use super::{HandData, JointSet, RejectKind, Rejection, Record, TrackedJoint};
use crate::kinematics::webxr;
use crate::kinematics::Side;

/// Floats per joint pose: a 4 × 4 column-major rigid transform, as `XRFrame.fillPoses` writes.
pub const MATRIX_FLOATS: usize = 16;
/// Largest deviation of a pose matrix's rotation from orthonormal (column lengths from 1,
/// columns' dot products from 0) that is rounding rather than a scaled or sheared matrix.
const ORTHONORMAL_TOLERANCE: f32 = 1e-2;

/// Reads the 25 WebXR joints (`XRHand`'s order) of `side`'s hand at `time` into `out`:
/// `matrices` holds [`MATRIX_FLOATS`] per joint, `radii` one per joint (m; empty when unknown).
///
/// # Errors
/// Other lengths, a time that is not finite or negative, a matrix that is not finite or not a
/// rigid transform, a position out of range, a radius that is not finite; `out` is unchanged.
pub fn joints_record(time: f64, side: Side, matrices: &[f32], radii: &[f32], out: &mut Record) -> Result<(), Rejection> {
    let time = seconds("t", time)?;
    if matrices.len() != JOINT_COUNT * MATRIX_FLOATS {
        return Err(Rejection::new(RejectKind::ColumnCount, format!("joint matrices: {} floats, 25 joints need {}", matrices.len(), JOINT_COUNT * MATRIX_FLOATS)));
    }
    if !radii.is_empty() && radii.len() != JOINT_COUNT {
        return Err(Rejection::new(RejectKind::ColumnCount, format!("joint radii: {} floats, 25 joints need 25 (or none)", radii.len())));
    }
    let mut set = JointSet::new();
    for (i, m) in matrices.chunks_exact(MATRIX_FLOATS).enumerate() {
        let label = || format!("joint {}", webxr::JOINT_NAMES[i]);
        let rotation = rotation(m, label)?;
        let radius = radii.get(i).copied().unwrap_or(0.0);
        if !radius.is_finite() {
            return Err(Rejection::new(RejectKind::NonFinite, format!("{}: radius {radius}", label())));
        }
        set.set(i, TrackedJoint { position: position([m[12], m[13], m[14]], label)?, orientation: Some(rotation), radius });
    }
    *out = Record { time, side, hand: Some(HandData::Joints(set)), tracker: None, arrival: None };
    Ok(())
}

/// Reads MediaPipe's 21 world landmarks of `side`'s hand at `time` (x y z each, metres, the
/// engine's axes: [`super::mediapipe`]) into `out`.
///
/// # Errors
/// Another length, a time that is not finite or negative, a landmark not finite or out of
/// range; `out` is unchanged.
pub fn landmarks_record(time: f64, side: Side, landmarks: &[f32], out: &mut Record) -> Result<(), Rejection> {
    let time = seconds("t", time)?;
    if landmarks.len() != 3 * LANDMARK_COUNT {
        return Err(Rejection::new(RejectKind::ColumnCount, format!("landmarks: {} floats, 21 landmarks need 63", landmarks.len())));
    }
    let mut points = [Vec3::ZERO; LANDMARK_COUNT];
    for (i, (p, l)) in points.iter_mut().zip(landmarks.chunks_exact(3)).enumerate() {
        *p = position([l[0], l[1], l[2]], || format!("landmark {i}"))?;
    }
    *out = Record { time, side, hand: Some(HandData::Landmarks(points)), tracker: None, arrival: None };
    Ok(())
}

/// The rotation of a column-major 4 × 4 rigid transform, refused when the upper 3 × 3 is not a
/// rotation within rounding (a scaled, sheared or mirrored matrix has no joint orientation).
fn rotation(m: &[f32], label: impl Fn() -> String) -> Result<Quat, Rejection> {
    if let Some(bad) = m.iter().find(|v| !v.is_finite()) {
        return Err(Rejection::new(RejectKind::NonFinite, format!("{}: matrix holds {bad}", label())));
    }
    let r = Mat3::from_cols_slice(&[m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]]);
    let (x, y, z) = (r.x_axis, r.y_axis, r.z_axis);
    let off = [x.length() - 1.0, y.length() - 1.0, z.length() - 1.0, x.dot(y), y.dot(z), z.dot(x), r.determinant() - 1.0];
    if off.iter().any(|e| e.abs() > ORTHONORMAL_TOLERANCE) {
        return Err(Rejection::new(RejectKind::OutOfRange, format!("{}: matrix is not a rigid transform (its rotation part is scaled, sheared or mirrored)", label())));
    }
    orientation(Quat::from_mat3(&r).normalize().to_array(), label)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::json_record::parse_record;

    /// A joint matrix as `fillPoses` writes it, and the same joint as a JSON record's entry.
    fn joint(i: usize) -> ([f32; 16], String) {
        let q = Quat::from_euler(glam::EulerRot::XYZ, 0.1 * i as f32, -0.3, 0.05 * i as f32);
        let p = Vec3::new(0.01 * i as f32, 1.1, -0.3 - 0.002 * i as f32);
        let m = glam::Mat4::from_rotation_translation(q, p).to_cols_array();
        (m, format!("{{\"p\":[{},{},{}],\"q\":[{},{},{},{}],\"r\":0.01}}", p.x, p.y, p.z, q.x, q.y, q.z, q.w))
    }

    #[test]
    fn matrices_read_as_the_json_record_of_the_same_joints() {
        let (mut matrices, mut entries) = (Vec::new(), Vec::new());
        for i in 0..JOINT_COUNT {
            let (m, e) = joint(i);
            matrices.extend(m);
            entries.push(e);
        }
        let mut from_arrays = Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None };
        joints_record(0.5, Side::Left, &matrices, &[0.01; JOINT_COUNT], &mut from_arrays).unwrap();
        let mut from_json = from_arrays;
        parse_record::<&str>(&format!("{{\"t\":0.5,\"hand\":\"left\",\"joints\":[{}]}}", entries.join(",")), Side::Right, &[], &mut from_json).unwrap();
        let (Some(HandData::Joints(a)), Some(HandData::Joints(b))) = (from_arrays.hand, from_json.hand) else { panic!("joints expected") };
        assert_eq!((from_arrays.time, from_arrays.side), (0.5, Side::Left));
        for i in 0..JOINT_COUNT {
            let (a, b) = (a.get(i).unwrap(), b.get(i).unwrap());
            assert!(a.position.distance(b.position) < 1e-6, "joint {i}");
            assert!(a.orientation.unwrap().dot(b.orientation.unwrap()).abs() > 1.0 - 1e-6, "joint {i}");
            assert_eq!(a.radius, b.radius);
        }
    }

    #[test]
    fn bad_arrays_are_refused_with_the_joint_and_the_problem() {
        let mut matrices: Vec<f32> = (0..JOINT_COUNT).flat_map(|i| joint(i).0).collect();
        let mut out = Record { time: 0.0, side: Side::Right, hand: None, tracker: None, arrival: None };
        let before = out;
        let refused = |m: &[f32], radii: &[f32], out: &mut Record| joints_record(1.0, Side::Right, m, radii, out).unwrap_err().to_string();
        assert!(refused(&matrices[..16], &[], &mut out).contains("joint matrices: 16 floats"));
        assert!(refused(&matrices, &[0.01; 3], &mut out).contains("joint radii: 3 floats"));
        matrices[16 * 3] = 2.0; // joint 3's x axis scaled
        assert!(refused(&matrices, &[], &mut out).contains("joint thumb-phalanx-distal: matrix is not a rigid transform"));
        matrices[16 * 3] = f32::NAN;
        assert!(refused(&matrices, &[], &mut out).contains("joint thumb-phalanx-distal: matrix holds NaN"));
        assert_eq!(out, before, "a refused record leaves the record as it was");
        assert!(joints_record(-1.0, Side::Right, &matrices, &[], &mut out).unwrap_err().to_string().contains("t: -1 is negative"));
        assert!(landmarks_record(0.0, Side::Right, &[0.0; 62], &mut out).unwrap_err().to_string().contains("landmarks: 62 floats"));
        let mut far = [0.0; 63];
        far[5] = 1e3;
        assert!(landmarks_record(0.0, Side::Right, &far, &mut out).unwrap_err().to_string().contains("landmark 1: position"));
        landmarks_record(2.0, Side::Left, &[0.01; 63], &mut out).unwrap();
        assert!(matches!(out.hand, Some(HandData::Landmarks(p)) if p[20] == Vec3::splat(0.01)));
    }
}
