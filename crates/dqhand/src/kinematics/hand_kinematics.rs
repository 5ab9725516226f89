//! The kinematics layer of a hand: joint angles posed on its anatomical chain.

use glam::Affine3A;

use super::{HandRig, JointModel, KinematicsLayer, Limits, Pose, Skeleton};
use crate::math::DualQuat;
use crate::Result;

/// An angle of a pose that was outside its joint's anatomical range and was clamped to it.
#[derive(Clone, Debug, PartialEq)]
pub struct ClampedAngle {
    /// The degree of freedom, as the joint model names it (`index-finger-phalanx-proximal flex`).
    pub dof: String,
    /// The angle asked for (degrees).
    pub asked_deg: f32,
    /// Its range (degrees).
    pub min_deg: f32,
    /// Its range (degrees).
    pub max_deg: f32,
}

impl core::fmt::Display for ClampedAngle {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} of {:.1} degrees clamped to its range {}..{} degrees", self.dof, self.asked_deg, self.min_deg, self.max_deg)
    }
}

/// A hand's kinematics layer: a [`HandRig`] (a joint model on the skeleton's WebXR joints)
/// turning each [`Pose`] into local transforms, and the [`KinematicsLayer`] they pose, once.
///
/// This is what every loop holds: the gesture loop poses the tracked hand with it, the
/// contact constraint the rendered hand, and the skin layer reads either's transforms.
///
/// ```
/// # #[cfg(feature = "hand")] {
/// use dqhand::glam::Vec3;
/// use dqhand::kinematics::{JointModel, Pose};
///
/// let hand = dqhand::hand::build(&dqhand::hand::HandParams { vertices: 2000, ..Default::default() })?;
/// let mut kinematics = hand.hand_kinematics(JointModel::Paper)?;
/// let rest = kinematics.world().to_vec();
/// let mut pose = Pose::rest(JointModel::Paper.dof_count());
/// pose.angles[JointModel::Paper.dof_index("index-finger-phalanx-proximal.flex")?] = 1.0; // radians
/// kinematics.pose(&pose);
/// assert_eq!(kinematics.layer().passes(), 1, "one forward kinematics pass per pose");
/// let (index, pinky) = (kinematics.skeleton().index_of("index-finger-tip")?, kinematics.skeleton().index_of("pinky-finger-tip")?);
/// assert!(kinematics.world()[index].translation.distance(rest[index].translation) > 0.02, "the index finger bends");
/// assert_eq!(kinematics.world()[pinky], rest[pinky], "the little finger stays");
/// // Each dual quaternion is its skinning transform, rigidly.
/// let p = Vec3::new(0.01, 0.02, -0.05);
/// for (q, m) in kinematics.dual_quats().iter().zip(kinematics.skinning()) {
///     assert!(q.transform_point3(p).abs_diff_eq(m.transform_point3(p), 1e-5));
/// }
/// # }
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct HandKinematics {
    rig: HandRig,
    limits: Limits,
    layer: KinematicsLayer,
}

impl HandKinematics {
    /// `joint_model` resolved on `skeleton`'s WebXR joints, skinned by `inverse_bind` (one
    /// per joint of `skeleton`), in the rest pose, with anatomical limits.
    ///
    /// # Errors
    /// As [`HandRig::new`]: a joint the model needs is missing, or the joint frames are not
    /// WebXR's.
    ///
    /// # Panics
    /// If `inverse_bind` does not have one transform per joint.
    pub fn new(skeleton: &Skeleton, inverse_bind: &[Affine3A], joint_model: JointModel) -> Result<Self> {
        let rig = HandRig::new(skeleton, joint_model)?;
        let layer = KinematicsLayer::new(rig.skeleton().clone(), inverse_bind);
        Ok(Self { rig, limits: Limits::Anatomical, layer })
    }

    /// Whether angles are clamped to the joint model's anatomical ranges when posing.
    pub fn set_limits(&mut self, limits: Limits) {
        self.limits = limits;
    }

    /// Poses `pose` (the wrist from the tracker, each angle in radians, within the limits):
    /// the rig's local transforms, then one pass of [`KinematicsLayer`]. Allocates nothing.
    ///
    /// # Panics
    /// If `pose` has another angle count than the joint model ([`JointModel::dof_count`]).
    pub fn pose(&mut self, pose: &Pose) {
        self.rig.locals(pose, self.limits, self.layer.locals_mut());
        self.layer.forward();
    }

    /// [`Self::pose`], saying which angles the anatomical limits clamped (none with
    /// [`Limits::Off`]): for poses that people write, not per frame (it allocates).
    ///
    /// # Panics
    /// As [`Self::pose`].
    pub fn pose_checked(&mut self, pose: &Pose) -> Vec<ClampedAngle> {
        let clamped = if self.limits == Limits::Anatomical {
            let mut clamped_pose = pose.clone();
            let dofs: Vec<_> = self.rig.model().dofs().collect();
            self.rig
                .clamp(&mut clamped_pose)
                .into_iter()
                .map(|i| ClampedAngle { dof: dofs[i].name(), asked_deg: pose.angles[i].to_degrees(), min_deg: dofs[i].min_deg, max_deg: dofs[i].max_deg })
                .collect()
        } else {
            Vec::new()
        };
        self.pose(pose);
        clamped
    }

    /// The rig.
    #[must_use]
    pub fn rig(&self) -> &HandRig {
        &self.rig
    }

    /// Whether angles are clamped.
    #[must_use]
    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// The posed skeleton's transforms.
    #[must_use]
    pub fn layer(&self) -> &KinematicsLayer {
        &self.layer
    }

    /// The posed skeleton's transforms, the rig let go.
    #[must_use]
    pub fn into_layer(self) -> KinematicsLayer {
        self.layer
    }

    /// The skeleton posed: the rig's anatomical chain.
    #[must_use]
    pub fn skeleton(&self) -> &Skeleton {
        self.rig.skeleton()
    }

    /// The world transform of each joint in the current pose (m).
    #[must_use]
    pub fn world(&self) -> &[Affine3A] {
        self.layer.world()
    }

    /// The skinning transform of each joint in the current pose.
    #[must_use]
    pub fn skinning(&self) -> &[Affine3A] {
        self.layer.skinning()
    }

    /// Each joint's skinning transform as a unit dual quaternion.
    #[must_use]
    pub fn dual_quats(&self) -> &[DualQuat] {
        self.layer.dual_quats()
    }
}
