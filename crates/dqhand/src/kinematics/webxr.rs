//! The WebXR Hand Input joint names, the canonical ids of the hand's joints.
//!
//! The paper's 20 bones are these 25 joints minus the five tips, which are end sites.

/// Fingers in WebXR order, thumb first.
pub const FINGERS: [&str; 5] = ["thumb", "index-finger", "middle-finger", "ring-finger", "pinky-finger"];

/// The 25 WebXR hand joints in the order of the WebXR specification.
pub const JOINT_NAMES: [&str; 25] = [
    "wrist",
    "thumb-metacarpal",
    "thumb-phalanx-proximal",
    "thumb-phalanx-distal",
    "thumb-tip",
    "index-finger-metacarpal",
    "index-finger-phalanx-proximal",
    "index-finger-phalanx-intermediate",
    "index-finger-phalanx-distal",
    "index-finger-tip",
    "middle-finger-metacarpal",
    "middle-finger-phalanx-proximal",
    "middle-finger-phalanx-intermediate",
    "middle-finger-phalanx-distal",
    "middle-finger-tip",
    "ring-finger-metacarpal",
    "ring-finger-phalanx-proximal",
    "ring-finger-phalanx-intermediate",
    "ring-finger-phalanx-distal",
    "ring-finger-tip",
    "pinky-finger-metacarpal",
    "pinky-finger-phalanx-proximal",
    "pinky-finger-phalanx-intermediate",
    "pinky-finger-phalanx-distal",
    "pinky-finger-tip",
];

/// Whether a joint is a tip (an end site: no bone starts there).
#[must_use]
pub fn is_tip(name: &str) -> bool {
    name.ends_with("-tip")
}

/// The anatomical parent of a WebXR joint: the previous joint of its finger chain, and the
/// wrist for each metacarpal. `None` for the wrist and for names that are not WebXR joints.
#[must_use]
pub fn anatomical_parent(name: &str) -> Option<&'static str> {
    let i = JOINT_NAMES.iter().position(|&n| n == name)?;
    match i {
        0 => None,
        1 | 5 | 10 | 15 | 20 => Some(JOINT_NAMES[0]),
        _ => Some(JOINT_NAMES[i - 1]),
    }
}
