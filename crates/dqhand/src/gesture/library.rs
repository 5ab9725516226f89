//! The daily gestures of the paper's Figure 7 and of common VR use, as joint angles.
//!
//! Angles are degrees on the `full` joint model; posed on the `paper` model the DOFs it lacks
//! (thumb CMC, thumb MCP abduction, palm cupping) stay at rest.

use crate::kinematics::{JointModel, Pose};

/// A named hand shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gesture {
    /// Short name (`fist`, `point`, …).
    pub name: &'static str,
    /// Groups of `(dof name, degrees)` (one group per finger or shared shape), every DOF
    /// away from rest.
    pub angles_deg: &'static [&'static [(&'static str, f32)]],
}

impl Gesture {
    /// The gesture as a pose of `model` (wrist at rest); DOFs the model lacks are skipped.
    #[must_use]
    pub fn pose(&self, model: JointModel) -> Pose {
        let mut pose = Pose::rest(model.dof_count());
        for &(name, deg) in self.angles_deg.iter().copied().flatten() {
            if let Ok(i) = model.dof_index(name) {
                pose.angles[i] = deg.to_radians();
            }
        }
        pose
    }
}

/// The library entry called `name`.
#[must_use]
pub fn gesture(name: &str) -> Option<&'static Gesture> {
    GESTURES.iter().find(|g| g.name == name)
}

macro_rules! curl {
    ($f:literal, $mcp:expr, $pip:expr, $dip:expr) => {
        [
            (concat!($f, "-phalanx-proximal.flex"), $mcp),
            (concat!($f, "-phalanx-intermediate.flex"), $pip),
            (concat!($f, "-phalanx-distal.flex"), $dip),
        ]
    };
}

const INDEX_FIST: [(&str, f32); 3] = curl!("index-finger", 85.0, 100.0, 60.0);
const MIDDLE_FIST: [(&str, f32); 3] = curl!("middle-finger", 88.0, 100.0, 60.0);
const RING_FIST: [(&str, f32); 3] = curl!("ring-finger", 88.0, 100.0, 60.0);
const PINKY_FIST: [(&str, f32); 3] = curl!("pinky-finger", 88.0, 95.0, 60.0);
const CUP: [(&str, f32); 2] = [("ring-finger-metacarpal.flex", 8.0), ("pinky-finger-metacarpal.flex", 15.0)];
/// The thumb folded over the middle phalanges of the curled fingers.
const THUMB_OVER: [(&str, f32); 4] = [
    ("thumb-metacarpal.abd", 10.0),
    ("thumb-metacarpal.flex", 10.0),
    ("thumb-phalanx-proximal.flex", 30.0),
    ("thumb-phalanx-distal.flex", 75.0),
];
/// The thumb tucked against the side of the palm, as when counting on the fingers.
const THUMB_IN: [(&str, f32); 4] = [
    ("thumb-metacarpal.abd", -10.0),
    ("thumb-metacarpal.flex", 5.0),
    ("thumb-phalanx-proximal.flex", 55.0),
    ("thumb-phalanx-distal.flex", 70.0),
];
const THUMB_OUT: [(&str, f32); 3] =
    [("thumb-metacarpal.abd", 20.0), ("thumb-metacarpal.flex", -15.0), ("thumb-phalanx-distal.flex", -10.0)];

const OK_INDEX: [(&str, f32); 3] = curl!("index-finger", 45.0, 65.0, 35.0);
/// The thumb pad on the index pad (angles from a grid search over the thumb's DOFs for the two
/// tips 16 mm apart on the built-in hand; the same for `PINCH_THUMB`).
const OK_THUMB: [(&str, f32); 3] =
    [("thumb-metacarpal.flex", 30.0), ("thumb-phalanx-proximal.flex", -5.0), ("thumb-phalanx-distal.flex", 50.0)];
