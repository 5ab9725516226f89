//! Pose files (JSON): a wrist pose and joint angles for our joint models, or local rotations
//! for the nodes of any skinned glTF.
//!
//! ```json
//! {
//!   "model": "full",
//!   "wrist": { "translation": [0, 0, 0], "rotation": [0, 0, 0, 1] },
//!   "angles_deg": { "index-finger-phalanx-intermediate.flex": 90 },
//!   "local_rotations": { "<node name>": [0, 0, 0, 1] }
//! }
//! ```
//! Every field is optional; `angles_deg` and `local_rotations` exclude each other. `model`
//! defaults to `paper` when every angle is a `paper` DOF, else `full`.

use std::collections::BTreeMap;
use std::path::Path;

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

use crate::kinematics::{JointModel, Pose, PoseTarget, Skeleton};
use crate::math::DualQuat;
use crate::{Error, Result};

/// The wrist's world pose as written in a pose file.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WristPose {
    /// Position (m).
    #[serde(default)]
    pub translation: [f32; 3],
    /// Rotation `[x, y, z, w]`.
    #[serde(default = "identity")]
    pub rotation: [f32; 4],
}

fn identity() -> [f32; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

/// A pose file as written.
///
/// ```
/// # #[cfg(feature = "hand")] {
/// use dqhand::io::PoseFile;
/// use dqhand::kinematics::{JointModel, PoseTarget};
///
/// let hand = dqhand::hand::build(&dqhand::hand::HandParams { vertices: 2000, ..Default::default() })?;
/// let file: PoseFile = serde_json::from_str(r#"{"angles_deg": {"index-finger-phalanx-intermediate.flex": 90}}"#)?;
/// let PoseTarget::Angles { model, pose } = file.resolve(&hand.skeleton)? else { panic!("angles resolve to angles") };
/// assert_eq!(model, JointModel::Paper, "every angle is a paper DOF");
/// let i = model.dof_index("index-finger-phalanx-intermediate.flex")?;
/// assert!((pose.angles[i] - 90f32.to_radians()).abs() < 1e-6, "degrees in the file, radians in the pose");
/// assert_eq!(pose.angles.iter().filter(|&&a| a != 0.0).count(), 1);
/// // Node rotations name joints of the skeleton; an unknown one is refused, listing the valid ones.
/// let file: PoseFile = serde_json::from_str(r#"{"local_rotations": {"index-tip": [0, 0, 0, 1]}}"#)?;
/// let err = file.resolve(&hand.skeleton).unwrap_err().to_string();
/// assert!(err.starts_with("unknown node \"index-tip\"") && err.contains("index-finger-tip"), "{err}");
/// # }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseFile {
    /// `paper` or `full`; inferred from the angle names when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// The wrist's world pose (the tracker).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wrist: Option<WristPose>,
    /// `"<bone>.<flex|abd>"` to degrees.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub angles_deg: BTreeMap<String, f32>,
    /// Node name to the rotation `[x, y, z, w]` that replaces its rest rotation.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub local_rotations: BTreeMap<String, [f32; 4]>,
}

impl PoseFile {
    /// Reads and parses a pose file.
    ///
    /// # Errors
    /// [`Error::Io`], or [`Error::File`] naming the file around an [`Error::Pose`].
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(Error::io(path))?;
        serde_json::from_str(&text).map_err(|e| Error::Pose(format!("not a valid pose file: {e}")).in_file(path))
    }

    /// Resolves names against `skeleton` (node names) and the joint models (DOF names).
    ///
    /// # Errors
    /// [`Error::UnknownName`] for an unknown DOF or node (listing the valid ones),
    /// [`Error::Pose`] for a zero or non-finite rotation, a non-finite value, or a file
    /// that mixes `angles_deg` and `local_rotations`.
    pub fn resolve(&self, skeleton: &Skeleton) -> Result<PoseTarget> {
        let quat = |what: &str, q: [f32; 4]| -> Result<Quat> {
            let q = Quat::from_array(q);
            if !q.is_finite() || q.length() < 1e-6 {
                return Err(Error::Pose(format!("{what} rotation {:?} is not a rotation", q.to_array())));
            }
            Ok(q.normalize())
        };
        if !self.local_rotations.is_empty() {
            if !self.angles_deg.is_empty() || self.wrist.is_some() || self.model.is_some() {
                return Err(Error::Pose("local_rotations cannot be mixed with model, wrist or angles_deg".into()));
            }
            return self
                .local_rotations
                .iter()
                .map(|(name, &q)| Ok((skeleton.index_of(name).map_err(node_kind)?, quat(name, q)?)))
                .collect::<Result<_>>()
                .map(PoseTarget::LocalRotations);
        }
        if self.angles_deg.is_empty() && self.wrist.is_none() && self.model.is_none() {
            // Nothing to pose: the rest pose as stored, which needs no hand joints.
            return Ok(PoseTarget::LocalRotations(Vec::new()));
        }
        let joint_model = match &self.model {
            Some(m) => m.parse()?,
            None if self.angles_deg.keys().all(|k| JointModel::Paper.dof_index(k).is_ok()) => JointModel::Paper,
            None => JointModel::Full,
        };
        let mut pose = Pose::rest(joint_model.dof_count());
        for (name, &deg) in &self.angles_deg {
            if !deg.is_finite() {
                return Err(Error::Pose(format!("angle {name} = {deg} is not finite")));
            }
            pose.angles[joint_model.dof_index(name)?] = deg.to_radians();
        }
        if let Some(w) = self.wrist {
            let t = Vec3::from(w.translation);
            if !t.is_finite() {
                return Err(Error::Pose(format!("wrist translation {:?} is not finite", w.translation)));
            }
            pose.wrist = Some(DualQuat::from_rotation_translation(quat("wrist", w.rotation)?, t));
        }
        Ok(PoseTarget::Angles { model: joint_model, pose })
    }

    /// The pose file of a joint-angle pose (angles in degrees; zero angles omitted).
    #[must_use]
    pub fn from_pose(model: JointModel, pose: &Pose) -> Self {
        let angles_deg = model
            .dofs()
            .zip(&pose.angles)
            .filter(|(_, a)| **a != 0.0)
            .map(|(d, a)| (d.name(), a.to_degrees()))
            .collect();
        let wrist = pose.wrist.map(|w| {
            let (r, t) = w.to_rotation_translation();
            WristPose { translation: t.to_array(), rotation: r.to_array() }
        });
        Self { model: Some(model.as_str().into()), wrist, angles_deg, local_rotations: BTreeMap::new() }
    }
}

fn node_kind(e: Error) -> Error {
    match e {
        Error::UnknownName { name, valid, .. } => Error::UnknownName { kind: "node", name, valid },
        other => other,
    }
}
