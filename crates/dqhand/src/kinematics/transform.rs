//! A node's local transform as glTF stores it: translation, rotation, scale.

use glam::{Affine3A, Quat, Vec3};

/// Translation (m), rotation and scale of a node relative to its parent (glTF's TRS).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Offset from the parent's origin, in the parent's frame (m).
    pub translation: Vec3,
    /// Rotation relative to the parent (unit quaternion).
    pub rotation: Quat,
    /// Scale along the local axes (1 for anatomical bones).
    pub scale: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// No offset, no rotation, unit scale.
    pub const IDENTITY: Self = Self { translation: Vec3::ZERO, rotation: Quat::IDENTITY, scale: Vec3::ONE };

    /// A rigid transform (unit scale).
    #[must_use]
    pub fn from_rotation_translation(rotation: Quat, translation: Vec3) -> Self {
        Self { translation, rotation, scale: Vec3::ONE }
    }

    /// Decomposes an affine matrix (no shear) into TRS.
    #[must_use]
    pub fn from_affine(m: &Affine3A) -> Self {
        let (scale, rotation, translation) = m.to_scale_rotation_translation();
        Self { translation, rotation: rotation.normalize(), scale }
    }

    /// The affine matrix `T * R * S`.
    #[must_use]
    pub fn to_affine(&self) -> Affine3A {
        Affine3A::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }

    /// Whether all components are finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.translation.is_finite() && self.rotation.is_finite() && self.scale.is_finite()
    }
}
