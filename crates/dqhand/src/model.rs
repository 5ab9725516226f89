//! A skinned model: a skeleton and the mesh bound to it, and the per-frame buffers that pose it.

use glam::Affine3A;

use crate::io::PoseTarget;
use crate::kinematics::{forward_kinematics, HandRig, Limits, Skeleton, Transform};
use crate::skin::{skinning_transforms, SkinnedMesh};
use crate::Result;

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

impl Model {
    /// The skinning transforms of a resolved pose file: joint angles are posed on the
    /// anatomical chain of a [`HandRig`], local rotations on the file's own hierarchy.
    /// Returns the transforms and one warning per angle clamped to its joint limits.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] if joint angles are given for a skeleton without the WebXR
    /// hand joints.
    pub fn pose_skinning(&self, target: &PoseTarget, limits: Limits) -> Result<(Vec<Affine3A>, Vec<String>)> {
        let mut warnings = Vec::new();
        let skinning = match target {
            PoseTarget::Angles { model, pose } => {
                let rig = HandRig::new(&self.skeleton, *model)?;
                let mut pose = pose.clone();
                if limits == Limits::Anatomical {
                    let dofs: Vec<_> = model.dofs().collect();
                    for i in rig.clamp(&mut pose) {
                        let d = dofs[i];
                        warnings.push(format!(
                            "{} clamped to its range {}..{} degrees (use --no-limits to allow it)",
                            d.name(),
                            d.min_deg,
                            d.max_deg
                        ));
                    }
                }
                let mut buffers = PoseBuffers::new(rig.skeleton());
                rig.locals(&pose, limits, &mut buffers.locals);
                buffers.evaluate(rig.skeleton(), self.mesh.inverse_bind()).to_vec()
            }
            PoseTarget::LocalRotations(rotations) => {
                let mut buffers = PoseBuffers::new(&self.skeleton);
                for &(j, q) in rotations {
                    buffers.locals[j].rotation = q;
                }
                buffers.evaluate(&self.skeleton, self.mesh.inverse_bind()).to_vec()
            }
        };
        Ok((skinning, warnings))
    }
}
