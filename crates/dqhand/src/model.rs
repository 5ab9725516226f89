//! A skinned model: a skeleton and the mesh bound to it, and the per-frame buffers that pose it.

use glam::Affine3A;

use crate::kinematics::{forward_kinematics, Skeleton, Transform};
use crate::skin::{skinning_transforms, SkinnedMesh};

/// A skeleton with its skinned mesh, as loaded from a file or built by [`crate::hand`].
#[derive(Clone, Debug)]
pub struct Model {
    /// One line saying where the model comes from.
    pub description: String,
    /// The joints as stored (for glTF: the file's node hierarchy).
    pub skeleton: Skeleton,
    /// The mesh; its influences index `skeleton`'s joints.
    pub mesh: SkinnedMesh,
    /// Problems that were repaired while loading (for example renormalised weights).
    pub warnings: Vec<String>,
}

/// Scratch for one frame of posing: local transforms in, skinning transforms out.
#[derive(Clone, Debug)]
pub struct PoseBuffers {
    /// Local transform of each joint; fill it, then call [`Self::evaluate`].
    pub locals: Vec<Transform>,
    /// World transform of each joint after [`Self::evaluate`].
    pub world: Vec<Affine3A>,
    /// Skinning transform of each joint after [`Self::evaluate`].
    pub skinning: Vec<Affine3A>,
}

impl PoseBuffers {
    /// Buffers for `skeleton`, holding its rest pose.
    #[must_use]
    pub fn new(skeleton: &Skeleton) -> Self {
        let n = skeleton.len();
        Self { locals: skeleton.rest_locals(), world: vec![Affine3A::IDENTITY; n], skinning: vec![Affine3A::IDENTITY; n] }
    }

    /// Forward kinematics, then `world · inverse_bind` per joint (paper 4.4 step 1).
    /// Allocates nothing.
    pub fn evaluate(&mut self, skeleton: &Skeleton, inverse_bind: &[Affine3A]) -> &[Affine3A] {
        forward_kinematics(skeleton, &self.locals, &mut self.world);
        skinning_transforms(&self.world, inverse_bind, &mut self.skinning);
        &self.skinning
    }
}
