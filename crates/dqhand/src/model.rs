//! A skinned model: a skeleton and the mesh bound to it.

use glam::Affine3A;

use crate::kinematics::Skeleton;
use crate::skin::SkinnedMesh;

/// A skeleton with its skinned mesh, as loaded from a glTF file or built as the built-in hand.
#[derive(Clone, Debug)]
pub struct Model {
    /// One line saying where the model comes from.
    pub description: String,
    /// The joints as stored (for glTF: the file's node hierarchy), in their rest pose.
    pub skeleton: Skeleton,
    /// The mesh, in bind space; its influences index `skeleton`'s joints.
    pub mesh: SkinnedMesh,
    /// Problems that were repaired while loading (for example renormalised weights).
    pub warnings: Vec<String>,
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
}
