//! MediaPipe Hands' 21 landmarks: names, order, and where each sits among the WebXR joints.
//!
//! The order is MediaPipe's (`HandLandmark` in the MediaPipe solution API), as in its world
//! landmarks: metres, origin near the hand's centre. MediaPipe has no finger metacarpal
//! bases; the retargeter places them ([`super::Retargeter::landmark_joints`]).

/// The landmark names in MediaPipe's order.
pub const LANDMARK_NAMES: [&str; 21] = [
    "WRIST",
    "THUMB_CMC",
    "THUMB_MCP",
    "THUMB_IP",
    "THUMB_TIP",
    "INDEX_FINGER_MCP",
    "INDEX_FINGER_PIP",
    "INDEX_FINGER_DIP",
    "INDEX_FINGER_TIP",
    "MIDDLE_FINGER_MCP",
    "MIDDLE_FINGER_PIP",
    "MIDDLE_FINGER_DIP",
    "MIDDLE_FINGER_TIP",
    "RING_FINGER_MCP",
    "RING_FINGER_PIP",
    "RING_FINGER_DIP",
    "RING_FINGER_TIP",
    "PINKY_MCP",
    "PINKY_PIP",
    "PINKY_DIP",
    "PINKY_TIP",
];

/// The WebXR joint (index in [`crate::kinematics::webxr::JOINT_NAMES`]) at each landmark:
/// the thumb's CMC, MCP and IP are the bases of its metacarpal, proximal and distal bones; a
/// finger's MCP, PIP and DIP the bases of its proximal, intermediate and distal phalanges.
pub const WEBXR_INDEX: [usize; 21] = [0, 1, 2, 3, 4, 6, 7, 8, 9, 11, 12, 13, 14, 16, 17, 18, 19, 21, 22, 23, 24];
