//! A skinned model: a skeleton and the mesh bound to it.

use std::sync::Arc;

use glam::Affine3A;

use crate::appearance::Appearance;
use crate::kinematics::{ClampedAngle, HandKinematics, JointModel, KinematicsLayer, Limits, PoseTarget, Skeleton};
use crate::skin::SkinnedMesh;

/// A skeleton with its skinned mesh, as loaded from a glTF file or built as the built-in hand.
#[derive(Clone, Debug)]
pub struct Model {
    /// One line saying where the model comes from.
    pub description: String,
    /// The joints as stored (for glTF: the file's node hierarchy), in their rest pose.
    pub skeleton: Skeleton,
    /// The mesh, in bind space; its influences index `skeleton`'s joints.
    pub mesh: Arc<SkinnedMesh>,
    /// Problems that were repaired while loading (for example renormalised weights).
    pub warnings: Vec<crate::Warning>,
    /// The skin's regions and maps, where the model has them (the built-in hand; a loaded
    /// file keeps its own materials out of the engine).
    pub appearance: Option<Arc<Appearance>>,
}

impl Model {
    /// The world transform of every joint in the bind pose, the pose the mesh was bound in:
    /// the inverse of each inverse bind matrix.
    ///
    /// This, not the skeleton's rest pose, relates the mesh's vertices to the joints: an
    /// exported asset's nodes are often stored in another pose than the one it was skinned in.
    #[must_use]
    pub fn bind_world(&self) -> Vec<Affine3A> {
        self.mesh.inverse_bind().iter().map(Affine3A::inverse).collect()
    }

    /// The kinematics layer of this model's own skeleton, posed by local transforms (any
    /// skinned model).
    #[must_use]
    pub fn kinematics(&self) -> KinematicsLayer {
        KinematicsLayer::new(self.skeleton.clone(), self.mesh.inverse_bind())
    }

    /// The kinematics layer posing joint angles of `joint_model` on this model's WebXR joints.
    ///
    /// # Errors
    /// As [`HandKinematics::new`].
    pub fn hand_kinematics(&self, joint_model: JointModel) -> crate::Result<HandKinematics> {
        HandKinematics::new(&self.skeleton, self.mesh.inverse_bind(), joint_model)
    }

    /// The kinematics layer posed for a resolved pose file: joint angles on the anatomical
    /// chain of its joint model (clamped with `limits`, saying which were), or local rotations
    /// of this model's own skeleton.
    ///
    /// ```
    /// # #[cfg(feature = "hand")] {
    /// use dqhand::kinematics::{JointModel, Limits, Pose, PoseTarget};
    ///
    /// let hand = dqhand::hand::build(&dqhand::hand::HandParams { vertices: 2000, ..Default::default() })?;
    /// let mut pose = Pose::rest(JointModel::Paper.dof_count());
    /// pose.angles[JointModel::Paper.dof_index("index-finger-phalanx-intermediate.flex")?] = 150f32.to_radians();
    /// let target = PoseTarget::Angles { model: JointModel::Paper, pose }; // as a pose file resolves
    /// let (layer, clamped) = hand.pose_target(&target, Limits::Anatomical)?;
    /// assert_eq!(layer.passes(), 1);
    /// assert_eq!(clamped.len(), 1, "{clamped:?}");
    /// assert_eq!(clamped[0].dof, "index-finger-phalanx-intermediate.flex");
    /// assert_eq!((clamped[0].asked_deg.round(), clamped[0].min_deg, clamped[0].max_deg), (150.0, 0.0, 110.0));
    /// assert!(clamped[0].to_string().contains("clamped to its range 0..110 degrees"), "{}", clamped[0]);
    /// let (_, clamped) = hand.pose_target(&target, Limits::Off)?;
    /// assert!(clamped.is_empty(), "without limits nothing is clamped");
    /// # }
    /// # Ok::<(), dqhand::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`HandKinematics::new`], for angles on a skeleton without the WebXR joints.
    pub fn pose_target(&self, target: &PoseTarget, limits: Limits) -> crate::Result<(KinematicsLayer, Vec<ClampedAngle>)> {
        match target {
            PoseTarget::Angles { model, pose } => {
                let mut hand = self.hand_kinematics(*model)?;
                hand.set_limits(limits);
                let clamped = hand.pose_checked(pose);
                Ok((hand.into_layer(), clamped))
            }
            PoseTarget::LocalRotations(rotations) => {
                let mut layer = self.kinematics();
                layer.pose_rotations(rotations);
                Ok((layer, Vec::new()))
            }
        }
    }
}