const OK_OTHERS: [(&str, f32); 5] = [
    ("middle-finger-phalanx-proximal.flex", 15.0),
    ("middle-finger-phalanx-proximal.abd", -5.0),
    ("ring-finger-phalanx-proximal.flex", 20.0),
    ("ring-finger-phalanx-proximal.abd", 8.0),
    ("pinky-finger-phalanx-proximal.abd", 15.0),
];
const PINCH_INDEX: [(&str, f32); 3] = curl!("index-finger", 40.0, 45.0, 20.0);
const PINCH_THUMB: [(&str, f32); 4] = [
    ("thumb-metacarpal.flex", 35.0),
    ("thumb-phalanx-proximal.flex", -5.0),
    ("thumb-phalanx-proximal.abd", 5.0),
    ("thumb-phalanx-distal.flex", 10.0),
];
const PINCH_OTHERS: [(&str, f32); 6] = [
    ("middle-finger-phalanx-proximal.flex", 30.0),
    ("middle-finger-phalanx-intermediate.flex", 40.0),
    ("ring-finger-phalanx-proximal.flex", 35.0),
    ("ring-finger-phalanx-intermediate.flex", 45.0),
    ("pinky-finger-phalanx-proximal.flex", 40.0),
    ("pinky-finger-phalanx-intermediate.flex", 50.0),
];
const V_SPREAD: [(&str, f32); 2] = [("index-finger-phalanx-proximal.abd", 12.0), ("middle-finger-phalanx-proximal.abd", -10.0)];
const PINKY_SPREAD: [(&str, f32); 1] = [("pinky-finger-phalanx-proximal.abd", 20.0)];

const FIST: &[&[(&str, f32)]] = &[&INDEX_FIST, &MIDDLE_FIST, &RING_FIST, &PINKY_FIST, &CUP, &THUMB_OVER];
const POINT: &[&[(&str, f32)]] = &[&MIDDLE_FIST, &RING_FIST, &PINKY_FIST, &CUP, &THUMB_OVER];
const VICTORY: &[&[(&str, f32)]] = &[&RING_FIST, &PINKY_FIST, &CUP, &THUMB_OVER, &V_SPREAD];

/// The gesture library, in demo order.
pub const GESTURES: [Gesture; 14] = [
    Gesture { name: "open", angles_deg: &[] },
    Gesture { name: "fist", angles_deg: FIST },
    Gesture { name: "point", angles_deg: POINT },
    Gesture { name: "victory", angles_deg: VICTORY },
    Gesture { name: "ok", angles_deg: &[&OK_INDEX, &OK_THUMB, &OK_OTHERS] },
    Gesture { name: "thumbs-up", angles_deg: &[&INDEX_FIST, &MIDDLE_FIST, &RING_FIST, &PINKY_FIST, &CUP, &THUMB_OUT] },
    Gesture { name: "pinch", angles_deg: &[&PINCH_INDEX, &PINCH_THUMB, &PINCH_OTHERS] },
    Gesture { name: "call-me", angles_deg: &[&INDEX_FIST, &MIDDLE_FIST, &RING_FIST, &PINKY_SPREAD, &THUMB_OUT] },
    Gesture { name: "horns", angles_deg: &[&MIDDLE_FIST, &RING_FIST, &THUMB_OVER] },
    Gesture { name: "one", angles_deg: POINT },
    Gesture { name: "two", angles_deg: VICTORY },
    Gesture { name: "three", angles_deg: &[&PINKY_FIST, &THUMB_IN] },
    Gesture { name: "four", angles_deg: &[&THUMB_IN] },
    Gesture { name: "five", angles_deg: &[] },
];

/// The whole library as one animation: each gesture reached from the previous one in
/// `steps` frames (angles interpolated linearly), back to the first at the end.
#[must_use]
pub fn tour(model: JointModel, steps: usize) -> Vec<Pose> {
    let poses: Vec<Pose> = GESTURES.iter().map(|g| g.pose(model)).collect();
    let mut frames = Vec::with_capacity(poses.len() * steps);
    for (i, a) in poses.iter().enumerate() {
        let b = &poses[(i + 1) % poses.len()];
        frames.extend((0..steps).map(|s| a.interpolate(b, s as f32 / steps as f32)));
    }
    frames
}
