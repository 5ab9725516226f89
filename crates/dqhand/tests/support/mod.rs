//! Shared test helpers.
#![allow(dead_code)]

use glam::{Quat, Vec3};
use proptest::prelude::*;

pub mod kernels;

/// The WebXR generic right hand (a mesh the project did not make): `DQHAND_WEBXR_HAND`, else
/// the npm asset under third_party/ (`make test` installs it).
pub fn webxr_hand() -> dqhand::model::Model {
    let path = std::env::var_os("DQHAND_WEBXR_HAND").map_or_else(
        || std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/right.glb"),
        std::path::PathBuf::from,
    );
    assert!(path.is_file(), "the WebXR generic hand {} is missing: run `make test`, or set DQHAND_WEBXR_HAND", path.display());
    dqhand::io::load_gltf(&path).expect("the WebXR generic hand loads")
}

/// Asserts `|a - b| <= tol` for anything with a distance, printing both values, the
/// tolerance and the difference (and, after them, a message formatted from the rest).
#[macro_export]
macro_rules! assert_close {
    ($a:expr, $b:expr, $tol:expr) => {{
        let (a, b, tol) = ($a, $b, $tol);
        let d = $crate::support::Distance::distance(&a, &b);
        assert!(d <= tol, "assert_close failed:\n  left:  {:?}\n  right: {:?}\n  tolerance {} < difference {}", a, b, tol, d);
    }};
    ($a:expr, $b:expr, $tol:expr, $($message:tt)+) => {{
        let (a, b, tol) = ($a, $b, $tol);
        let d = $crate::support::Distance::distance(&a, &b);
        assert!(d <= tol, "assert_close failed:\n  left:  {:?}\n  right: {:?}\n  tolerance {} < difference {}\n  {}", a, b, tol, d, format_args!($($message)+));
    }};
}

/// Distance between two values of the same kind.
pub trait Distance {
    fn distance(&self, other: &Self) -> f32;
}

impl Distance for f32 {
    fn distance(&self, other: &Self) -> f32 {
        (self - other).abs()
    }
}

impl Distance for Vec3 {
    fn distance(&self, other: &Self) -> f32 {
        (*self - *other).length()
    }
}

impl Distance for [f32; 3] {
    fn distance(&self, other: &Self) -> f32 {
        Vec3::from(*self).distance(Vec3::from(*other))
    }
}

pub fn vec3(range: f32) -> impl Strategy<Value = Vec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Uniformly distributed-enough unit quaternions (axis on the sphere, any angle).
pub fn rotation() -> impl Strategy<Value = Quat> {
    (vec3(1.0), -3.1f32..3.1).prop_filter_map("axis too short", |(axis, angle)| {
        (axis.length() > 0.1).then(|| Quat::from_axis_angle(axis.normalize(), angle))
    })
}

/// Poses `model` with `target` through its kinematics layer; returns the skinning transforms
/// and the angles clamped.
pub fn pose_skinning(model: &dqhand::model::Model, target: &dqhand::kinematics::PoseTarget, limits: dqhand::kinematics::Limits) -> dqhand::Result<(Vec<glam::Affine3A>, Vec<dqhand::kinematics::ClampedAngle>)> {
    let (layer, clamped) = model.pose_target(target, limits)?;
    Ok((layer.skinning().to_vec(), clamped))
}

/// World transforms of `rig`'s skeleton posed by `pose`: the rig's local transforms, then
/// forward kinematics.
pub fn world_of(rig: &dqhand::kinematics::HandRig, pose: &dqhand::kinematics::Pose, limits: dqhand::kinematics::Limits) -> Vec<glam::Affine3A> {
    let mut locals = rig.skeleton().rest_locals();
    rig.locals(pose, limits, &mut locals);
    let mut world = vec![glam::Affine3A::IDENTITY; locals.len()];
    dqhand::kinematics::forward_kinematics(rig.skeleton(), &locals, &mut world);
    world
}
