//! Hand features for gesture recognition, in the style of today's VR hand-tracking SDKs
//! (per-finger curl, knuckle flexion, spread, thumb–fingertip distances, palm and thumb
//! direction): measured on joint positions only, so any tracker that reports the 25 WebXR
//! joints can drive the recogniser, not only this engine.
//!
//! Every feature, with its name in gesture definitions (`gestures.json`):
//!
//! | name | kind | unit | definition |
//! |---|---|---|---|
//! | `thumb.curl` | curl | 0–1 | (θ_MCP + θ_IP) / 140°, clamped to 1 |
//! | `index.curl` … `pinky.curl` | curl | 0–1 | (θ_MCP + θ_PIP + θ_DIP) / 270°, clamped to 1 |
//! | `thumb.flexion` | flexion | ° | unsigned angle between the thumb's metacarpal and proximal phalanx |
//! | `index.flexion` … `pinky.flexion` | flexion | ° | signed angle of the proximal phalanx from the metacarpal about the knuckle's lateral axis, + toward the palm |
//! | `thumb.abduction` … `ring.abduction` | abduction | ° | angle between the finger's proximal phalanx and the next finger's, both projected on the palm plane (0 if one is perpendicular to the palm) |
//! | `index.opposition` … `pinky.opposition` | opposition | hand sizes | thumb tip to that fingertip / hand size |
//! | `thumb.across` | opposition | hand sizes | thumb tip from the index knuckle toward the little finger's, in the palm's frame |
//! | `thumb.palmar` | opposition | hand sizes | thumb tip from the index knuckle out of the palm (toward what the hand holds) |
//! | `thumb.along` | opposition | hand sizes | thumb tip from the index knuckle toward the fingertips |
//! | `palm.up` | direction | ° | angle between the palm normal (out of the back of the hand) and world up (+Y) |
//! | `thumb.up` | direction | ° | angle between the thumb (proximal phalanx base to tip) and world up (+Y) |
//!
//! θ is the unsigned angle between two successive bones (0 when they are collinear), so a
//! straight finger has curl 0 whatever its direction. 270° is a tight fist's sum (MCP 90°,
//! PIP 110°, DIP 70°), 140° the thumb's (MCP 60°, IP 80°): the anatomical ranges of
//! [`JointModel`](crate::kinematics::JointModel).
//!
//! The hand size is the middle finger's chain, metacarpal base to tip: the sum of four bone
//! lengths, so it does not change with the pose, and it scales distances so that one threshold
//! fits small and large hands (0.16 on the built-in hand of 19 cm length).
//!
//! The thumb's position tells where people put it, which its curl does not: tucked over the
//! fingers (palmar, across), along the index (small across and palmar), across the palm (large
//! across), or out (negative across, or far along or behind). The palm's frame is orthonormal:
//! across (index knuckle → little knuckle), the palm normal, and along (wrist → middle knuckle)
//! made orthogonal to both; it turns with the hand, and it mirrors with a left hand, so the
//! three are the same for a left hand and its mirror image.
//!
//! The palm normal is the dorsal direction, (middle knuckle − wrist) × (index knuckle − pinky
//! knuckle) for a right hand and the opposite for a left one: the joint frames' +Y.

use glam::Vec3;

use crate::kinematics::Side;

/// A finger, thumb first (WebXR order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Finger {
    /// The thumb.
    Thumb,
    /// The index finger.
    Index,
    /// The middle finger.
    Middle,
    /// The ring finger.
    Ring,
    /// The little finger.
    Pinky,
}

impl Finger {
    /// The five, in WebXR order.
    pub const ALL: [Finger; 5] = [Finger::Thumb, Finger::Index, Finger::Middle, Finger::Ring, Finger::Pinky];

    /// The name used in feature names: `thumb`, `index`, `middle`, `ring`, `pinky`.
    #[must_use]
    pub fn name(self) -> &'static str {
        ["thumb", "index", "middle", "ring", "pinky"][self as usize]
    }
}

/// What a feature measures, which decides its hysteresis margin.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FeatureKind {
    /// Curl, 0–1.
    Curl,
    /// Knuckle flexion, degrees.
    Flexion,
    /// Spread between adjacent fingers, degrees.
    Abduction,
    /// Thumb tip to fingertip, hand sizes.
    Opposition,
    /// Angle of a hand direction to world up, degrees.
    Direction,
}

impl FeatureKind {
    /// The name used in the `hysteresis` table of gesture definitions.
    #[must_use]
    pub fn name(self) -> &'static str {
        ["curl", "flexion", "abduction", "opposition", "direction"][self as usize]
    }
}

