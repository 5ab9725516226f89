//! The 6-DOF wrist tracker's mounting offset: the sensor sits on the back of the wrist (or on
//! the glove's cuff), not at the wrist joint, so its pose is not the wrist's.
//!
//! The offset is the wrist joint's pose in the sensor's frame: `wrist = sensor · offset`.
//! It is measured once ([`MountingOffset::calibrate`]) by holding the hand in a known wrist
//! pose, typically the rest pose shown on screen.

use glam::{Affine3A, Quat, Vec3};
use serde::{Deserialize, Serialize};

use super::RigidPose;
use crate::math::DualQuat;

/// Where the wrist joint is in the tracker sensor's frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MountingOffset {
    /// Wrist joint position in the sensor frame, metres.
    pub p: [f32; 3],
    /// Wrist joint orientation in the sensor frame, `[x, y, z, w]`.
    pub q: [f32; 4],
}

impl Default for MountingOffset {
    /// A sensor strapped flat on the back of the wrist, its axes along the hand's (+Y out of
    /// the back): the joint lies 2 cm below it.
    fn default() -> Self {
        Self { p: [0.0, -0.02, 0.0], q: [0.0, 0.0, 0.0, 1.0] }
    }
}

impl MountingOffset {
    /// The offset that makes `sensor` read as `wrist` (the wrist's known pose while the
    /// sensor reads `sensor`).
    #[must_use]
    pub fn calibrate(sensor: RigidPose, wrist: DualQuat) -> Self {
        let (rotation, translation) = wrist.to_rotation_translation();
        let offset = affine(sensor).inverse() * Affine3A::from_rotation_translation(rotation, translation);
        let (_, q, p) = offset.to_scale_rotation_translation();
        Self { p: p.to_array(), q: q.normalize().to_array() }
    }

    /// The wrist's world pose for a sensor reading.
    #[must_use]
    pub fn wrist(&self, sensor: RigidPose) -> DualQuat {
        let offset = Affine3A::from_rotation_translation(Quat::from_array(self.q).normalize(), Vec3::from(self.p));
        let (_, rotation, translation) = (affine(sensor) * offset).to_scale_rotation_translation();
        DualQuat::from_rotation_translation(rotation.normalize(), translation)
    }

    /// Whether the values are finite and `q` is near unit length.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        let q = Quat::from_array(self.q);
        Vec3::from(self.p).is_finite() && q.is_finite() && (q.length() - 1.0).abs() < 0.01
    }
}

fn affine(pose: RigidPose) -> Affine3A {
    Affine3A::from_rotation_translation(pose.orientation, pose.position)
}
