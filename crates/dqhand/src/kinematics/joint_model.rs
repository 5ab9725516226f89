//! Joint models: which joints of the hand move, about which axis, within which anatomical range.
//!
//! Axes follow the WebXR joint frames: each bone's −Z runs along the bone toward the tip and
//! +Y points out of the back of the hand (dorsal). Flexion (`flex`) turns a bone about its
//! −X axis, so positive flexion curls toward the palm. Abduction (`abd`) turns it about its
//! ±Y axis, positive away from the middle finger (the middle finger: toward the index; the
//! thumb: away from the palm, palmar abduction). The sign of the Y axis is fixed per hand
//! from its rest geometry, so left and right hands share one model.
//!
//! Ranges are active ranges of healthy adults, in degrees: the American Academy of
//! Orthopaedic Surgeons' normal values (Greene & Heckman 1994) for MCP, PIP, DIP and thumb
//! MCP/IP, Cooney et al. 1981 (J Bone Joint Surg 63A:1371) for the thumb carpometacarpal
//! joint, El-Shennawy et al. 2001 (J Hand Surg 26A:1030) for ring and little finger
//! carpometacarpal flexion. Coupling between joints (DIP ≈ ⅔ PIP, less abduction at full
//! MCP flexion) is not imposed: poses from trackers already carry it.

use core::fmt;

/// The motion of one degree of freedom.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Motion {
    /// Flexion (+) and extension (−), about the bone's −X axis.
    Flex,
    /// Abduction (+) and adduction (−), about the bone's ±Y axis.
    Abd,
}

impl Motion {
    /// The short name used in pose files: `flex` or `abd`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Motion::Flex => "flex",
            Motion::Abd => "abd",
        }
    }
}

impl fmt::Display for Motion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One degree of freedom: a motion of the joint at the base of a named bone, and its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dof {
    /// WebXR name of the bone whose base joint moves.
    pub bone: &'static str,
    /// Flexion or abduction.
    pub motion: Motion,
    /// Anatomical lower limit, degrees.
    pub min_deg: f32,
    /// Anatomical upper limit, degrees.
    pub max_deg: f32,
    /// The anatomical joint, for documentation (`"index MCP"`).
    pub joint: &'static str,
}

impl Dof {
    /// The pose-file name, `"<bone>.<motion>"`.
    #[must_use]
    pub fn name(&self) -> String {
        format!("{}.{}", self.bone, self.motion)
    }
}

const fn dof(bone: &'static str, motion: Motion, min_deg: f32, max_deg: f32, joint: &'static str) -> Dof {
    Dof { bone, motion, min_deg, max_deg, joint }
}

use Motion::{Abd, Flex};

/// The paper's Table 1: 18 DOF. Thumb MCP ("TPIP") and IP ("TDIP") flexion, and for each
/// finger MCP flexion and abduction, PIP and DIP flexion; palm joints and thumb root fixed.
const PAPER: [Dof; 18] = [
    dof("thumb-phalanx-proximal", Flex, -10.0, 60.0, "thumb MCP (paper TPIP)"),
    dof("thumb-phalanx-distal", Flex, -20.0, 80.0, "thumb IP (paper TDIP)"),
    dof("index-finger-phalanx-proximal", Abd, -10.0, 20.0, "index MCP"),
    dof("index-finger-phalanx-proximal", Flex, -30.0, 90.0, "index MCP"),
    dof("index-finger-phalanx-intermediate", Flex, 0.0, 110.0, "index PIP"),
    dof("index-finger-phalanx-distal", Flex, -10.0, 90.0, "index DIP"),
    dof("middle-finger-phalanx-proximal", Abd, -15.0, 15.0, "middle MCP"),
    dof("middle-finger-phalanx-proximal", Flex, -30.0, 90.0, "middle MCP"),
    dof("middle-finger-phalanx-intermediate", Flex, 0.0, 110.0, "middle PIP"),
    dof("middle-finger-phalanx-distal", Flex, -10.0, 90.0, "middle DIP"),
    dof("ring-finger-phalanx-proximal", Abd, -10.0, 20.0, "ring MCP"),
    dof("ring-finger-phalanx-proximal", Flex, -30.0, 90.0, "ring MCP"),
    dof("ring-finger-phalanx-intermediate", Flex, 0.0, 110.0, "ring PIP"),
    dof("ring-finger-phalanx-distal", Flex, -10.0, 90.0, "ring DIP"),
    dof("pinky-finger-phalanx-proximal", Abd, -10.0, 30.0, "little MCP"),
    dof("pinky-finger-phalanx-proximal", Flex, -30.0, 90.0, "little MCP"),
    dof("pinky-finger-phalanx-intermediate", Flex, 0.0, 110.0, "little PIP"),
    dof("pinky-finger-phalanx-distal", Flex, -10.0, 90.0, "little DIP"),
];

