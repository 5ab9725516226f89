//! The daily gestures of the paper's Figure 7 and of common VR use, as joint angles.
//!
//! Angles are degrees on the `full` joint model; posed on the `paper` model the DOFs it lacks
//! (thumb CMC, thumb MCP abduction, palm cupping) stay at rest.

use crate::kinematics::{JointModel, Pose};
use crate::{Error, Result};

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
    /// The gesture as a pose of `model` (wrist at rest); DOFs the model lacks are skipped
    /// (every name is a DOF of the `full` model: [`Self::check`]).
    #[must_use]
    pub fn pose(&self, model: JointModel) -> Pose {
        debug_assert!(self.check().is_ok(), "gesture {:?} names a DOF no joint model has", self.name);
        let mut pose = Pose::rest(model.dof_count());
        for &(name, deg) in self.angles_deg.iter().copied().flatten() {
            if let Ok(i) = model.dof_index(name) {
                pose.angles[i] = deg.to_radians();
            }
        }
        pose
    }

    /// Checks that every angle names a DOF of the `full` model, so that [`Self::pose`] drops
    /// only the DOFs a smaller model lacks, never a misspelled one.
    ///
    /// # Errors
    /// [`Error::UnknownName`] for the first name that is no DOF, naming the gesture.
    pub fn check(&self) -> Result<()> {
        for &(name, _) in self.angles_deg.iter().copied().flatten() {
            JointModel::Full.dof_index(name).map_err(|e| match e {
                Error::UnknownName { name, valid, .. } => Error::UnknownName { kind: "degree of freedom (in a gesture)", name: format!("{}: {name}", self.name), valid },
                other => other,
            })?;
        }
        Ok(())
    }
}

/// The library entry called `name`.
///
/// # Errors
/// [`Error::UnknownName`] listing the gestures.
pub fn gesture(name: &str) -> Result<&'static Gesture> {
    GESTURES.iter().find(|g| g.name == name).ok_or_else(|| Error::UnknownName {
        kind: "gesture",
        name: name.to_owned(),
        valid: GESTURES.map(|g| g.name).join(", "),
    })
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
/// The other fingers half curled, clearly not extended (curl about 0.45–0.5).
const PINCH_OTHERS: [[(&str, f32); 3]; 3] =
    [curl!("middle-finger", 40.0, 55.0, 25.0), curl!("ring-finger", 45.0, 60.0, 25.0), curl!("pinky-finger", 50.0, 65.0, 25.0)];
const V_SPREAD: [(&str, f32); 2] = [("index-finger-phalanx-proximal.abd", 12.0), ("middle-finger-phalanx-proximal.abd", -10.0)];
const PINKY_SPREAD: [(&str, f32); 1] = [("pinky-finger-phalanx-proximal.abd", 20.0)];

const FIST: &[&[(&str, f32)]] = &[&INDEX_FIST, &MIDDLE_FIST, &RING_FIST, &PINKY_FIST, &CUP, &THUMB_OVER];
const POINT: &[&[(&str, f32)]] = &[&MIDDLE_FIST, &RING_FIST, &PINKY_FIST, &CUP, &THUMB_OVER];
const VICTORY: &[&[(&str, f32)]] = &[&RING_FIST, &PINKY_FIST, &CUP, &THUMB_OVER, &V_SPREAD];

/// The thumb spread out beside the open hand, its pad turned toward the index.
const THUMB_SPREAD: [(&str, f32); 3] =
    [("thumb-metacarpal.abd", 25.0), ("thumb-metacarpal.flex", -15.0), ("thumb-phalanx-distal.flex", -5.0)];
const OPEN_SPREAD: [(&str, f32); 3] = [
    ("index-finger-phalanx-proximal.abd", 5.0),
    ("ring-finger-phalanx-proximal.abd", 5.0),
    ("pinky-finger-phalanx-proximal.abd", 10.0),
];

/// The gesture library, in demo order; the names are the recogniser's (`data/gestures.json`),
/// which also defines `thumbs_down`: `thumbs_up`'s shape with the thumb pointing down.
pub const GESTURES: [Gesture; 11] = [
    Gesture { name: "open_palm", angles_deg: &[&THUMB_SPREAD, &OPEN_SPREAD] },
    Gesture { name: "fist", angles_deg: FIST },
    Gesture { name: "point", angles_deg: POINT },
    Gesture { name: "victory", angles_deg: VICTORY },
    Gesture { name: "three", angles_deg: &[&PINKY_FIST, &THUMB_IN] },
    Gesture { name: "four", angles_deg: &[&THUMB_IN] },
    Gesture { name: "rock", angles_deg: &[&MIDDLE_FIST, &RING_FIST, &THUMB_OVER] },
    Gesture { name: "call_me", angles_deg: &[&INDEX_FIST, &MIDDLE_FIST, &RING_FIST, &PINKY_SPREAD, &THUMB_OUT] },
    Gesture { name: "thumbs_up", angles_deg: &[&INDEX_FIST, &MIDDLE_FIST, &RING_FIST, &PINKY_FIST, &CUP, &THUMB_OUT] },
    Gesture { name: "ok", angles_deg: &[&OK_INDEX, &OK_THUMB, &OK_OTHERS] },
    Gesture { name: "pinch", angles_deg: &[&PINCH_INDEX, &PINCH_THUMB, &PINCH_OTHERS[0], &PINCH_OTHERS[1], &PINCH_OTHERS[2]] },
];

#[cfg(test)]
mod tests {
    use super::{Gesture, GESTURES};

    #[test]
    fn every_library_gesture_names_dofs_of_the_full_model() {
        for g in &GESTURES {
            g.check().unwrap();
        }
    }

    #[test]
    fn a_misspelled_dof_is_an_error() {
        const TYPO: Gesture = Gesture { name: "typo", angles_deg: &[&[("index-finger-phalanx-intermedaite.flex", 90.0)]] };
        let e = TYPO.check().unwrap_err().to_string();
        assert!(e.contains("typo: index-finger-phalanx-intermedaite.flex"), "{e}");
    }
}
