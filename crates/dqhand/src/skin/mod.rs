//! Skin layer (paper 4.1, 4.4): the skinned mesh and the LB, QB and DQB deformers.

mod deformer;
mod dual_quaternion_blend;
mod kernel;
mod linear_blend;
mod quaternion_blend;
mod skinned_mesh;

pub use kernel::simd_available;
pub use deformer::{skinning_transforms, Deformed, Deformer, Method};
pub use skinned_mesh::{vertex_normals, MeshData, Part, SkinnedMesh, LANES, MAX_INFLUENCES};
