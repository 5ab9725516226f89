//! Input layer (paper Figure 1, top): what captures the user's hand — a dataglove and a 6-DOF
//! wrist tracker, or hand tracking (WebXR, OpenXR, camera landmarks) — turned into records,
//! and records turned into poses of the engine step (calibration, retargeting, filtering,
//! dropouts). One file per format or step.

pub mod json_record;
pub mod mediapipe;
mod one_euro;
pub mod openxr;
mod record;
mod rejection;
mod retarget;
mod tracker_mount;

pub use one_euro::{OneEuro, OneEuroParams, OneEuroRotation, OneEuroVec3};
pub use record::{GloveSample, HandData, JointSet, Record, RigidPose, TrackedJoint, JOINT_COUNT, LANDMARK_COUNT, MAX_GLOVE_SENSORS};
pub use rejection::{RejectKind, Rejection, Rejections};
pub use retarget::{Retargeter, CONTACT_FADE, CONTACT_FULL};
pub use tracker_mount::MountingOffset;
