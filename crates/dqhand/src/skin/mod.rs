//! Skin layer (paper 4.1, 4.4): the skinned mesh, the LB, QB and DQB deformers (and CoR,
//! beyond the paper), and the [`SkinLayer`] that runs a set of them on the kinematics
//! layer's transforms; the contact pass after them ([`SelfContactPass`]), which keeps skin out
//! of the other parts' skin.

mod centre_of_rotation_blend;
mod centres_of_rotation;
mod crew;
mod deformer;
mod dual_quaternion_blend;
mod fastest_strategy;
mod kernel;
mod linear_blend;
mod method;
mod method_set;
mod pair_signs;
mod phalanx_field;
mod quaternion_blend;
mod self_contact_pass;
mod skin_layer;
mod skinned_mesh;
mod strategy;

pub use centres_of_rotation::{centres_of_rotation, SIMILARITY_SIGMA};
pub use crew::Crew;
pub use deformer::{Bones, Deformed, Deformer, VertexBuffers, MIN_VERTICES_PER_THREAD};
pub use kernel::Kernel;
pub use method::Method;
pub use method_set::MethodSet;
pub use self_contact_pass::{ContactPassReport, SelfContactPass, CLEARANCE};
pub use skin_layer::SkinLayer;
pub use skinned_mesh::{MeshData, Part, SkinnedMesh, LANES, MAX_INFLUENCES};
pub use strategy::Strategy;
