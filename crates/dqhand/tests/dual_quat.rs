//! Dual quaternions: construction, product, conjugates, inverse, transforms, matrices, screw
//! parameters (paper eq. (2)) and ScLERP.

mod support;

use dqhand::math::{DualQuat, Screw};
use glam::{Mat4, Quat, Vec3};
use proptest::prelude::*;
use support::{rotation, vec3};

fn rigid() -> impl Strategy<Value = DualQuat> {
    (rotation(), vec3(2.0)).prop_map(|(r, t)| DualQuat::from_rotation_translation(r, t))
}

proptest! {
    #[test]
    fn rotation_translation_round_trip(r in rotation(), t in vec3(5.0)) {
        let q = DualQuat::from_rotation_translation(r, t);
        let (r2, t2) = q.to_rotation_translation();
        assert_close!(t2, t, 1e-5);
        prop_assert!(r2.dot(r).abs() > 1.0 - 1e-6);
        prop_assert!(q.is_normalized(1e-5));
    }

    #[test]
    fn transforms_points_and_vectors_like_the_matrix(q in rigid(), p in vec3(3.0)) {
        let m = q.to_mat4();
        assert_close!(q.transform_point3(p), m.transform_point3(p), 1e-5);
        assert_close!(q.transform_vector3(p), m.transform_vector3(p), 1e-5);
        // The sandwich q̂ (1 + ε p) q̂⁻* gives the same point.
        let pd = DualQuat { real: Quat::IDENTITY, dual: Quat::from_xyzw(p.x, p.y, p.z, 0.0) };
        let s = q * pd * q.combined_conjugate();
        assert_close!(Vec3::new(s.dual.x, s.dual.y, s.dual.z), q.transform_point3(p), 1e-4);
    }

    #[test]
    fn product_composes(a in rigid(), b in rigid(), p in vec3(3.0)) {
        assert_close!((a * b).transform_point3(p), a.transform_point3(b.transform_point3(p)), 1e-4);
        assert_close!((a * b).to_mat4().transform_point3(p), (a.to_mat4() * b.to_mat4()).transform_point3(p), 1e-4);
    }

    #[test]
    fn inverse_and_conjugate_undo(q in rigid(), p in vec3(3.0)) {
        assert_close!(q.inverse().transform_point3(q.transform_point3(p)), p, 1e-4);
        assert_close!(q.conjugate().transform_point3(q.transform_point3(p)), p, 1e-4);
        let i = q * q.inverse();
        assert_close!(i.transform_point3(p), p, 1e-4);
        // The dual conjugate of a pure translation reverses it.
        let t = DualQuat::from_translation(p);
        assert_close!(t.dual_conjugate().translation(), -p, 1e-5);
    }

    #[test]
    fn matrix_round_trip(q in rigid(), p in vec3(3.0)) {
        let back = DualQuat::from_mat4(&q.to_mat4());
        assert_close!(back.transform_point3(p), q.transform_point3(p), 1e-4);
        prop_assert_eq!(DualQuat::from_array(q.to_array()), q);
    }

    #[test]
    fn normalize_projects_onto_rigid_transforms(q in rigid(), s in 0.2f32..5.0, p in vec3(2.0)) {
        let n = (q * s).normalize();
        prop_assert!(n.is_normalized(1e-5));
        assert_close!(n.transform_point3(p), q.transform_point3(p), 1e-4);
    }

    #[test]
    fn screw_round_trip_and_meaning(q in rigid(), p in vec3(2.0)) {
        let s = q.to_screw();
        prop_assert!((0.0..=std::f32::consts::PI + 1e-5).contains(&s.angle));
        assert_close!(s.direction.length(), 1.0, 1e-4);
        // The moment is perpendicular to the axis; points on the axis only slide along it.
        // A nearly pure translation has its axis far away (|m| ~ |t| / θ), and f32 keeps
        // these relations only to a few ulps of that distance.
        let far = s.moment.length();
        assert_close!(s.moment.dot(s.direction), 0.0, 1e-4 + 1e-6 * far);
        let on_axis = s.closest_point_to_origin();
        assert_close!(q.transform_point3(on_axis), on_axis + s.direction * s.pitch, 2e-3 + 1e-6 * far);
        assert_close!(DualQuat::from_screw(s).transform_point3(p), q.transform_point3(p), 2e-3);
    }

    #[test]
    fn sclerp_endpoints_and_halves(a in rigid(), b in rigid(), p in vec3(1.0)) {
        assert_close!(a.sclerp(b, 0.0).transform_point3(p), a.transform_point3(p), 1e-3);
        assert_close!(a.sclerp(b, 1.0).transform_point3(p), b.transform_point3(p), 2e-3);
        // Two half steps of the relative screw make the whole step.
        let half = a.conjugate() * a.sclerp(b, 0.5);
        assert_close!(a.transform_point3((half * half).transform_point3(p)), b.transform_point3(p), 2e-3);
        prop_assert!(a.sclerp(b, 0.3).is_normalized(1e-4));
    }
}

#[test]
fn screw_of_a_known_motion() {
    // 90° about +Z through the point (1, 0, 0), then 0.5 m along +Z.
    let axis_point = Vec3::X;
    let motion = Mat4::from_translation(Vec3::Z * 0.5 + axis_point)
        * Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2)
        * Mat4::from_translation(-axis_point);
    let s = DualQuat::from_mat4(&motion).to_screw();
    assert_close!(s.angle, std::f32::consts::FRAC_PI_2, 1e-5);
    assert_close!(s.pitch, 0.5, 1e-5);
    assert_close!(s.direction, Vec3::Z, 1e-5);
    assert_close!(s.moment, axis_point.cross(Vec3::Z), 1e-5);
    assert_close!(s.closest_point_to_origin(), axis_point, 1e-5);
}

#[test]
fn screw_of_pure_translation_and_identity() {
    let s = DualQuat::from_translation(Vec3::new(0.0, 3.0, 4.0)).to_screw();
    assert_eq!(s.angle, 0.0);
    assert_close!(s.pitch, 5.0, 1e-5);
    assert_close!(s.direction, Vec3::new(0.0, 0.6, 0.8), 1e-5);
    let i = DualQuat::IDENTITY.to_screw();
    assert_eq!(i, Screw { angle: 0.0, pitch: 0.0, direction: Vec3::X, moment: Vec3::ZERO });
}

#[test]
fn sclerp_moves_at_constant_speed_about_one_axis() {
    let a = DualQuat::IDENTITY;
    let b = DualQuat::from_rotation_translation(Quat::from_rotation_y(2.0), Vec3::new(1.0, 2.0, 0.0));
    let p = Vec3::new(0.3, -0.2, 0.7);
    let pts: Vec<Vec3> = (0..=10).map(|i| a.sclerp(b, i as f32 / 10.0).transform_point3(p)).collect();
    let steps: Vec<f32> = pts.windows(2).map(|w| w[0].distance(w[1])).collect();
    for s in &steps {
        assert_close!(*s, steps[0], 1e-4);
    }
}

#[test]
fn antipodal_dual_quaternions_are_the_same_transform() {
    let q = DualQuat::from_rotation_translation(Quat::from_rotation_x(1.0), Vec3::ONE);
    let p = Vec3::new(0.1, 0.2, 0.3);
    assert_close!((-q).transform_point3(p), q.transform_point3(p), 1e-6);
    // ScLERP takes the short way even when given the antipode.
    assert_close!(DualQuat::IDENTITY.sclerp(-q, 0.5).transform_point3(p), DualQuat::IDENTITY.sclerp(q, 0.5).transform_point3(p), 1e-5);
}
