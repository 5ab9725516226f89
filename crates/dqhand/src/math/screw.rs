//! Screw parameters (Chasles' theorem): every rigid motion is a rotation about an axis and a
//! translation along the same axis.

use glam::Vec3;

/// The screw form of a rigid transform, the dual angle and dual axis of paper eq. (2).
///
/// The paper writes `θ̂ = θ₀ + ε θ_ε` and `ŝ = s₀ + ε s_ε`: here `angle = θ₀` (rad),
/// `pitch = θ_ε` (the translation along the axis, m), `direction = s₀` (unit) and
/// `moment = s_ε = r × s₀` for any point `r` on the axis (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Screw {
    /// Rotation angle about the axis, radians, in `[0, π]` as returned by `to_screw`.
    pub angle: f32,
    /// Translation along the axis (m).
    pub pitch: f32,
    /// Unit direction of the axis.
    pub direction: Vec3,
    /// Moment of the axis about the origin, `r × direction` (m).
    pub moment: Vec3,
}

impl Screw {
    /// The point of the axis closest to the origin, `direction × moment` (m).
    #[must_use]
    pub fn closest_point_to_origin(&self) -> Vec3 {
        self.direction.cross(self.moment)
    }
}
