//! Mesh geometry shared by the layers above it (skin, the built-in hand, metrics): normals,
//! edges, closed surfaces and their volume, inside/outside tests.

mod closed_surface;
mod edges;
mod vertex_normals;
mod winding_number;

pub use closed_surface::{check_closed, enclosed_volume};
pub use edges::edges;
pub use vertex_normals::vertex_normals;
pub use winding_number::winding_number;
