//! OpenXR `XR_EXT_hand_tracking`: the 26 joints of `XrHandJointEXT`, in the specification's
//! order. They are WebXR's 25 joints plus the palm first, in the same frames (−Z along the
//! bone, +Y on the back of the hand) and world axes (+Y up, metres). The palm is ignored.

/// The `XrHandJointEXT` names in enum order (value = index).
pub const JOINT_NAMES: [&str; 26] = [
    "XR_HAND_JOINT_PALM_EXT",
    "XR_HAND_JOINT_WRIST_EXT",
    "XR_HAND_JOINT_THUMB_METACARPAL_EXT",
    "XR_HAND_JOINT_THUMB_PROXIMAL_EXT",
    "XR_HAND_JOINT_THUMB_DISTAL_EXT",
    "XR_HAND_JOINT_THUMB_TIP_EXT",
    "XR_HAND_JOINT_INDEX_METACARPAL_EXT",
    "XR_HAND_JOINT_INDEX_PROXIMAL_EXT",
    "XR_HAND_JOINT_INDEX_INTERMEDIATE_EXT",
    "XR_HAND_JOINT_INDEX_DISTAL_EXT",
    "XR_HAND_JOINT_INDEX_TIP_EXT",
    "XR_HAND_JOINT_MIDDLE_METACARPAL_EXT",
    "XR_HAND_JOINT_MIDDLE_PROXIMAL_EXT",
    "XR_HAND_JOINT_MIDDLE_INTERMEDIATE_EXT",
    "XR_HAND_JOINT_MIDDLE_DISTAL_EXT",
    "XR_HAND_JOINT_MIDDLE_TIP_EXT",
    "XR_HAND_JOINT_RING_METACARPAL_EXT",
    "XR_HAND_JOINT_RING_PROXIMAL_EXT",
    "XR_HAND_JOINT_RING_INTERMEDIATE_EXT",
    "XR_HAND_JOINT_RING_DISTAL_EXT",
    "XR_HAND_JOINT_RING_TIP_EXT",
    "XR_HAND_JOINT_LITTLE_METACARPAL_EXT",
    "XR_HAND_JOINT_LITTLE_PROXIMAL_EXT",
    "XR_HAND_JOINT_LITTLE_INTERMEDIATE_EXT",
    "XR_HAND_JOINT_LITTLE_DISTAL_EXT",
    "XR_HAND_JOINT_LITTLE_TIP_EXT",
];

/// The OpenXR joint's index in the WebXR order, `None` for the palm.
#[must_use]
pub fn webxr_index(openxr: usize) -> Option<usize> {
    (1..JOINT_NAMES.len()).contains(&openxr).then(|| openxr - 1)
}