/// One named feature (the module docs list them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Feature {
    /// Curl of a finger, 0 straight … 1 fully curled.
    Curl(Finger),
    /// Flexion at a finger's knuckle (MCP), degrees.
    Flexion(Finger),
    /// Spread between a finger and the next one (not the pinky), degrees.
    Abduction(Finger),
    /// Thumb tip to a fingertip (not the thumb), in hand sizes.
    Opposition(Finger),
    /// Angle between the palm normal (dorsal) and world up, degrees.
    PalmUp,
    /// Angle between the thumb and world up, degrees.
    ThumbUp,
    /// The thumb tip along one axis of the palm's frame, from the index knuckle, hand sizes.
    ThumbTip(PalmAxis),
}

/// An axis of the palm's frame (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PalmAxis {
    /// Index knuckle toward the little finger's knuckle.
    Across,
    /// Out of the palm's front (the opposite of the palm normal).
    Palmar,
    /// Toward the fingertips.
    Along,
}

use Finger::{Index, Middle, Pinky, Ring, Thumb};

impl Feature {
    /// Every feature, in the order of the module docs.
    pub const ALL: [Feature; 23] = [
        Feature::Curl(Thumb),
        Feature::Curl(Index),
        Feature::Curl(Middle),
        Feature::Curl(Ring),
        Feature::Curl(Pinky),
        Feature::Flexion(Thumb),
        Feature::Flexion(Index),
        Feature::Flexion(Middle),
        Feature::Flexion(Ring),
        Feature::Flexion(Pinky),
        Feature::Abduction(Thumb),
        Feature::Abduction(Index),
        Feature::Abduction(Middle),
        Feature::Abduction(Ring),
        Feature::Opposition(Index),
        Feature::Opposition(Middle),
        Feature::Opposition(Ring),
        Feature::Opposition(Pinky),
        Feature::PalmUp,
        Feature::ThumbUp,
        Feature::ThumbTip(PalmAxis::Across),
        Feature::ThumbTip(PalmAxis::Palmar),
        Feature::ThumbTip(PalmAxis::Along),
    ];

    /// The name in gesture definitions, `<finger>.<kind>` or `palm.up` / `thumb.up`.
    #[must_use]
    pub fn name(self) -> String {
        match self {
            Feature::Curl(f) => format!("{}.curl", f.name()),
            Feature::Flexion(f) => format!("{}.flexion", f.name()),
            Feature::Abduction(f) => format!("{}.abduction", f.name()),
            Feature::Opposition(f) => format!("{}.opposition", f.name()),
            Feature::PalmUp => "palm.up".into(),
            Feature::ThumbUp => "thumb.up".into(),
            Feature::ThumbTip(PalmAxis::Across) => "thumb.across".into(),
            Feature::ThumbTip(PalmAxis::Palmar) => "thumb.palmar".into(),
            Feature::ThumbTip(PalmAxis::Along) => "thumb.along".into(),
        }
    }

    /// The feature called `name`, `None` if there is none.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Feature> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// What it measures.
    #[must_use]
    pub fn kind(self) -> FeatureKind {
        match self {
            Feature::Curl(_) => FeatureKind::Curl,
            Feature::Flexion(_) => FeatureKind::Flexion,
            Feature::Abduction(_) => FeatureKind::Abduction,
            Feature::Opposition(_) | Feature::ThumbTip(_) => FeatureKind::Opposition,
            Feature::PalmUp | Feature::ThumbUp => FeatureKind::Direction,
        }
    }
}

/// The features of one hand in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HandFeatures {
    /// Curl per finger (thumb first), 0–1.
    pub curl: [f32; 5],
    /// Knuckle flexion per finger, degrees.
    pub flexion_deg: [f32; 5],
    /// Spread thumb–index, index–middle, middle–ring, ring–pinky, degrees.
    pub abduction_deg: [f32; 4],
    /// Thumb tip to the index, middle, ring and pinky tips, in hand sizes.
    pub opposition: [f32; 4],
    /// Middle finger chain length, metres: the unit of `opposition`.
    pub hand_size: f32,
    /// Unit normal out of the back of the hand, world frame.
    pub palm_normal: Vec3,
    /// Unit direction of the thumb, proximal phalanx base to tip, world frame.
    pub thumb_direction: Vec3,
    /// The thumb tip from the index knuckle in the palm's frame (across, palmar, along), hand
    /// sizes.
    pub thumb_tip: [f32; 3],
}

