//! Unit dual quaternions: the rigid transforms of the paper's section 4.4.
//!
//! A dual quaternion `q̂ = q₀ + ε q_ε` stores a rotation in its real part `q₀` and the
//! translation `t` in its dual part `q_ε = ½ t q₀`. Composition is the product, and a blend of
//! several of them (DQB, paper eq. (3)) stays a rigid transform once normalised, which is why
//! the paper uses them as the hand's pseudo-muscle layer.

use core::ops::{Add, Mul, Neg};
use glam::{Affine3A, Mat4, Quat, Vec3};

use super::Screw;

/// A dual quaternion `real + ε dual`, usually of unit norm (a rigid transform).
///
/// Conventions: glam's Hamilton quaternions, column vectors, transforms act on points as
/// `p' = r p r* + t`. The type is plain data; nothing is normalised behind your back.
///
/// ```
/// use dqhand::glam::{Quat, Vec3};
/// use dqhand::math::DualQuat;
///
/// let (r, t) = (Quat::from_rotation_z(90f32.to_radians()), Vec3::new(0.0, 0.0, 0.2));
/// let q = DualQuat::from_rotation_translation(r, t);
/// let p = Vec3::new(0.1, 0.0, 0.0);
/// assert!(q.transform_point3(p).abs_diff_eq(r * p + t, 1e-6), "rotate, then translate");
/// assert!((q.inverse() * q).transform_point3(p).abs_diff_eq(p, 1e-6), "the product composes");
/// // ScLERP halfway along this screw (about and along Z): half the turn, half the advance.
/// let (half_r, half_t) = DualQuat::IDENTITY.sclerp(q, 0.5).to_rotation_translation();
/// assert!(half_r.abs_diff_eq(Quat::from_rotation_z(45f32.to_radians()), 1e-6));
/// assert!(half_t.abs_diff_eq(Vec3::new(0.0, 0.0, 0.1), 1e-6));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualQuat {
    /// Rotation part `q₀` (unit norm for a rigid transform).
    pub real: Quat,
    /// Translation part `q_ε = ½ (0, t) q₀`, orthogonal to `real` for a rigid transform.
    pub dual: Quat,
}

impl Default for DualQuat {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// The pure quaternion `(v, 0)`.
#[inline]
fn pure(v: Vec3) -> Quat {
    Quat::from_xyzw(v.x, v.y, v.z, 0.0)
}

impl DualQuat {
    /// The identity transform.
    pub const IDENTITY: Self = Self { real: Quat::IDENTITY, dual: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0) };