/// What `full` adds to `paper`: the opposable thumb and the cupping of the palm.
///
/// * thumb CMC flexion −20…50° and palmar abduction −10…60°: Cooney's arcs (53°, 42°),
///   widened because these two axes also stand in for the CMC's coupled axial rotation, which
///   opposition (OK sign, pinch, thumbs up) needs;
/// * thumb MCP abduction ±15°: the small radial/ulnar play that lets the thumb pad meet the
///   index pad in a pinch;
/// * ring and little finger CMC flexion 0…10° and 0…20°: the palm arches around a grasped
///   object and in a fist.
const FULL_EXTRA: [Dof; 5] = [
    dof("thumb-metacarpal", Abd, -10.0, 60.0, "thumb CMC"),
    dof("thumb-metacarpal", Flex, -20.0, 50.0, "thumb CMC"),
    dof("thumb-phalanx-proximal", Abd, -15.0, 15.0, "thumb MCP"),
    dof("ring-finger-metacarpal", Flex, 0.0, 10.0, "ring CMC"),
    dof("pinky-finger-metacarpal", Flex, 0.0, 20.0, "little CMC"),
];

/// A joint model: the list of degrees of freedom of the hand below the wrist.
///
/// The wrist carries the tracker's 6-DOF pose in both models.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum JointModel {
    /// The paper's Table 1, 18 DOF.
    #[default]
    Paper,
    /// `Paper` plus thumb CMC flexion and abduction, thumb MCP abduction, ring and little
    /// finger CMC flexion: 23 DOF.
    Full,
}

impl JointModel {
    /// Both models, for listing and parsing.
    pub const ALL: [JointModel; 2] = [JointModel::Paper, JointModel::Full];

    /// The model's name: `paper` or `full`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            JointModel::Paper => "paper",
            JointModel::Full => "full",
        }
    }

    /// The degrees of freedom, in a fixed order (a [`Pose`](super::Pose)'s angle order).
    /// Abduction precedes flexion on the same joint, which is also the order they compose in.
    pub fn dofs(self) -> impl Iterator<Item = &'static Dof> {
        let extra: &'static [Dof] = match self {
            JointModel::Paper => &[],
            JointModel::Full => &FULL_EXTRA,
        };
        extra.iter().chain(PAPER.iter())
    }

    /// Number of degrees of freedom below the wrist (18 or 23).
    #[must_use]
    pub fn dof_count(self) -> usize {
        self.dofs().count()
    }

    /// Copies the `angles` (of this model) of the DOFs that `to` shares with it, the same
    /// bone and motion, into `out` (of `to`); the others in `out` are left as they are.
    /// Allocates nothing.
    pub fn carry_angles(self, angles: &[f32], to: JointModel, out: &mut [f32]) {
        for (d, &a) in self.dofs().zip(angles) {
            if let Some(i) = to.dofs().position(|e| e.bone == d.bone && e.motion == d.motion) {
                out[i] = a;
            }
        }
    }

    /// Index of the DOF called `"<bone>.<motion>"`, or an error listing the valid names.
    ///
    /// # Errors
    /// [`crate::Error::UnknownName`].
    pub fn dof_index(self, name: &str) -> crate::Result<usize> {
        self.dofs().position(|d| d.name() == name).ok_or_else(|| crate::Error::UnknownName {
            kind: "degree of freedom",
            name: name.to_owned(),
            valid: self.dofs().map(Dof::name).collect::<Vec<_>>().join(", "),
        })
    }
}

impl fmt::Display for JointModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl core::str::FromStr for JointModel {
    type Err = crate::Error;
    /// `paper` or `full`; anything else is [`crate::Error::UnknownName`].
    fn from_str(s: &str) -> crate::Result<Self> {
        Self::ALL.into_iter().find(|m| m.as_str() == s).ok_or_else(|| crate::Error::UnknownName {
            kind: "joint model",
            name: s.to_owned(),
            valid: "paper, full".into(),
        })
    }
}
