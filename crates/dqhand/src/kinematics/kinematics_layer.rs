//! The kinematics layer of one skeleton, posed once per pose (paper 4.3, and step 1 of 4.4).

use glam::{Affine3A, Quat};

use super::{forward_kinematics, skinning_transforms, Skeleton, Transform};
use crate::math::DualQuat;

/// A skeleton posed by local transforms: forward kinematics fills each joint's world
/// transform, its skinning transform `world · inverse_bind` and that transform as a unit dual
/// quaternion, each computed once per pose and read by everything that follows (the skin
/// layer's deformers, the collision layer, a GPU shader's bone texture).
///
/// Any skinned skeleton can be posed this way; [`super::HandKinematics`] poses joint angles
/// on a hand's anatomical chain through one. Every buffer is allocated here; posing
/// allocates nothing.
///
/// ```
/// use dqhand::glam::{Affine3A, Quat, Vec3};
/// use dqhand::kinematics::{Joint, KinematicsLayer, Skeleton, Transform};
///
/// // A 10 cm bone along +X: the root at the origin, its child at the bone's end.
/// let skeleton = Skeleton::new(vec![
///     Joint { name: "root".into(), parent: None, rest: Transform::IDENTITY },
///     Joint { name: "tip".into(), parent: Some(0), rest: Transform::from_rotation_translation(Quat::IDENTITY, Vec3::X * 0.1) },
/// ])?;
/// let inverse_bind: Vec<Affine3A> = skeleton.rest_world().iter().map(Affine3A::inverse).collect();
/// let mut layer = KinematicsLayer::new(skeleton.clone(), &inverse_bind);
/// let mut locals = skeleton.rest_locals();
/// locals[0].rotation = Quat::from_rotation_z(90f32.to_radians()); // turn the root
/// layer.pose_locals(&locals);
/// assert_eq!(layer.passes(), 1, "one forward kinematics pass per pose");
/// // The child rides on its parent, from +X to +Y; its skinning transform and dual
/// // quaternion carry its bind position there too.
/// let tip = Vec3::Y * 0.1;
/// assert!(Vec3::from(layer.world()[1].translation).abs_diff_eq(tip, 1e-6));
/// assert!(layer.skinning()[1].transform_point3(Vec3::X * 0.1).abs_diff_eq(tip, 1e-6));
/// assert!(layer.dual_quats()[1].transform_point3(Vec3::X * 0.1).abs_diff_eq(tip, 1e-6));
/// # Ok::<(), dqhand::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct KinematicsLayer {
    skeleton: Skeleton,
    inverse_bind: Vec<Affine3A>,
    locals: Vec<Transform>,
    world: Vec<Affine3A>,
    skinning: Vec<Affine3A>,
    dual_quats: Vec<DualQuat>,
    passes: u64,
}

impl KinematicsLayer {
    /// `skeleton` in its rest pose, skinned by `inverse_bind` (one per joint: the mesh's).
    ///
    /// # Panics
    /// If `inverse_bind` does not have one transform per joint.
    #[must_use]
    pub fn new(skeleton: Skeleton, inverse_bind: &[Affine3A]) -> Self {
        assert_eq!(inverse_bind.len(), skeleton.len(), "inverse_bind: one transform per joint");
        let n = skeleton.len();
        let mut layer = Self {
            locals: skeleton.rest_locals(),
            skeleton,
            inverse_bind: inverse_bind.to_vec(),
            world: vec![Affine3A::IDENTITY; n],
            skinning: vec![Affine3A::IDENTITY; n],
            dual_quats: vec![DualQuat::IDENTITY; n],
            passes: 0,
        };
        layer.forward();
        layer.passes = 0;
        layer
    }

    /// Poses the skeleton by `locals` (#joints, relative to each parent): forward kinematics,
    /// then the skinning transforms and their dual quaternions. Allocates nothing.
    ///
    /// # Panics
    /// If `locals` does not have one transform per joint.
    pub fn pose_locals(&mut self, locals: &[Transform]) {
        self.locals.copy_from_slice(locals);
        self.forward();
    }

    /// Poses the rest pose with some joints' local rotations replaced (a pose file's
    /// `rotations`: joint index, rotation relative to the parent). Allocates nothing.
    ///
    /// # Panics
    /// If a joint index is out of range.
    pub fn pose_rotations(&mut self, rotations: &[(usize, Quat)]) {
        for (l, j) in self.locals.iter_mut().zip(self.skeleton.joints()) {
            *l = j.rest;
        }
        for &(j, q) in rotations {
            self.locals[j].rotation = q;
        }
        self.forward();
    }

    /// The local transforms to fill and pose with [`Self::forward`]: for posers that write
    /// them in place ([`super::HandRig::locals`]).
    pub(crate) fn locals_mut(&mut self) -> &mut [Transform] {
        &mut self.locals
    }

    /// Forward kinematics (paper 4.3) of the current local transforms, then each joint's
    /// skinning transform and its unit dual quaternion (paper 4.4, step 1): one pass.
    pub(crate) fn forward(&mut self) {
        forward_kinematics(&self.skeleton, &self.locals, &mut self.world);
        skinning_transforms(&self.world, &self.inverse_bind, &mut self.skinning);
        for (q, m) in self.dual_quats.iter_mut().zip(&self.skinning) {
            *q = DualQuat::from_affine(m);
        }
        self.passes += 1;
    }

    /// The skeleton posed.
    #[must_use]
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Each joint's inverse bind matrix (bind space to the joint's frame).
    #[must_use]
    pub fn inverse_bind(&self) -> &[Affine3A] {
        &self.inverse_bind
    }

    /// The local transform of each joint in the current pose.
    #[must_use]
    pub fn locals(&self) -> &[Transform] {
        &self.locals
    }

    /// The world transform of each joint in the current pose (m).
    #[must_use]
    pub fn world(&self) -> &[Affine3A] {
        &self.world
    }

    /// The skinning transform `world · inverse_bind` of each joint in the current pose.
    #[must_use]
    pub fn skinning(&self) -> &[Affine3A] {
        &self.skinning
    }

    /// Each joint's skinning transform as a unit dual quaternion (its rigid part: a scaled
    /// bone's scale is dropped), what dual quaternion blending and a GPU shader read.
    #[must_use]
    pub fn dual_quats(&self) -> &[DualQuat] {
        &self.dual_quats
    }

    /// How many times forward kinematics has run since the layer was made: one per pose.
    #[must_use]
    pub fn passes(&self) -> u64 {
        self.passes
    }
}