    /// All eight components zero: the neutral element of blending sums (not a transform).
    pub const ZERO: Self =
        Self { real: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0), dual: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0) };

    /// Creates the transform "rotate by `rotation`, then translate by `translation` (m)".
    ///
    /// `rotation` must be normalised.
    #[inline]
    #[must_use]
    pub fn from_rotation_translation(rotation: Quat, translation: Vec3) -> Self {
        Self { real: rotation, dual: pure(translation) * rotation * 0.5 }
    }

    /// A pure rotation about the origin.
    #[inline]
    #[must_use]
    pub fn from_rotation(rotation: Quat) -> Self {
        Self::from_rotation_translation(rotation, Vec3::ZERO)
    }

    /// A pure translation (m).
    #[inline]
    #[must_use]
    pub fn from_translation(translation: Vec3) -> Self {
        Self::from_rotation_translation(Quat::IDENTITY, translation)
    }

    /// The rigid part of an affine matrix (rotation and translation; any scale is discarded,
    /// which is why DQB and QB ignore scaled bones that LB follows).
    #[must_use]
    pub fn from_mat4(m: &Mat4) -> Self {
        let (_, rotation, translation) = m.to_scale_rotation_translation();
        Self::from_rotation_translation(rotation.normalize(), translation)
    }

    /// The rigid part of an affine transform, as [`Self::from_mat4`].
    #[must_use]
    pub fn from_affine(m: &Affine3A) -> Self {
        let (_, rotation, translation) = m.to_scale_rotation_translation();
        Self::from_rotation_translation(rotation.normalize(), translation)
    }

    /// Builds the dual quaternion from its eight components `[x, y, z, w]` real then dual.
    #[inline]
    #[must_use]
    pub fn from_array(a: [f32; 8]) -> Self {
        Self {
            real: Quat::from_xyzw(a[0], a[1], a[2], a[3]),
            dual: Quat::from_xyzw(a[4], a[5], a[6], a[7]),
        }
    }

    /// The eight components `[x, y, z, w]` of the real part, then of the dual part.
    #[inline]
    #[must_use]
    pub fn to_array(self) -> [f32; 8] {
        let (r, d) = (self.real, self.dual);
        [r.x, r.y, r.z, r.w, d.x, d.y, d.z, d.w]
    }

    /// The rotation and translation (m) of a unit dual quaternion: `t = 2 q_ε q₀*`.
    #[inline]
    #[must_use]
    pub fn to_rotation_translation(self) -> (Quat, Vec3) {
        (self.real, self.translation())
    }

    /// The translation (m) of a unit dual quaternion.
    #[inline]
    #[must_use]
    pub fn translation(self) -> Vec3 {
        let t = self.dual * self.real.conjugate() * 2.0;
        Vec3::new(t.x, t.y, t.z)
    }

    /// The 4x4 matrix of a unit dual quaternion.
    #[inline]
    #[must_use]
    pub fn to_mat4(self) -> Mat4 {
        Mat4::from_rotation_translation(self.real, self.translation())
    }

    /// Quaternion conjugate of both parts, `q₀* + ε q_ε*`: the inverse of a unit dual quaternion.
    #[inline]
    #[must_use]
    pub fn conjugate(self) -> Self {
        Self { real: self.real.conjugate(), dual: self.dual.conjugate() }
    }

    /// Dual-number conjugate, `q₀ − ε q_ε`.
    #[inline]
    #[must_use]
    pub fn dual_conjugate(self) -> Self {
        Self { real: self.real, dual: -self.dual }
    }

    /// Both conjugates at once, `q₀* − ε q_ε*`: used to transform points as `q̂ (1 + ε p) q̂⁻*`.
    #[inline]
    #[must_use]
    pub fn combined_conjugate(self) -> Self {
        Self { real: self.real.conjugate(), dual: -self.dual.conjugate() }
    }

    /// The multiplicative inverse; for a non-unit dual quaternion too.
    ///
    /// `(q₀ + ε q_ε)⁻¹ = q₀⁻¹ − ε q₀⁻¹ q_ε q₀⁻¹`. The real part must not be zero.
    #[inline]
    #[must_use]
    pub fn inverse(self) -> Self {
        let ri = self.real.inverse();
        Self { real: ri, dual: -(ri * self.dual * ri) }
    }

    /// The norm of the real part, `‖q₀‖`, which DQB divides by (paper eq. (3)).
    #[inline]
    #[must_use]
    pub fn norm(self) -> f32 {
        self.real.length()
    }

    /// 4D dot product of the real parts; its sign tells whether two rotations share a hemisphere.
    #[inline]
    #[must_use]
    pub fn real_dot(self, other: Self) -> f32 {
        self.real.dot(other.real)
    }

    /// Projects onto the unit dual quaternions: `q₀/‖q₀‖`, and the dual part made orthogonal
    /// to the real part, so the result is an exact rigid transform.
    ///
    /// The real part must not be zero.
    #[must_use]
    pub fn normalize(self) -> Self {
        let inv = 1.0 / self.real.length();
        let real = self.real * inv;
        let dual = self.dual * inv;
        Self { real, dual: dual - real * real.dot(dual) }
    }

    /// Whether `‖q₀‖ = 1` and `q₀ · q_ε = 0` within `tolerance`.
    #[must_use]
    pub fn is_normalized(self, tolerance: f32) -> bool {
        (self.real.length() - 1.0).abs() <= tolerance && self.real.dot(self.dual).abs() <= tolerance
    }

    /// Whether every component is finite.
    #[must_use]
    pub fn is_finite(self) -> bool {
        self.real.is_finite() && self.dual.is_finite()
    }

    /// Transforms a point (m) by a unit dual quaternion: paper eq. (5) with `b̂ = q̂`.
    #[inline]
    #[must_use]
    pub fn transform_point3(self, p: Vec3) -> Vec3 {
        let (d0, a0) = (Vec3::new(self.real.x, self.real.y, self.real.z), self.real.w);
        let (de, ae) = (Vec3::new(self.dual.x, self.dual.y, self.dual.z), self.dual.w);
        p + 2.0 * d0.cross(d0.cross(p) + a0 * p) + 2.0 * (a0 * de - ae * d0 + d0.cross(de))
    }

    /// Transforms a direction (rotation only): paper eq. (6).
    #[inline]
    #[must_use]
    pub fn transform_vector3(self, v: Vec3) -> Vec3 {
        let (d0, a0) = (Vec3::new(self.real.x, self.real.y, self.real.z), self.real.w);
        v + 2.0 * d0.cross(d0.cross(v) + a0 * v)
    }

    /// The screw parameters of a unit dual quaternion (paper eq. (2), Chasles' theorem).
    ///
    /// For a pure translation the angle is zero and the axis is the direction of travel; for
    /// the identity the axis is `+X` by convention.
    #[must_use]
    pub fn to_screw(self) -> Screw {
        // Take the rotation with non-negative scalar part so the angle lies in [0, π].
        let q = if self.real.w < 0.0 { -self } else { self };
        let v = Vec3::new(q.real.x, q.real.y, q.real.z);
        let s = v.length();
        let t = q.translation();
        if s < 1e-6 {
            let pitch = t.length();
            let direction = if pitch > 1e-9 { t / pitch } else { Vec3::X };
            return Screw { angle: 0.0, pitch, direction, moment: Vec3::ZERO };
        }
        let angle = 2.0 * libm::atan2f(s, q.real.w);
        let direction = v / s;
        let pitch = t.dot(direction);
        // The axis passes through the point r = ½ (t⊥ + cot(θ/2) l × t), so m = r × l.
        let t_perp = t - pitch * direction;
        let cot = q.real.w / s;
        let r = 0.5 * (t_perp + cot * direction.cross(t));
        Screw { angle, pitch, direction, moment: r.cross(direction) }
    }

    /// The unit dual quaternion of a screw motion (paper eq. (2)).
    #[must_use]
    pub fn from_screw(screw: Screw) -> Self {
        let Screw { angle, pitch, direction: l, moment: m } = screw;
        let (s, c) = libm::sincosf(0.5 * angle);
        let real = Quat::from_xyzw(l.x * s, l.y * s, l.z * s, c);
        let dv = l * (0.5 * pitch * c) + m * s;
        let dual = Quat::from_xyzw(dv.x, dv.y, dv.z, -0.5 * pitch * s);
        Self { real, dual }
    }

    /// Raises a unit dual quaternion to a real power by scaling its screw (angle and pitch).
    #[must_use]
    pub fn powf(self, t: f32) -> Self {
        let s = self.to_screw();
        Self::from_screw(Screw { angle: s.angle * t, pitch: s.pitch * t, ..s })
    }

    /// Screw linear interpolation (ScLERP) from `self` (t = 0) to `end` (t = 1) along the
    /// shortest screw: constant rotational and translational speed about one fixed axis.
    #[must_use]
    pub fn sclerp(self, end: Self, t: f32) -> Self {
        let end = if self.real_dot(end) < 0.0 { -end } else { end };
        (self * (self.conjugate() * end).powf(t)).normalize()
    }
}

impl Mul for DualQuat {
    type Output = Self;
    /// Composition: `(a * b)` applies `b` first, then `a`.
    #[inline]
    fn mul(self, rhs: Self) -> Self {
        Self { real: self.real * rhs.real, dual: self.real * rhs.dual + self.dual * rhs.real }
    }
}

impl Mul<f32> for DualQuat {
    type Output = Self;
    #[inline]
    fn mul(self, rhs: f32) -> Self {
        Self { real: self.real * rhs, dual: self.dual * rhs }
    }
}

impl Add for DualQuat {
    type Output = Self;
    #[inline]
    fn add(self, rhs: Self) -> Self {
        Self { real: self.real + rhs.real, dual: self.dual + rhs.dual }
    }
}

impl Neg for DualQuat {
    type Output = Self;
    /// The same rigid transform: `q̂` and `−q̂` are antipodal representatives.
    #[inline]
    fn neg(self) -> Self {
        Self { real: -self.real, dual: -self.dual }
    }
}
