//! What a pose file asks for, resolved: joint angles of a joint model, or local rotations of
//! a skeleton's own joints.

use glam::Quat;

use super::{JointModel, Pose};

/// A pose resolved against a skeleton (from a pose file or built in code).
#[derive(Clone, Debug, PartialEq)]
pub enum PoseTarget {
    /// Joint angles of a joint model (and the wrist), posed on the anatomical chain.
    Angles {
        /// The joint model the angles belong to.
        model: JointModel,
        /// Wrist pose and angles in radians.
        pose: Pose,
    },
    /// Replacement local rotations of nodes in the file's own hierarchy.
    LocalRotations(Vec<(usize, Quat)>),
}
