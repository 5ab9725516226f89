//! Input layer (paper Figure 1, top): what captures the user's hand — a dataglove and a 6-DOF
//! wrist tracker, or hand tracking (WebXR, OpenXR, camera landmarks) — turned into records,
//! and records turned into poses of the engine step (calibration, retargeting, filtering,
//! dropouts). One file per format or step.

mod record;
mod rejection;

pub use record::{GloveSample, HandData, JointSet, Record, RigidPose, TrackedJoint, JOINT_COUNT, LANDMARK_COUNT, MAX_GLOVE_SENSORS};
pub use rejection::{RejectKind, Rejection, Rejections};