/// The first joint of each finger's chain in WebXR order (thumb: its metacarpal).
const CHAIN_START: [usize; 5] = [1, 5, 10, 15, 20];
const TIP: [usize; 5] = [4, 9, 14, 19, 24];
const WRIST: usize = 0;
/// Knuckles (proximal phalanx bases) of the index, middle and pinky.
const INDEX_KNUCKLE: usize = 6;
const MIDDLE_KNUCKLE: usize = 11;
const PINKY_KNUCKLE: usize = 21;
/// Sums of joint angles that count as fully curled, radians.
const THUMB_FULL_CURL: f32 = 140.0 * (core::f32::consts::PI / 180.0);
const FINGER_FULL_CURL: f32 = 270.0 * (core::f32::consts::PI / 180.0);

impl HandFeatures {
    /// Measures the features of a hand from its 25 joint positions in the world (WebXR
    /// order, [`webxr::JOINT_NAMES`](crate::kinematics::webxr::JOINT_NAMES)) and its side.
    /// Allocates nothing.
    ///
    /// Degenerate input (coincident joints) gives NaN features, which match no condition.
    #[must_use]
    pub fn from_positions(p: &[Vec3; 25], side: Side) -> Self {
        let across = p[INDEX_KNUCKLE] - p[PINKY_KNUCKLE];
        let along = p[MIDDLE_KNUCKLE] - p[WRIST];
        let right_normal = along.cross(across).normalize();
        let palm_normal = if side == Side::Right { right_normal } else { -right_normal };
        let bone = |f: usize, i: usize| p[CHAIN_START[f] + i + 1] - p[CHAIN_START[f] + i];

        let mut curl = [0.0; 5];
        let mut flexion_deg = [0.0; 5];
        let mut proximal_on_palm = [Vec3::ZERO; 5];
        for f in 0..5 {
            let joints = if f == 0 { 2 } else { 3 };
            let bent: f32 = (0..joints).map(|i| angle(bone(f, i), bone(f, i + 1))).sum();
            curl[f] = (bent / if f == 0 { THUMB_FULL_CURL } else { FINGER_FULL_CURL }).min(1.0);
            let (metacarpal, proximal) = (bone(f, 0).normalize(), bone(f, 1).normalize());
            flexion_deg[f] = if f == 0 {
                angle(metacarpal, proximal).to_degrees()
            } else {
                // Rotating the metacarpal about n × m turns it toward the palm (−n).
                let lateral = palm_normal.cross(metacarpal).normalize();
                libm::atan2f(metacarpal.cross(proximal).dot(lateral), metacarpal.dot(proximal)).to_degrees()
            };
            proximal_on_palm[f] = proximal.reject_from_normalized(palm_normal);
        }
        let abduction_deg = core::array::from_fn(|f| angle(proximal_on_palm[f], proximal_on_palm[f + 1]).to_degrees());
        let hand_size: f32 = (0..4).map(|i| bone(2, i).length()).sum();
        let opposition = core::array::from_fn(|f| p[TIP[0]].distance(p[TIP[f + 1]]) / hand_size);
        let thumb_direction = (p[TIP[0]] - p[CHAIN_START[0] + 1]).normalize();
        let across_unit = (-across).normalize();
        let along_unit = along.reject_from_normalized(right_normal).reject_from_normalized(across_unit).normalize();
        let tip = (p[TIP[0]] - p[INDEX_KNUCKLE]) / hand_size;
        let thumb_tip = [tip.dot(across_unit), -tip.dot(palm_normal), tip.dot(along_unit)];
        Self { curl, flexion_deg, abduction_deg, opposition, hand_size, palm_normal, thumb_direction, thumb_tip }
    }

    /// The value of one feature, in its unit (module docs).
    #[must_use]
    pub fn get(&self, feature: Feature) -> f32 {
        match feature {
            Feature::Curl(f) => self.curl[f as usize],
            Feature::Flexion(f) => self.flexion_deg[f as usize],
            Feature::Abduction(f) => self.abduction_deg.get(f as usize).copied().unwrap_or(f32::NAN),
            Feature::Opposition(f) => self.opposition.get((f as usize).wrapping_sub(1)).copied().unwrap_or(f32::NAN),
            Feature::PalmUp => angle(self.palm_normal, Vec3::Y).to_degrees(),
            Feature::ThumbUp => angle(self.thumb_direction, Vec3::Y).to_degrees(),
            Feature::ThumbTip(axis) => self.thumb_tip[axis as usize],
        }
    }
}

