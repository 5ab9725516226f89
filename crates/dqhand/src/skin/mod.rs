//! Skin layer (paper 4.1, 4.4): the skinned mesh and the LB, QB and DQB deformers.

mod crew;
mod deformer;
mod dual_quaternion_blend;
mod kernel;
mod linear_blend;
mod method;
mod method_set;
mod quaternion_blend;
mod skinned_mesh;

pub use crew::Crew;
pub use deformer::{skinning_transforms, Deformed, Deformer, MIN_VERTICES_PER_THREAD};
pub use kernel::Kernel;
pub use method::Method;
pub use method_set::MethodSet;
pub use skinned_mesh::{MeshData, Part, SkinnedMesh, LANES, MAX_INFLUENCES};
