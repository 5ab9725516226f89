//! One timestamped sample of the user's hand, whatever captured it: the unit every source
//! (glove, tracker, hand tracking, recordings, live streams) produces and everything
//! downstream (filtering, retargeting, recognition) consumes.
//!
//! A record is plain fixed-size data (no heap), so reading one into a reused record and
//! passing it down the per-record path allocates nothing.

use glam::{Quat, Vec3};

use crate::kinematics::Side;
use crate::kinematics::webxr;

/// Most sensors a glove record carries (the CyberGlove's 18, with room for 22-sensor gloves).
pub const MAX_GLOVE_SENSORS: usize = 24;
/// Number of WebXR hand joints, the joint set of a record.
pub const JOINT_COUNT: usize = webxr::JOINT_NAMES.len();
/// Number of MediaPipe hand landmarks.
pub const LANDMARK_COUNT: usize = 21;
/// Largest difference of a read quaternion's length from 1 that is rounding in the file.
const UNIT_ROUNDING: f32 = 1e-6;

/// A quaternion read from a file or message (`length` its length, already checked to be near
/// 1), made unit: scaled when it is off by more than rounding, else kept bit for bit, so that
/// what a writer wrote reads back equal (normalising a normalised quaternion can move its last
/// bits).
pub(crate) fn unit_as_read(q: Quat, length: f32) -> Quat {
    if (length - 1.0).abs() > UNIT_ROUNDING {
        q / length
    } else {
        q
    }
}

/// A 6-DOF pose: the wrist tracker's, or a tracked joint's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidPose {
    /// Position, metres.
    pub position: Vec3,
    /// Orientation (unit).
    pub orientation: Quat,
}

/// Raw glove sensor values in the order of the glove's layout ([`super::GloveLayout`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GloveSample {
    values: [f32; MAX_GLOVE_SENSORS],
    len: u8,
}

impl GloveSample {
    /// A sample of `values` (raw sensor units).
    ///
    /// # Panics
    /// If there are more than [`MAX_GLOVE_SENSORS`] values.
    #[must_use]
    pub fn new(values: &[f32]) -> Self {
        assert!(values.len() <= MAX_GLOVE_SENSORS, "{} glove sensors (at most {MAX_GLOVE_SENSORS})", values.len());
        let mut v = [0.0; MAX_GLOVE_SENSORS];
        v[..values.len()].copy_from_slice(values);
        Self { values: v, len: values.len() as u8 }
    }

    /// The raw values, one per sensor of the layout.
    #[must_use]
    pub fn values(&self) -> &[f32] {
        &self.values[..usize::from(self.len)]
    }
}

/// One tracked joint: position, orientation when the tracker gives one, radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackedJoint {
    /// Position, metres.
    pub position: Vec3,
    /// Orientation, `None` for position-only trackers.
    pub orientation: Option<Quat>,
    /// Radius of the finger at the joint (m), 0 when unknown.
    pub radius: f32,
}

/// The 25 WebXR hand joints of one record, in [`webxr::JOINT_NAMES`] order; a tracker may
/// leave some out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointSet {
    joints: [TrackedJoint; JOINT_COUNT],
    present: u32,
}

impl Default for JointSet {
    fn default() -> Self {
        Self::new()
    }
}

impl JointSet {
    /// A set with no joint.
    #[must_use]
    pub const fn new() -> Self {
        const NONE: TrackedJoint = TrackedJoint { position: Vec3::ZERO, orientation: None, radius: 0.0 };
        Self { joints: [NONE; JOINT_COUNT], present: 0 }
    }

    /// Sets joint `index` (WebXR order).
    ///
    /// # Panics
    /// If `index` ≥ [`JOINT_COUNT`].
    pub fn set(&mut self, index: usize, joint: TrackedJoint) {
        self.joints[index] = joint;
        self.present |= 1 << index;
    }

    /// Joint `index` (WebXR order), if the record has it.
    #[must_use]
    pub fn get(&self, index: usize) -> Option<&TrackedJoint> {
        (self.present & (1 << index) != 0).then(|| &self.joints[index])
    }

    /// Whether every one of the 25 joints is present.
    #[must_use]
    pub fn is_complete(&self) -> bool {
        self.present == (1 << JOINT_COUNT) - 1
    }

    /// Joint positions in WebXR order; missing joints are `None`.
    pub fn positions(&self) -> impl Iterator<Item = Option<Vec3>> + '_ {
        (0..JOINT_COUNT).map(|i| self.get(i).map(|j| j.position))
    }
}

/// What a record carries about the fingers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HandData {
    /// Raw dataglove sensor values.
    Glove(GloveSample),
    /// Tracked joint poses (WebXR and OpenXR hand tracking).
    Joints(JointSet),
    /// Landmark positions in MediaPipe's world-landmark order (metres).
    Landmarks([Vec3; LANDMARK_COUNT]),
}

/// One sample from a source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    /// Capture time, seconds (any origin; increasing within a stream).
    pub time: f64,
    /// Which of the user's hands.
    pub side: Side,
    /// The fingers, when the record has them (a tracker-only record has none).
    pub hand: Option<HandData>,
    /// The wrist tracker's pose (the sensor's, before the mounting offset), when present.
    pub tracker: Option<RigidPose>,
    /// When a live input took it, seconds on that input's arrival clock. A live recording
    /// writes it so that a replay judges lateness and "tracking lost" on the clock the live
    /// input judged them on, and so gives the same poses and events; `None` for records from
    /// a source (a live input sets its own, whatever the sender wrote).
    pub arrival: Option<f64>,
}
