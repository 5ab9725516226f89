//! A hand pose: the wrist's 6-DOF pose plus one angle per degree of freedom.

use crate::math::DualQuat;

/// What a glove and tracker report each frame (paper Figure 1, input layer).
#[derive(Debug, PartialEq)]
pub struct Pose {
    /// The wrist's world transform (the tracker), `None` to keep the rest wrist.
    pub wrist: Option<DualQuat>,
    /// Joint angles in radians, in the order of [`JointModel::dofs`](super::JointModel::dofs).
    pub angles: Vec<f32>,
}

impl Clone for Pose {
    fn clone(&self) -> Self {
        Self { wrist: self.wrist, angles: self.angles.clone() }
    }

    /// Reuses the angle buffer (a derived `Clone` would allocate a new one per copy, and
    /// per-frame code copies poses).
    fn clone_from(&mut self, source: &Self) {
        self.wrist = source.wrist;
        self.angles.clone_from(&source.angles);
    }
}

impl Pose {
    /// The rest pose of a model with `dof_count` degrees of freedom: all angles zero.
    #[must_use]
    pub fn rest(dof_count: usize) -> Self {
        Self { wrist: None, angles: vec![0.0; dof_count] }
    }

    /// Interpolates toward `end` by `t` in [0, 1]: angles linearly, the wrist by ScLERP.
    ///
    /// A missing wrist means the rest wrist, as when posing ([`HandRig::locals`]), so it
    /// stands for `rest_wrist` ([`HandRig::rest_wrist`]) when only one pose has a wrist; the
    /// result has none when neither has.
    ///
    /// [`HandRig::locals`]: super::HandRig::locals
    /// [`HandRig::rest_wrist`]: super::HandRig::rest_wrist
    ///
    /// # Panics
    /// If the poses have different angle counts.
    #[must_use]
    pub fn interpolate(&self, end: &Pose, t: f32, rest_wrist: DualQuat) -> Pose {
        let mut out = self.clone();
        self.interpolate_into(end, t, rest_wrist, &mut out);
        out
    }

    /// [`Self::interpolate`] into `out`, allocating nothing (for per-frame playback).
    ///
    /// # Panics
    /// If the three poses have different angle counts.
    pub fn interpolate_into(&self, end: &Pose, t: f32, rest_wrist: DualQuat, out: &mut Pose) {
        assert!(self.angles.len() == end.angles.len() && out.angles.len() == end.angles.len(), "poses of different joint models");
        for ((o, a), b) in out.angles.iter_mut().zip(&self.angles).zip(&end.angles) {
            *o = a + (b - a) * t;
        }
        out.wrist = match (self.wrist, end.wrist) {
            (None, None) => None,
            (a, b) => Some(a.unwrap_or(rest_wrist).sclerp(b.unwrap_or(rest_wrist), t)),
        };
    }
}
