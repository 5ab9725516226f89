//! The best-fit rigid motion between two point sets (Kabsch): what a grasped object does when
//! the points that hold it move.

use glam::{Mat3, Quat, Vec3};
use nalgebra::{Matrix3, SVD};

/// The rotation `R` and translation `t` that minimise `Σ |R·from[i] + t − to[i]|²` (Kabsch:
/// the SVD of the cross-covariance, with the sign that keeps `R` a rotation).
///
/// Fewer than three points, or points on a line, leave the rotation about that line free;
/// the SVD then picks one. Allocates nothing.
///
/// # Panics
/// If the slices differ in length or are empty.
#[must_use]
pub fn rigid_fit(from: &[Vec3], to: &[Vec3]) -> (Quat, Vec3) {
    assert!(!from.is_empty() && from.len() == to.len(), "two point sets of one length");
    let n = from.len() as f32;
    let ca = from.iter().copied().sum::<Vec3>() / n;
    let cb = to.iter().copied().sum::<Vec3>() / n;
    let mut h = Matrix3::<f32>::zeros();
    for (a, b) in from.iter().zip(to) {
        let (a, b) = (*a - ca, *b - cb);
        h += nalgebra::Vector3::new(a.x, a.y, a.z) * nalgebra::Vector3::new(b.x, b.y, b.z).transpose();
    }
    let svd = SVD::new(h, true, true);
    let (u, v_t) = (svd.u.expect("asked for U"), svd.v_t.expect("asked for Vᵀ"));
    let v = v_t.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, d)) * u.transpose();
    let m = Mat3::from_cols_array(&[r[(0, 0)], r[(1, 0)], r[(2, 0)], r[(0, 1)], r[(1, 1)], r[(2, 1)], r[(0, 2)], r[(1, 2)], r[(2, 2)]]);
    let rotation = Quat::from_mat3(&m).normalize();
    (rotation, cb - rotation * ca)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Points moved by a known rigid motion give that motion back.
        #[test]
        fn recovers_a_rigid_motion(axis in prop::array::uniform3(-1.0f32..1.0), angle in -3.0f32..3.0, t in prop::array::uniform3(-1.0f32..1.0), pts in prop::collection::vec(prop::array::uniform3(-0.1f32..0.1), 4..12)) {
            let axis = Vec3::from(axis);
            prop_assume!(axis.length() > 0.1);
            let q = Quat::from_axis_angle(axis.normalize(), angle);
            let t = Vec3::from(t);
            let from: Vec<Vec3> = pts.into_iter().map(Vec3::from).collect();
            // Points spread in 3D, not on a line or in a plane.
            let spread = from.iter().map(|p| (*p - from[0]).length()).fold(0.0, f32::max);
            prop_assume!(spread > 0.02);
            let to: Vec<Vec3> = from.iter().map(|&p| q * p + t).collect();
            let (r, u) = rigid_fit(&from, &to);
            for (a, b) in from.iter().zip(&to) {
                prop_assert!((r * *a + u - *b).length() < 1e-3, "{a} → {} vs {b}", r * *a + u);
            }
        }
    }

    #[test]
    fn never_reflects() {
        // A mirrored point set has no rotation onto it; the fit is still a rotation.
        let from = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ZERO];
        let to = [-Vec3::X, Vec3::Y, Vec3::Z, Vec3::ZERO];
        let (r, _) = rigid_fit(&from, &to);
        assert!((r.length() - 1.0).abs() < 1e-5);
        assert!(Mat3::from_quat(r).determinant() > 0.99);
    }
}
