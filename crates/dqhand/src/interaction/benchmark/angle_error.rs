//! How far solved joint angles are from the true ones: the retargeting error
//! (≤ 1° mean on noise-free joints of our own hand).

use crate::kinematics::Pose;

/// Absolute joint angle differences, degrees, accumulated over DOFs and poses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AngleError {
    sum_deg: f64,
    count: usize,
    max_deg: f32,
}

impl AngleError {
    /// The error of `solved` against `truth` (angles only, not the wrist).
    ///
    /// # Panics
    /// If the poses have different DOF counts (poses of two joint models).
    #[must_use]
    pub fn between(truth: &Pose, solved: &Pose) -> Self {
        let mut error = Self::default();
        error.add(truth, solved);
        error
    }

    /// Adds the DOF errors of one more pair of poses.
    ///
    /// # Panics
    /// As [`Self::between`].
    pub fn add(&mut self, truth: &Pose, solved: &Pose) {
        assert_eq!(truth.angles.len(), solved.angles.len(), "poses of {} and {} DOFs", truth.angles.len(), solved.angles.len());
        for (a, b) in truth.angles.iter().zip(&solved.angles) {
            let deg = (a - b).abs().to_degrees();
            self.sum_deg += f64::from(deg);
            self.max_deg = self.max_deg.max(deg);
        }
        self.count += truth.angles.len();
    }

    /// Adds everything `other` accumulated.
    pub fn merge(&mut self, other: &Self) {
        self.sum_deg += other.sum_deg;
        self.count += other.count;
        self.max_deg = self.max_deg.max(other.max_deg);
    }

    /// Mean absolute error over every DOF of every pose, degrees (0 before any pose).
    #[must_use]
    pub fn mean_deg(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.sum_deg / self.count as f64
        }
    }

    /// Largest absolute error of one DOF, degrees.
    #[must_use]
    pub fn max_deg(&self) -> f32 {
        self.max_deg
    }

    /// Angles compared (DOFs × poses).
    #[must_use]
    pub fn count(&self) -> usize {
        self.count
    }
}
