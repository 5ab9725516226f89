//! The scene of the manipulation loop (paper Figure 9): the objects the hand picks up and
//! the table they stand on, read from a scene file, and the meshes of mesh objects.

mod object_mesh;
mod scene_file;

pub use object_mesh::ObjectMesh;
pub use scene_file::{MeshSource, ObjectShape, Scene, SceneAction, SceneCommand, SceneObject, Table, DEFAULT_FRICTION, DEFAULT_RESTITUTION};