/// The unsigned angle between two vectors, radians; atan2 keeps it exact near 0 and 180°
/// (acos of a rounded cosine does not), and gives 0 for a zero vector.
fn angle(a: Vec3, b: Vec3) -> f32 {
    libm::atan2f(a.cross(b).length(), a.dot(b))
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::{Feature, Finger, HandFeatures, PalmAxis};
    use crate::kinematics::Side;

    /// A flat right hand, palm down (dorsal +Y), fingers along −Z; the index chain turned by
    /// `index_knuckle` toward the palm at its knuckle.
    fn hand(index_knuckle: f32) -> [Vec3; 25] {
        let mut p = [Vec3::ZERO; 25];
        let thumb = Vec3::new(-1.0, 0.0, -1.0).normalize();
        for (i, d) in [0.01, 0.04, 0.07, 0.095].into_iter().enumerate() {
            p[1 + i] = Vec3::new(-0.02, 0.0, -0.01) + thumb * d;
        }
        for (f, x) in [-0.03f32, -0.01, 0.01, 0.03].into_iter().enumerate() {
            let base = 5 + 5 * f;
            p[base] = Vec3::new(x, 0.0, -0.01);
            p[base + 1] = Vec3::new(x, 0.0, -0.08);
            let along = if f == 0 { Vec3::new(0.0, -libm::sinf(index_knuckle), -libm::cosf(index_knuckle)) } else { -Vec3::Z };
            for (j, length) in [0.04, 0.025, 0.02].into_iter().enumerate() {
                p[base + 2 + j] = p[base + 1 + j] + along * length;
            }
        }
        p
    }

    #[test]
    fn a_straight_hand_has_no_curl_or_flexion() {
        let f = HandFeatures::from_positions(&hand(0.0), Side::Right);
        for finger in Finger::ALL {
            assert!(f.get(Feature::Curl(finger)).abs() < 1e-5, "{finger:?} {f:?}");
            assert!(f.get(Feature::Flexion(finger)).abs() < 1e-3, "{finger:?} {f:?}");
        }
        assert!((f.hand_size - 0.155).abs() < 1e-6);
        assert!(f.get(Feature::PalmUp) < 1e-3, "palm down: the back of the hand faces up");
        assert!((f.get(Feature::ThumbUp) - 90.0).abs() < 1e-3);
        assert!((f.get(Feature::Abduction(Finger::Thumb)) - 45.0).abs() < 1e-3);
        assert!(f.get(Feature::Abduction(Finger::Index)).abs() < 1e-3);
        // The thumb tip 5.7 cm to the radial side of the index knuckle, 3 mm toward the wrist.
        let thumb = [-0.0572 / 0.155, 0.0, -0.0028 / 0.155];
        for (axis, expected) in [PalmAxis::Across, PalmAxis::Palmar, PalmAxis::Along].into_iter().zip(thumb) {
            assert!((f.get(Feature::ThumbTip(axis)) - expected).abs() < 1e-3, "{axis:?} {f:?}");
        }
        let tips = (hand(0.0)[4] - hand(0.0)[9]).length();
        assert!((f.get(Feature::Opposition(Finger::Index)) - tips / 0.155).abs() < 1e-6);
    }

    #[test]
    fn a_finger_bent_90_degrees_at_the_knuckle_has_flexion_90() {
        let f = HandFeatures::from_positions(&hand(90f32.to_radians()), Side::Right);
        assert!((f.get(Feature::Flexion(Finger::Index)) - 90.0).abs() < 1e-3, "{f:?}");
        assert!((f.get(Feature::Curl(Finger::Index)) - 1.0 / 3.0).abs() < 1e-5, "{f:?}");
        let back = HandFeatures::from_positions(&hand(-20f32.to_radians()), Side::Right);
        assert!((back.get(Feature::Flexion(Finger::Index)) + 20.0).abs() < 1e-3, "hyperextension is negative");
    }

    #[test]
    fn a_mirrored_left_hand_has_the_same_features() {
        let mirror = hand(60f32.to_radians()).map(|p| p * Vec3::new(-1.0, 1.0, 1.0));
        let (left, right) = (HandFeatures::from_positions(&mirror, Side::Left), HandFeatures::from_positions(&hand(60f32.to_radians()), Side::Right));
        for feature in Feature::ALL {
            assert!((left.get(feature) - right.get(feature)).abs() < 1e-3, "{}: {} vs {}", feature.name(), left.get(feature), right.get(feature));
        }
        assert_eq!(Feature::from_name("pinky.abduction"), None);
        assert_eq!(Feature::from_name("thumb.up"), Some(Feature::ThumbUp));
    }
}
