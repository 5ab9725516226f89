//! Input layer (paper Figure 1, top): what captures the user's hand — a dataglove and a 6-DOF
//! wrist tracker, or hand tracking (WebXR, OpenXR, camera landmarks) — turned into records,
//! and records turned into poses of the engine step (calibration, retargeting, filtering,
//! dropouts). One file per format or step.

mod glove_calibration;
mod glove_csv;
mod glove_layout;
mod glove_mapper;
mod glove_mapping;
mod config;
pub mod array_record;
pub mod json_record;
pub mod mediapipe;
mod one_euro;
mod pipeline;
pub mod openxr;
mod record;
mod rejection;
mod retarget;
mod tracker_mount;

pub use config::{GestureAction, InputConfig};
pub use glove_calibration::{Calibration, SensorCalibration, MIN_HOLD_FRAMES, MIN_MOVEMENT};
pub use glove_csv::{GloveCsvReader, GloveCsvWriter};
pub use glove_layout::{GloveLayout, Sensor, SensorKind, RAW_MAX};
pub use glove_mapper::GloveMapper;
pub use glove_mapping::{Coupling, MappingEntry, MappingTable};
pub use one_euro::{Filtered, OneEuro, OneEuroFilter, OneEuroParams, OneEuroRotation, OneEuroVec3, Velocity};
pub use pipeline::{InputPipeline, Tracking, MAX_LEAD_S};
pub use record::{GloveSample, HandData, JointSet, Record, RigidPose, TrackedJoint, JOINT_COUNT, LANDMARK_COUNT, MAX_GLOVE_SENSORS};
pub use rejection::{RejectKind, Rejection, Rejections};
pub use retarget::{rest_side, Retargeter, CONTACT_FADE, CONTACT_FULL, CONTACT_MARGIN};
pub use tracker_mount::MountingOffset;
